//! Results as CSV, markdown tables with the seeds' figures beside ours, and PNG plots.

use std::fmt::Write as _;
use std::path::Path;

use zoo_host::gpu::{PassCounts, PassOwner};

use crate::cli::parse_size;

use super::measure::*;
use super::plan::*;
use super::{plot, suite};

/// The `unshadowed` result with the same run, size and tessellation as `r`.
fn baseline<'a>(results: &'a [ConfigResult], r: &ConfigResult) -> Option<&'a ConfigResult> {
    results.iter().find(|b| {
        b.config.technique.id == zoo_host::builtin::UNSHADOWED_ID
            && b.config.run == r.config.run
            && b.config.common_key() == r.config.common_key()
    })
}

pub(super) fn ratio_to_baseline(results: &[ConfigResult], r: &ConfigResult) -> Option<f64> {
    baseline(results, r)
        .map(|b| b.frame_gpu.median)
        .filter(|m| *m > 0.0)
        .map(|m| r.frame_gpu.median / m)
}

/// `bench.csv`: one row per configuration and pass (plus frame and technique totals).
pub fn bench_csv(results: &[ConfigResult]) -> String {
    let mut out = String::from(
        "run,configuration,technique,size,tessellation,pass,owner,median_ms,mean_ms,p95_ms,p99_ms,min_ms,max_ms,frames,vertex_invocations,fragment_invocations,compute_invocations,samples_passed\n",
    );
    for r in results {
        let c = &r.config;
        let rows = r
            .passes
            .iter()
            .zip(&r.counts)
            .map(|((name, owner, s), counts)| {
                let owner = match owner {
                    PassOwner::Host => "host",
                    PassOwner::Technique => "technique",
                };
                (name.clone(), owner, *s, *counts)
            })
            .chain([
                (
                    "technique total (gpu)".to_string(),
                    "total",
                    r.technique_gpu,
                    None,
                ),
                ("frame total (gpu)".to_string(), "total", r.frame_gpu, None),
                ("frame (cpu wall)".to_string(), "total", r.frame_cpu, None),
            ]);
        for (name, owner, s, counts) in rows {
            let counts = counts.map_or(",,,".to_string(), |c| {
                let [v, f, c, s] = c.values();
                format!("{v},{f},{c},{s}")
            });
            let _ = writeln!(
                out,
                "\"{}\",\"{}\",{},{}x{},{},\"{}\",{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{},{counts}",
                c.run.replace('"', "'"),
                c.label().replace('"', "'"),
                c.technique.id,
                c.size.x,
                c.size.y,
                c.tessellation,
                name.replace('"', "'"),
                owner,
                s.median,
                s.mean,
                s.p95,
                s.p99,
                s.min,
                s.max,
                s.count
            );
        }
    }
    out
}

/// `summary.csv`: one row per configuration.
pub fn summary_csv(results: &[ConfigResult]) -> String {
    let mut out = String::from(
        "run,configuration,technique,size,tessellation,triangles,frame_median_ms,technique_median_ms,cpu_median_ms,ratio_to_unshadowed,flicker_index\n",
    );
    for r in results {
        let c = &r.config;
        let _ = writeln!(
            out,
            "\"{}\",\"{}\",{},{}x{},{},{},{:.4},{:.4},{:.4},{},{}",
            c.run.replace('"', "'"),
            c.label().replace('"', "'"),
            c.technique.id,
            c.size.x,
            c.size.y,
            c.tessellation,
            r.triangles,
            r.frame_gpu.median,
            r.technique_gpu.median,
            r.frame_cpu.median,
            ratio_to_baseline(results, r).map_or(String::new(), |x| format!("{x:.4}")),
            r.flicker.map_or(String::new(), |x| format!("{x:.6}")),
        );
    }
    out
}

/// Today's date (UTC) as YYYY-MM-DD.
fn today() -> String {
    let days = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() / 86_400)
        .unwrap_or(0) as i64;
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

