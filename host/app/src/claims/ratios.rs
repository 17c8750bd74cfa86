//! Claims measured by bench suites' ratios: the runs they need, trimmed to the configurations
//! the ratios divide and to a few frames, measured in one benchmark.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use zoo_host::ShaderLibrary;

use super::ClaimRow;
use super::list::RatioClaim;
use crate::bench::suite::{self, Measure, SuiteRatio, SuiteRun};
use crate::bench::{self, BenchPlan, BenchRun, RunOptions, Skipped};

/// Frames each run measures at most, after at most two warm-up frames: a ratio from one run,
/// not a suite's full statistics.
pub const CLAIM_FRAMES: u32 = 8;

/// A run a claim needs, under its name in the claims' benchmark (`SUITE: RUN`).
struct NeededRun {
    dir: PathBuf,
    run: SuiteRun,
    measures: Vec<Measure>,
}

/// The benchmark that measures ratio claims: its plans, the runs whose files are absent, and
/// each claim's ratio, its runs renamed `SUITE: RUN`.
pub struct ClaimPlans {
    pub plans: Vec<BenchPlan>,
    pub absent: Vec<Skipped>,
    pub ratios: Vec<SuiteRatio>,
}

/// Resolves `claims` into one benchmark: finds each ratio in its suite and the runs it needs,
/// trims them and plans them (scenes, techniques and sweeps checked). With `cpu_timing`, the
/// runs that are timed time each pass on the CPU clock; runs that only count (fragments,
/// samples, counters) keep the GPU's pipeline statistics, which CPU timing goes without.
pub fn plan(claims: &[RatioClaim], cpu_timing: bool) -> anyhow::Result<ClaimPlans> {
    let mut needed: BTreeMap<String, NeededRun> = BTreeMap::new();
    let mut ratios = Vec::new();
    for claim in claims {
        let ratio = claim_ratio(claim, cpu_timing, &mut needed)
            .with_context(|| format!("claim `{}` ({})", claim.claim, claim.source))?;
        ratios.push(ratio);
    }
    let mut plans = Vec::new();
    let mut absent = Vec::new();
    for (name, needed) in needed {
        let options = RunOptions {
            cpu_timing: cpu_timing && !needed.measures.iter().any(Measure::is_count),
            baseline: false,
            ..RunOptions::default()
        };
        let run = trimmed(needed.run, &needed.measures)?;
        let (mut p, mut a) = bench::plans_of_runs(&[run], &needed.dir, &options)
            .with_context(|| format!("run {name}"))?;
        plans.append(&mut p);
        absent.append(&mut a);
    }
    Ok(ClaimPlans {
        plans,
        absent,
        ratios,
    })
}

/// Measures `claims` in one benchmark written to `out` (see [`plan`] for `cpu_timing`): a row
/// per claim and configuration, and what was skipped.
pub fn measure(
    claims: &[RatioClaim],
    shaders: &ShaderLibrary,
    out: &Path,
    cpu_timing: bool,
) -> anyhow::Result<(Vec<ClaimRow>, Vec<Skipped>)> {
    if claims.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    let ClaimPlans {
        plans,
        absent,
        ratios,
    } = plan(claims, cpu_timing)?;
    let BenchRun { results, skipped } = bench::run_plans(&plans, shaders, out, None, absent)?;
    let rows = claims
        .iter()
        .zip(&ratios)
        .flat_map(|(claim, ratio)| {
            let measured = bench::suite_ratios(std::slice::from_ref(ratio), &results);
            let not_measured = measured.is_empty().then(|| ClaimRow {
                claim: claim.claim.clone(),
                source: claim.source.clone(),
                figure: ratio.seed.clone(),
                measured: None,
                configuration: "not measured here (see the skipped configurations)".into(),
                skew: claim.skew.clone(),
            });
            (measured.into_iter())
                .map(|row| ClaimRow {
                    claim: claim.claim.clone(),
                    source: claim.source.clone(),
                    figure: row.seed,
                    measured: row.value,
                    configuration: match row.frame_range {
                        Some((low, high)) => {
                            format!(
                                "{}; frame by frame {low:.2} to {high:.2}",
                                row.configuration
                            )
                        }
                        None => row.configuration,
                    },
                    skew: claim.skew.clone(),
                })
                .chain(not_measured)
                .collect::<Vec<_>>()
        })
        .collect();
    Ok((rows, skipped))
}

