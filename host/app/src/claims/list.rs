//! The list of claims (`scenes/claims/claims.ron`): each headline claim of a source with the
//! measurement that reproduces it, a bench suite's ratio or a judged metric.

use std::path::{Path, PathBuf};

use serde::Deserialize;

/// The claims file: claims measured by a benchmark ratio, and claims the judge shows.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClaimList {
    pub ratios: Vec<RatioClaim>,
    #[serde(default)]
    pub judged: Vec<JudgedClaim>,
}

/// A claim measured by a ratio of a bench suite (`scenes/bench/SUITE.ron`); the source's
/// figure is the ratio's `seed`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RatioClaim {
    /// What the source claims, in a line.
    pub claim: String,
    /// Where: the source, and its section, table or figure.
    pub source: String,
    pub suite: String,
    /// The ratio's `label` in the suite.
    pub ratio: String,
    /// Sweep values to measure it at, as (key, value) of the runs' sweeps (the suite may
    /// sweep more than the claim needs).
    #[serde(default)]
    pub at: Vec<(String, String)>,
    /// Which way this project's adapters skew the ratio against the source's GPU, and why.
    pub skew: String,
}

/// A claim the judge shows: a technique's metric on a scene, worst light.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JudgedClaim {
    pub claim: String,
    pub source: String,
    /// What the source says of it (seed 000 gives no numbers).
    pub figure: String,
    /// Scene file, relative to the claims file.
    pub scene: String,
    pub technique: String,
    /// Its parameters as `KEY` = value.
    #[serde(default)]
    pub set: Vec<(String, String)>,
    #[serde(default = "default_size")]
    pub size: (u32, u32),
    /// A judge metric's name, as in `results.csv` (`false_lit_core`, `mae`, ...).
    pub metric: String,
}

fn default_size() -> (u32, u32) {
    (256, 256)
}

/// Where the claims file lives: `scenes/claims/claims.ron` under the current folder, or under
/// the workspace the binary was built from.
pub fn locate() -> anyhow::Result<PathBuf> {
    let relative = Path::new("scenes/claims/claims.ron");
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join(relative);
    [relative.to_path_buf(), built]
        .into_iter()
        .find(|p| p.is_file())
        .ok_or_else(|| anyhow::anyhow!("{} not found", relative.display()))
}

/// Loads and parses a claims file.
pub fn load(path: &Path) -> anyhow::Result<ClaimList> {
    crate::ron_file::load(path)
}

impl ClaimList {
    /// Only the claims whose text or source contains `filter` (any case).
    pub fn only(self, filter: Option<&str>) -> ClaimList {
        let Some(filter) = filter.map(str::to_lowercase) else {
            return self;
        };
        let keeps = |claim: &str, source: &str| {
            claim.to_lowercase().contains(&filter) || source.to_lowercase().contains(&filter)
        };
        ClaimList {
            ratios: (self.ratios.into_iter())
                .filter(|c| keeps(&c.claim, &c.source))
                .collect(),
            judged: (self.judged.into_iter())
                .filter(|c| keeps(&c.claim, &c.source))
                .collect(),
        }
    }
}