/// A result's measure (see [`suite::Measure::passes`]): the median time of the frame, of the
/// technique or of the passes starting with a prefix; a counter's mean over the measured frames;
/// or the passes' median count of one kind ([`PassCounts::NAMES`]). `None` where it was not
/// measured (a counter the technique lacks, counts on a device without pipeline statistics).
fn measure(r: &ConfigResult, passes: &str) -> Option<f64> {
    if let Some(name) = passes.strip_prefix("counter:") {
        return counter_mean(r, name);
    }
    for (index, kind) in PassCounts::NAMES.iter().enumerate() {
        let prefix = passes.strip_prefix(kind).and_then(|p| p.strip_prefix(':'));
        if let Some(prefix) = prefix {
            let counts: Option<Vec<u64>> = (r.passes.iter().zip(&r.counts))
                .filter(|((name, _, _), _)| name.starts_with(prefix))
                .map(|(_, counts)| counts.map(|c| c.values()[index]))
                .collect();
            return counts
                .filter(|c| !c.is_empty())
                .map(|c| c.iter().sum::<u64>() as f64);
        }
    }
    Some(match passes {
        "frame" => r.frame_gpu.median,
        "technique" => r.technique_gpu.median,
        prefix => (r.passes.iter())
            .filter(|(n, _, _)| n.starts_with(prefix))
            .map(|(_, _, s)| s.median)
            .fold(0.0, |a, b| a + b),
    })
}

/// Counter `name`'s mean over the measured frames (its one value where it did not change).
fn counter_mean(r: &ConfigResult, name: &str) -> Option<f64> {
    match r.varying_counters.iter().find(|(n, _)| n == name) {
        Some((_, values)) => Some(values.iter().sum::<f64>() / values.len().max(1) as f64),
        None => (r.counters.iter())
            .find(|(n, _)| n == name)
            .map(|(_, value)| *value),
    }
}

/// One suite ratio for one pair of configurations.
#[derive(Debug, Clone, PartialEq)]
pub struct RatioRow {
    pub label: String,
    /// The numerator's size, tessellation and sweep values.
    pub configuration: String,
    /// `None` where a measure was not taken on this device.
    pub value: Option<f64>,
    /// Where both measures are counts: the least and greatest ratio of one frame's counts
    /// along the path (the camera's or the light's positions differ per frame).
    pub frame_range: Option<(f64, f64)>,
    /// The seed's figure.
    pub seed: String,
}

/// Suite ratios, one row for every matching pair of configurations.
pub fn suite_ratios(ratios: &[suite::SuiteRatio], results: &[ConfigResult]) -> Vec<RatioRow> {
    let mut out = Vec::new();
    for ratio in ratios {
        let (n, d) = (&ratio.numerator, &ratio.denominator);
        // Sweeps a measure picks a value of are not paired.
        let pinned = |key: &str| n.swept.iter().chain(&d.swept).any(|(k, _)| k == key);
        for num in results.iter().filter(|r| {
            r.config.run == n.run
                && r.config.technique.id == n.technique
                && n.picks(&r.config.swept)
        }) {
            // Same size and tessellation, and equal values for every sweep both sides share.
            let den = results.iter().find(|r| {
                r.config.run == d.run
                    && r.config.technique.id == d.technique
                    && d.picks(&r.config.swept)
                    && r.config.common_key() == num.config.common_key()
                    && (num.config.swept.iter().filter(|(k, _)| !pinned(k)))
                        .all(|(k, v)| r.config.swept.iter().all(|(k2, v2)| k2 != k || v2 == v))
            });
            let Some(den) = den else { continue };
            let bottom = measure(den, &d.passes);
            if bottom.is_some_and(|b| b <= 0.0) {
                continue;
            }
            let configuration = format!(
                "{}x{}, tessellation {}{}",
                num.config.size.x,
                num.config.size.y,
                num.config.tessellation,
                if num.config.swept.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", num.config.label())
                }
            );
            out.push(RatioRow {
                label: ratio.label.clone(),
                configuration,
                value: measure(num, &n.passes).zip(bottom).map(|(top, b)| top / b),
                frame_range: frame_ratio_range(num, &n.passes, den, &d.passes),
                seed: ratio.seed.clone(),
            });
        }
    }
    out
}

/// The least and greatest ratio of two count measures frame by frame (`None` unless both are
/// counts of the same number of frames, all denominators positive).
fn frame_ratio_range(
    num: &ConfigResult,
    top: &str,
    den: &ConfigResult,
    bottom: &str,
) -> Option<(f64, f64)> {
    let (tops, bottoms) = (frame_counts(num, top)?, frame_counts(den, bottom)?);
    if tops.len() != bottoms.len() || bottoms.iter().any(|b| *b <= 0.0) {
        return None;
    }
    let ratios = tops.iter().zip(&bottoms).map(|(t, b)| t / b);
    ratios.fold(None, |range, r| match range {
        None => Some((r, r)),
        Some((low, high)) => Some((r.min(low), r.max(high))),
    })
}