/// The suite ratio `claim` names, its runs renamed `SUITE: RUN` and pinned to the claim's
/// sweep values; the runs it needs are added to `needed`. With `cpu_timing`, a count's run is
/// measured apart, `SUITE: RUN (counted)`, with the GPU's statistics.
fn claim_ratio(
    claim: &RatioClaim,
    cpu_timing: bool,
    needed: &mut BTreeMap<String, NeededRun>,
) -> anyhow::Result<SuiteRatio> {
    let path = suite::locate(&claim.suite)?;
    let s = suite::load(&path)?;
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let Some(ratio) = s.ratios.iter().find(|r| r.label == claim.ratio) else {
        bail!("suite {} has no ratio labelled `{}`", s.name, claim.ratio);
    };
    let mut ratio = ratio.clone();
    let mut pinned = vec![false; claim.at.len()];
    for measure in [&mut ratio.numerator, &mut ratio.denominator] {
        let run = (s.runs.iter())
            .find(|r| r.name == measure.run)
            .with_context(|| format!("suite {} has no run `{}`", s.name, measure.run))?;
        for (i, (key, value)) in claim.at.iter().enumerate() {
            if let Some((_, values)) = run.sweeps.iter().find(|(k, _)| k == key)
                && !values.contains(value)
            {
                bail!(
                    "`at` {key}={value}: run `{}` sweeps {key} over {} only",
                    run.name,
                    values.join(", ")
                );
            }
            if sweeps(run, key, &measure.technique)? {
                if let Some((_, own)) = measure.swept.iter().find(|(k, _)| k == key)
                    && own != value
                {
                    bail!("`at` {key}={value}: the ratio itself takes {key}={own}");
                }
                measure.swept.push((key.clone(), value.clone()));
                pinned[i] = true;
            }
        }
        let counted = if cpu_timing && measure.is_count() {
            " (counted)"
        } else {
            ""
        };
        measure.run = format!("{}: {}{counted}", s.name, run.name);
        let entry = needed
            .entry(measure.run.clone())
            .or_insert_with(|| NeededRun {
                dir: dir.clone(),
                run: SuiteRun {
                    name: measure.run.clone(),
                    ..run.clone()
                },
                measures: Vec::new(),
            });
        entry.measures.push(measure.clone());
    }
    if let Some(i) = pinned.iter().position(|p| !p) {
        bail!(
            "`at` names {}, which sweeps neither of the ratio's measures",
            claim.at[i].0
        );
    }
    Ok(ratio)
}

/// Whether `run` sweeps `key` over `technique`'s configurations.
fn sweeps(run: &SuiteRun, key: &str, technique: &str) -> anyhow::Result<bool> {
    let Some((_, values)) = run.sweeps.iter().find(|(k, _)| k == key) else {
        return Ok(false);
    };
    Ok(bench::parse_sweep(key, values)?.key.applies_to(technique))
}

/// `run` with only the techniques `measures` divide, each sweep only at the values they pin
/// where all the measures it sweeps pin it, and at most [`CLAIM_FRAMES`] frames after at most
/// two warm-up frames.
fn trimmed(mut run: SuiteRun, measures: &[Measure]) -> anyhow::Result<SuiteRun> {
    // The baseline is measured where a ratio divides by it, whether the run names it or not.
    let baseline = zoo_host::builtin::UNSHADOWED_ID;
    if !run.techniques.iter().any(|t| t == baseline) {
        run.techniques.push(baseline.to_string());
    }
    run.techniques
        .retain(|t| measures.iter().any(|m| &m.technique == t));
    let unchanged = run.clone();
    for (key, values) in &mut run.sweeps {
        let mut pins = Vec::new();
        let mut all_pinned = true;
        for m in measures {
            if !sweeps(&unchanged, key, &m.technique)? {
                continue;
            }
            match m.swept.iter().find(|(k, _)| k == key) {
                Some((_, value)) => pins.push(value.clone()),
                None => all_pinned = false,
            }
        }
        if all_pinned && !pins.is_empty() {
            values.retain(|v| pins.contains(v));
        }
    }
    run.frames = run.frames.min(CLAIM_FRAMES);
    run.warmup = run.warmup.min(2);
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measure(technique: &str, swept: &[(&str, &str)]) -> Measure {
        Measure {
            run: "r".into(),
            technique: technique.into(),
            passes: "frame".into(),
            swept: (swept.iter())
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        }
    }

    #[test]
    fn runs_keep_only_what_the_ratios_divide() {
        let run: SuiteRun = ron::from_str(
            r#"(name: "r", scene: "s.ron", techniques: ["sm-pcf", "vsm", "unshadowed"],
                frames: 10, warmup: 3, sweeps: [("size", ["128x128", "256x256"]),
                ("sm-pcf.map_size", ["512", "1024", "2048"])])"#,
        )
        .unwrap();
        // vsm is not swept over sm-pcf's map size: sm-pcf's pins are all that count.
        let measures = [
            measure("sm-pcf", &[("sm-pcf.map_size", "2048")]),
            measure("sm-pcf", &[("sm-pcf.map_size", "512")]),
            measure("vsm", &[("size", "256x256")]),
        ];
        let run = trimmed(run, &measures).unwrap();
        assert_eq!(run.techniques, ["sm-pcf", "vsm"]);
        // Not pinned by every measure it sweeps: every size; pinned by all: theirs only.
        assert_eq!(run.sweeps[0].1, ["128x128", "256x256"]);
        assert_eq!(run.sweeps[1].1, ["512", "2048"]);
        assert_eq!((run.frames, run.warmup), (CLAIM_FRAMES, 2));
    }
}
