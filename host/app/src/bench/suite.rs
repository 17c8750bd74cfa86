//! Benchmark suites (`scenes/bench/*.ron`) that reproduce the seeds' experiments.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::PathMode;

/// A suite: runs, plus ratios to place beside the seed's figures.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Suite {
    pub name: String,
    pub description: String,
    pub runs: Vec<SuiteRun>,
    #[serde(default)]
    pub ratios: Vec<SuiteRatio>,
    /// What the seeds report, quoted beside this project's numbers.
    #[serde(default)]
    pub seed_figures: Vec<String>,
}

/// One benchmark run of a suite.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuiteRun {
    pub name: String,
    /// Scene file, relative to the suite file.
    pub scene: String,
    pub techniques: Vec<String>,
    #[serde(default = "default_size")]
    pub size: (u32, u32),
    #[serde(default = "default_frames")]
    pub frames: u32,
    #[serde(default = "default_warmup")]
    pub warmup: u32,
    #[serde(default)]
    pub path: PathMode,
    /// (key, values) as for `--sweep KEY=v1,v2`.
    #[serde(default)]
    pub sweeps: Vec<(String, Vec<String>)>,
    /// Technique parameters as `ID.KEY` = value.
    #[serde(default)]
    pub set: Vec<(String, String)>,
    /// A folder the scene reads, relative to the suite file, that is not part of the
    /// repository (`../shared/models`' real meshes): where it is absent the run is skipped
    /// and listed as such.
    #[serde(default)]
    pub needs: Option<String>,
    /// Let frames keep work whose inputs did not change, as `--reuse-unchanged` does for the
    /// whole suite: a run that measures a cache (virtual maps' pages along a camera path).
    #[serde(default)]
    pub reuse_unchanged: bool,
}

impl SuiteRun {
    /// Why the run cannot be measured here (its `needs` folder is absent), if so.
    pub fn missing(&self, suite_dir: &std::path::Path) -> Option<String> {
        let needs = self.needs.as_ref()?;
        let folder = suite_dir.join(needs);
        (!folder.is_dir())
            .then(|| format!("needs {} (not part of the repository)", folder.display()))
    }
}

fn default_size() -> (u32, u32) {
    (256, 256)
}
fn default_frames() -> u32 {
    10
}
fn default_warmup() -> u32 {
    2
}

/// What a ratio divides: a run's technique, optionally one configuration, and a measure.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Measure {
    pub run: String,
    pub technique: String,
    /// What is measured: median times of the `frame`, the `technique` (its passes) or the
    /// passes whose names start with a prefix (over `frame` of the same technique: the passes'
    /// share of the frame); `counter:NAME`, the counter's mean over the measured frames; or
    /// `vertices:PREFIX`, `fragments:PREFIX`, `compute:PREFIX`, the median shader invocations
    /// of those passes, or `samples:PREFIX`, their samples passing the depth and stencil tests
    /// (where the device counts them).
    #[serde(default = "default_measure")]
    pub passes: String,
    /// Only the configurations with these swept values, as (key, value) of the run's
    /// `sweeps`: a ratio of two configurations of one sweep (PCF 23x23 over 5x5). Other sweeps
    /// still pair the configurations with equal values.
    #[serde(default)]
    pub swept: Vec<(String, String)>,
}

impl Measure {
    /// Whether it measures a count (a counter, shader invocations, samples), not a time.
    pub fn is_count(&self) -> bool {
        self.passes.starts_with("counter:")
            || (zoo_host::gpu::PassCounts::NAMES.iter())
                .any(|kind| (self.passes.strip_prefix(kind)).is_some_and(|p| p.starts_with(':')))
    }

    /// Whether a configuration swept to `swept` is one this measure takes.
    pub fn picks(&self, swept: &[(String, String)]) -> bool {
        (self.swept.iter()).all(|(k, v)| swept.iter().any(|(k2, v2)| k2 == k && v2 == v))
    }
}

fn default_measure() -> String {
    "frame".into()
}

/// A ratio to report beside the seed's figure; computed for every matching pair of
/// configurations (same size and tessellation).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuiteRatio {
    pub label: String,
    pub numerator: Measure,
    pub denominator: Measure,
    /// The seed's figure for the same ratio.
    pub seed: String,
}

/// Where suite `name` lives: `scenes/bench/NAME.ron` under the current folder, or under the
/// workspace the binary was built from.
pub fn locate(name: &str) -> anyhow::Result<PathBuf> {
    let relative = Path::new("scenes/bench").join(format!("{name}.ron"));
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join(&relative);
    [relative.clone(), built]
        .into_iter()
        .find(|p| p.is_file())
        .ok_or_else(|| {
            let known: Vec<String> =
                std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bench"))
                    .into_iter()
                    .flatten()
                    .filter_map(|e| e.ok())
                    .filter_map(|e| {
                        e.path()
                            .file_stem()
                            .map(|s| s.to_string_lossy().into_owned())
                    })
                    .collect();
            anyhow::anyhow!(
                "no suite `{name}` ({} not found; suites: {})",
                relative.display(),
                known.join(", ")
            )
        })
}

/// Loads and parses a suite file.
pub fn load(path: &Path) -> anyhow::Result<Suite> {
    crate::ron_file::load(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_needing(folder: &str) -> SuiteRun {
        let text =
            format!("(name: \"r\", scene: \"s.ron\", techniques: [], needs: Some(\"{folder}\"))");
        ron::from_str(&text).unwrap()
    }

    #[test]
    fn a_run_whose_folder_is_absent_says_which() {
        let here = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        assert_eq!(run_needing("scenes/bench").missing(here), None);
        let reason = run_needing("no-such-folder").missing(here).unwrap();
        assert!(reason.contains("no-such-folder"), "{reason}");
        let plain: SuiteRun =
            ron::from_str("(name: \"r\", scene: \"s.ron\", techniques: [])").unwrap();
        assert_eq!(plain.missing(here), None);
    }

    #[test]
    fn counts_are_told_from_times() {
        let measure = |passes: &str| Measure {
            run: "r".into(),
            technique: "t".into(),
            passes: passes.into(),
            swept: Vec::new(),
        };
        for count in [
            "counter:maps rendered",
            "samples:Hybrid volumes",
            "fragments:Shadow",
        ] {
            assert!(measure(count).is_count(), "{count}");
        }
        for time in ["frame", "technique", "Shadow map", "samplesShadow"] {
            assert!(!measure(time).is_count(), "{time}");
        }
    }
}