/// A count measure (`fragments:PREFIX`, ...) per measured frame: the sum over the passes so
/// named. `None` for other measures or where counts were not taken.
fn frame_counts(r: &ConfigResult, passes: &str) -> Option<Vec<f64>> {
    let (index, prefix) = (PassCounts::NAMES.iter().enumerate()).find_map(|(index, kind)| {
        let prefix = passes.strip_prefix(kind)?.strip_prefix(':')?;
        Some((index, prefix))
    })?;
    let named: Vec<&Vec<PassCounts>> = (r.passes.iter().zip(&r.frame_counts))
        .filter(|((name, _, _), _)| name.starts_with(prefix))
        .map(|(_, frames)| frames)
        .collect();
    let frames = named.first()?.len();
    if frames == 0 || named.iter().any(|f| f.len() != frames) {
        return None;
    }
    Some(
        (0..frames)
            .map(|k| named.iter().map(|f| f[k].values()[index] as f64).sum())
            .collect(),
    )
}

/// For configurations swept over `scene.lights`: (run, configuration without the light
/// count, light counts, least-squares slope of the frame median in ms per light).
pub fn per_light_costs(results: &[ConfigResult]) -> Vec<(String, String, String, f64)> {
    /// (run, configuration, (light count, frame median) points).
    type Group = (String, String, Vec<(f64, f64)>);
    let mut groups: Vec<Group> = Vec::new();
    for r in results {
        let Some(n) = r.config.lights else { continue };
        let mut config = r.config.clone();
        config.swept.retain(|(k, _)| k != "scene.lights");
        let key = format!(
            "{} {}x{}@{}",
            config.label(),
            config.size.x,
            config.size.y,
            config.tessellation
        );
        let point = (n as f64, r.frame_gpu.median);
        match groups
            .iter_mut()
            .find(|(run, k, _)| *run == r.config.run && *k == key)
        {
            Some((_, _, points)) => points.push(point),
            None => groups.push((r.config.run.clone(), key, vec![point])),
        }
    }
    groups
        .into_iter()
        .filter(|(_, _, points)| points.len() >= 2)
        .map(|(run, key, points)| {
            let count = points.len() as f64;
            let mean_x = points.iter().map(|p| p.0).sum::<f64>() / count;
            let mean_y = points.iter().map(|p| p.1).sum::<f64>() / count;
            let sxy: f64 = points.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
            let sxx: f64 = points.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
            let lights: Vec<String> = points.iter().map(|p| p.0.to_string()).collect();
            (
                run,
                key,
                lights.join(", "),
                sxy / sxx.max(f64::MIN_POSITIVE),
            )
        })
        .collect()
}

/// `bench.md`: readable tables with the environment, ratios and flicker.
pub fn bench_md(
    plans: &[BenchPlan],
    results: &[ConfigResult],
    skipped: &[super::Skipped],
    adapter: &str,
    suite: Option<&suite::Suite>,
) -> String {
    let mut out = String::new();
    let w = &mut out;
    environment_md(w, plans, results, skipped, adapter, suite);
    frame_times_md(w, results);
    light_costs_md(w, results);
    if let Some(s) = suite {
        seeds_md(w, s, results);
    }
    passes_md(w, results);
    counters_md(w, results);
    varying_counters_md(w, results);
    out
}

/// The title, the suite's description and the bullet list of the environment, the runs and
/// the configurations skipped.
fn environment_md(
    w: &mut String,
    plans: &[BenchPlan],
    results: &[ConfigResult],
    skipped: &[super::Skipped],
    adapter: &str,
    suite: Option<&suite::Suite>,
) {
    let title = suite.map_or("Shadow Zoo benchmark".to_string(), |s| {
        format!("Shadow Zoo benchmark suite `{}`", s.name)
    });
    let _ = writeln!(w, "# {title}\n");
    if let Some(s) = suite {
        let _ = writeln!(w, "{}\n", s.description.trim());
    }
    let _ = writeln!(w, "- Date: {}", today());
    let _ = writeln!(w, "- Adapter: {adapter}");
    let _ = writeln!(
        w,
        "- OS: {} ({})",
        std::env::consts::OS,
        std::env::consts::ARCH
    );
    let _ = writeln!(
        w,
        "- Timing: {}",
        results.first().map_or("none", |r| r.timing_source.label())
    );
    for plan in plans {
        let _ = writeln!(
            w,
            "- Run `{}`: scene `{}`, {}x{} (unless swept), {} frames after {} warm-up frames, path: {:?}",
            plan.run,
            plan.scene_path.display(),
            plan.size.x,
            plan.size.y,
            plan.frames,
            plan.warmup,
            plan.path
        );
    }
    for s in skipped {
        let _ = writeln!(
            w,
            "- Skipped `{}`: this adapter cannot run it ({})",
            s.configuration, s.reason
        );
    }
}

/// The main table: each configuration's frame times, ratio to `unshadowed` and flicker.
fn frame_times_md(w: &mut String, results: &[ConfigResult]) {
    let _ = writeln!(
        w,
        "\nFrame times are GPU pass sums (medians over frames); the ratio is to `unshadowed` with the same run, size and tessellation. The flicker index is the mean fraction of pixels whose visibility flips between consecutive frames where the reference visibility does not change.\n"
    );
    let _ = writeln!(
        w,
        "| run | configuration | triangles | frame median (ms) | mean | p95 | technique median (ms) | CPU frame (ms) | × unshadowed | flicker |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|");
    for r in results {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} |",
            r.config.run,
            r.config.label(),
            r.triangles,
            r.frame_gpu.median,
            r.frame_gpu.mean,
            r.frame_gpu.p95,
            r.technique_gpu.median,
            r.frame_cpu.median,
            ratio_to_baseline(results, r).map_or("–".into(), |x| format!("{x:.2}")),
            r.flicker.map_or("–".into(), |x| format!("{x:.5}")),
        );
    }
}

/// The cost of each added light, when a run sweeps `scene.lights`.
fn light_costs_md(w: &mut String, results: &[ConfigResult]) {
    let slopes = per_light_costs(results);
    if slopes.is_empty() {
        return;
    }
    let _ = writeln!(
        w,
        "\n## Cost per added light\n\nLeast-squares slope of the frame median over the `scene.lights` sweep.\n"
    );
    let _ = writeln!(w, "| run | configuration | lights | ms per added light |");
    let _ = writeln!(w, "|---|---|---|---|");
    for (run, label, lights, slope) in slopes {
        let _ = writeln!(w, "| {run} | {label} | {lights} | {slope:.3} |");
    }
}

/// The suite's ratios beside the ones its seeds report, and the seeds' own figures.
fn seeds_md(w: &mut String, suite: &suite::Suite, results: &[ConfigResult]) {
    let ratios = suite_ratios(&suite.ratios, results);
    if !ratios.is_empty() {
        let _ = writeln!(w, "\n## This project beside the seeds\n");
        let _ = writeln!(w, "| ratio | configuration | this project | seed |");
        let _ = writeln!(w, "|---|---|---|---|");
        for row in ratios {
            let mut value =
                (row.value).map_or("not measured on this device".into(), |v| format!("{v:.2}"));
            if let Some((low, high)) = row.frame_range {
                value += &format!(" (frames {low:.2} to {high:.2})");
            }
            let RatioRow {
                label,
                configuration,
                seed,
                ..
            } = row;
            let _ = writeln!(w, "| {label} | {configuration} | {value} | {seed} |");
        }
    }
    if !suite.seed_figures.is_empty() {
        let _ = writeln!(w, "\nWhat the seeds report:\n");
        for f in &suite.seed_figures {
            let _ = writeln!(w, "- {f}");
        }
    }
}

/// Each configuration's pass times, with the counts where they were taken.
fn passes_md(w: &mut String, results: &[ConfigResult]) {
    let _ = writeln!(
        w,
        "\n## Passes (median / p95 ms; vertex / fragment / compute invocations / samples passing \
         the depth and stencil tests, where counted)\n"
    );
    for r in results {
        let passes: Vec<String> = r
            .passes
            .iter()
            .zip(&r.counts)
            .map(|((n, _, s), counts)| match counts.map(|c| c.values()) {
                Some([v, f, c, p]) => {
                    format!("{n} {:.2}/{:.2} ({v}/{f}/{c}/{p})", s.median, s.p95)
                }
                None => format!("{n} {:.2}/{:.2}", s.median, s.p95),
            })
            .collect();
        let _ = writeln!(
            w,
            "- {} `{}`: {}",
            r.config.run,
            r.config.label(),
            passes.join(", ")
        );
    }
}

/// The techniques' workload counters on the last frame.
fn counters_md(w: &mut String, results: &[ConfigResult]) {
    let counted: Vec<&ConfigResult> = results.iter().filter(|r| !r.counters.is_empty()).collect();
    if counted.is_empty() {
        return;
    }
    let _ = writeln!(w, "\n## Workload counters (last frame)\n");
    for r in counted {
        let values: Vec<String> = r.counters.iter().map(|(k, v)| format!("{k} {v}")).collect();
        let _ = writeln!(
            w,
            "- {} `{}`: {}",
            r.config.run,
            r.config.label(),
            values.join(", ")
        );
    }
}

/// The counters that change between frames, with their value on every measured frame.
fn varying_counters_md(w: &mut String, results: &[ConfigResult]) {
    let varying: Vec<&ConfigResult> = results
        .iter()
        .filter(|r| !r.varying_counters.is_empty())
        .collect();
    if varying.is_empty() {
        return;
    }
    let _ = writeln!(
        w,
        "\n## Counters that change between frames (value per measured frame)\n"
    );
    for r in varying {
        for (name, values) in &r.varying_counters {
            let values: Vec<String> = values.iter().map(|v| v.to_string()).collect();
            let _ = writeln!(
                w,
                "- {} `{}` {name}: {}",
                r.config.run,
                r.config.label(),
                values.join(", ")
            );
        }
    }
}

fn file_name(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Draws `passes.png` (every configuration's pass times) and one `sweep-<run>-<sweep>.png`
/// per sweep of each run (frame time against the swept value) into `out`.
pub(super) fn write_plots(
    plans: &[BenchPlan],
    results: &[ConfigResult],
    out: &Path,
) -> anyhow::Result<()> {
    let bars: Vec<plot::Bar> = results.iter().map(pass_family_bar).collect();
    plot::pass_bars(&bars, "Per-pass GPU time (median)", &out.join("passes.png"))?;
    for plan in plans {
        for sweep in &plan.sweeps {
            let lines = sweep_lines(plan, sweep, results);
            if lines.is_empty() {
                continue;
            }
            let x_label = match sweep.key {
                SweepKey::Size => "pixels".to_string(),
                _ => sweep.name.clone(),
            };
            plot::sweep_lines(
                &lines,
                &format!("{}: frame time against {}", plan.run, sweep.name),
                &x_label,
                &out.join(format!(
                    "sweep-{}-{}.png",
                    file_name(&plan.run),
                    file_name(&sweep.name)
                )),
            )?;
        }
    }
    Ok(())
}

/// One configuration's bar, one segment per pass family ("Shadow map: light 0 face 2" ->
/// "Shadow map").
fn pass_family_bar(r: &ConfigResult) -> plot::Bar {
    let mut segments: Vec<(String, f64)> = Vec::new();
    for (name, _, s) in &r.passes {
        let family = name.split(':').next().unwrap_or(name).trim().to_string();
        match segments.iter_mut().find(|(n, _)| *n == family) {
            Some((_, total)) => *total += s.median,
            None => segments.push((family, s.median)),
        }
    }
    plot::Bar {
        label: format!("{}: {}", r.config.run, r.config.label()),
        segments,
    }
}

/// The frame time against the value of `sweep` in run `plan`: one line per technique and
/// values of the run's other sweeps, its points in increasing order.
fn sweep_lines(plan: &BenchPlan, sweep: &Sweep, results: &[ConfigResult]) -> Vec<plot::Line> {
    let x_of = |value: &str| -> Option<f64> {
        match sweep.key {
            SweepKey::Size => parse_size(value).ok().map(|s| (s.x * s.y) as f64),
            _ => value.parse().ok(),
        }
    };
    let mut lines: Vec<plot::Line> = Vec::new();
    for r in results.iter().filter(|r| r.config.run == plan.run) {
        let Some((_, value)) = r.config.swept.iter().find(|(k, _)| *k == sweep.name) else {
            continue;
        };
        let Some(x) = x_of(value) else { continue };
        let name = sweep_line_name(r, sweep);
        match lines.iter_mut().find(|l| l.name == name) {
            Some(line) => line.points.push((x, r.frame_gpu.median)),
            None => lines.push(plot::Line {
                name,
                points: vec![(x, r.frame_gpu.median)],
            }),
        }
    }
    for line in &mut lines {
        line.points.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    lines
}

/// The name of a configuration's line in the plot of `sweep`: its technique, with the
/// values of the other sweeps in brackets.
fn sweep_line_name(r: &ConfigResult, sweep: &Sweep) -> String {
    let others: Vec<String> = r
        .config
        .swept
        .iter()
        .filter(|(k, _)| *k != sweep.name)
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    if others.is_empty() {
        r.config.technique.id.to_string()
    } else {
        format!("{} [{}]", r.config.technique.id, others.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::stats::Summary;
    use zoo_host::gpu::TimingSource;

    /// A result of run `run` for `unshadowed` with `passes` (name, median ms, invocations) and
    /// counters, some varying over three frames.
    fn result(
        run: &str,
        passes: &[(&str, f64, Option<[u64; 4]>)],
        counters: &[(&str, f64)],
        varying: &[(&str, [f64; 3])],
    ) -> ConfigResult {
        let technique = zoo_host::find_technique("unshadowed").unwrap();
        let summary = |ms: f64| Summary::of(&[ms]);
        let total: f64 = passes.iter().map(|p| p.1).sum();
        ConfigResult {
            config: Configuration {
                run: run.into(),
                technique,
                params: zoo_host::params::defaults(&(technique.params)()),
                swept: Vec::new(),
                size: zoo_host::glam::UVec2::new(64, 64),
                tessellation: 1.0,
                lights: None,
            },
            passes: (passes.iter())
                .map(|(name, ms, _)| (name.to_string(), PassOwner::Technique, summary(*ms)))
                .collect(),
            counts: (passes.iter())
                .map(|p| p.2.map(PassCounts::from_values))
                .collect(),
            frame_counts: (passes.iter())
                .map(|p| p.2.map(PassCounts::from_values).into_iter().collect())
                .collect(),
            frame_gpu: summary(total),
            technique_gpu: summary(total),
            frame_cpu: summary(total),
            counters: (counters.iter())
                .map(|(name, value)| (name.to_string(), *value))
                .collect(),
            varying_counters: (varying.iter())
                .map(|(name, values)| (name.to_string(), values.to_vec()))
                .collect(),
            flicker: None,
            timing_source: TimingSource::GpuTimestamps,
            triangles: 0,
        }
    }

    #[test]
    fn measures_are_times_counters_and_invocations() {
        let r = result(
            "a",
            &[
                ("Volumes: light 0", 2.0, Some([3, 100, 0, 40])),
                ("Volumes: light 1", 4.0, Some([5, 300, 0, 20])),
                ("Lighting", 1.0, None),
            ],
            &[("pages", 7.0), ("drawn", 6.0)],
            &[("drawn", [2.0, 4.0, 6.0])],
        );
        assert_eq!(measure(&r, "frame"), Some(7.0));
        assert_eq!(measure(&r, "Volumes"), Some(6.0));
        assert_eq!(measure(&r, "fragments:Volumes"), Some(400.0));
        assert_eq!(measure(&r, "vertices:Volumes"), Some(8.0));
        assert_eq!(measure(&r, "samples:Volumes"), Some(60.0));
        // A count's name is followed by a colon; anything else is a pass prefix.
        assert_eq!(measure(&r, "samplesVolumes"), Some(0.0));
        // Invocations a device did not count, or no pass of that name: not measured.
        assert_eq!(measure(&r, "fragments:Lighting"), None);
        assert_eq!(measure(&r, "fragments:Shadow"), None);
        // A counter that changed is averaged over the frames; one that did not is its value.
        assert_eq!(measure(&r, "counter:drawn"), Some(4.0));
        assert_eq!(measure(&r, "counter:pages"), Some(7.0));
        assert_eq!(measure(&r, "counter:absent"), None);
    }

    #[test]
    fn ratios_divide_any_measure_and_name_what_was_not_measured() {
        let suite: suite::Suite = ron::from_str(
            r#"(name: "t", description: "", runs: [], ratios: [
                (label: "fragments", numerator: (run: "a", technique: "unshadowed",
                    passes: "fragments:Volumes"), denominator: (run: "b",
                    technique: "unshadowed", passes: "fragments:Volumes"), seed: "8-30x"),
                (label: "share", numerator: (run: "a", technique: "unshadowed",
                    passes: "Volumes"), denominator: (run: "a", technique: "unshadowed"),
                    seed: "> 88 %"),
                (label: "unmeasured", numerator: (run: "a", technique: "unshadowed",
                    passes: "fragments:Lighting"), denominator: (run: "b",
                    technique: "unshadowed"), seed: "-"),
            ])"#,
        )
        .unwrap();
        let a = result(
            "a",
            &[
                ("Volumes", 3.0, Some([0, 50, 0, 0])),
                ("Lighting", 1.0, None),
            ],
            &[],
            &[],
        );
        let b = result("b", &[("Volumes", 6.0, Some([0, 1000, 0, 0]))], &[], &[]);
        let ratios = suite_ratios(&suite.ratios, &[a, b]);
        let values: Vec<(&str, Option<f64>)> =
            ratios.iter().map(|r| (r.label.as_str(), r.value)).collect();
        assert_eq!(
            values,
            [
                ("fragments", Some(0.05)),
                ("share", Some(0.75)),
                ("unmeasured", None)
            ]
        );
    }

    #[test]
    fn count_ratios_give_their_range_over_the_frames() {
        let suite: suite::Suite = ron::from_str(
            r#"(name: "t", description: "", runs: [], ratios: [
                (label: "samples", numerator: (run: "a", technique: "unshadowed",
                    passes: "samples:Volumes"), denominator: (run: "b",
                    technique: "unshadowed", passes: "samples:Volumes"), seed: "8-30x"),
                (label: "time", numerator: (run: "a", technique: "unshadowed",
                    passes: "Volumes"), denominator: (run: "b", technique: "unshadowed",
                    passes: "Volumes"), seed: "-"),
            ])"#,
        )
        .unwrap();
        let per_frame = |samples: &[[u64; 2]]| -> Vec<Vec<PassCounts>> {
            (0..2)
                .map(|pass| {
                    (samples.iter())
                        .map(|s| PassCounts::from_values([0, 0, 0, s[pass]]))
                        .collect()
                })
                .collect()
        };
        let passes = [
            ("Volumes: light 0", 1.0, Some([0, 0, 0, 100])),
            ("Volumes: light 1", 1.0, Some([0, 0, 0, 100])),
        ];
        let mut a = result("a", &passes, &[], &[]);
        let mut b = result("b", &passes, &[], &[]);
        // Frame by frame, both lights' samples: 300/30, 200/20 and 90/30.
        a.frame_counts = per_frame(&[[100, 200], [150, 50], [40, 50]]);
        b.frame_counts = per_frame(&[[10, 20], [10, 10], [10, 20]]);
        let ratios = suite_ratios(&suite.ratios, &[a.clone(), b.clone()]);
        assert_eq!(ratios[0].frame_range, Some((3.0, 10.0)));
        // Times have no per-frame series here.
        assert_eq!(ratios[1].frame_range, None);
        // Series of different lengths, or a frame with no samples below, give no range.
        b.frame_counts = per_frame(&[[10, 20], [10, 10]]);
        assert_eq!(
            suite_ratios(&suite.ratios, &[a.clone(), b.clone()])[0].frame_range,
            None
        );
        b.frame_counts = per_frame(&[[10, 20], [10, 10], [0, 0]]);
        assert_eq!(suite_ratios(&suite.ratios, &[a, b])[0].frame_range, None);
    }

    #[test]
    fn ratios_can_divide_two_configurations_of_one_sweep() {
        let suite: suite::Suite = ron::from_str(
            r#"(name: "t", description: "", runs: [], ratios: [
                (label: "wide over narrow", numerator: (run: "a", technique: "unshadowed",
                    swept: [("k", "wide")]), denominator: (run: "a", technique: "unshadowed",
                    swept: [("k", "narrow")]), seed: "-"),
            ])"#,
        )
        .unwrap();
        let swept = |kernel: &str, lights: &str, ms: f64| {
            let mut r = result("a", &[("Lookup", ms, None)], &[], &[]);
            r.config.swept = vec![
                ("k".to_string(), kernel.to_string()),
                ("scene.lights".to_string(), lights.to_string()),
            ];
            r
        };
        let results = [
            swept("narrow", "1", 2.0),
            swept("wide", "1", 6.0),
            swept("narrow", "4", 4.0),
            swept("wide", "4", 20.0),
        ];
        let values: Vec<Option<f64>> = (suite_ratios(&suite.ratios, &results).iter())
            .map(|r| r.value)
            .collect();
        // Each wide configuration over the narrow one with the same light count.
        assert_eq!(values, [Some(3.0), Some(5.0)]);
    }
}
