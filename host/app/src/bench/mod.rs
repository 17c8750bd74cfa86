//! `shadow-zoo bench`: techniques rendered along the scene's camera and light paths after a
//! warm-up, with per-pass GPU times, CPU frame times, workload counters and a flicker index,
//! summarised as CSV, markdown and PNG plots. Ratios to `unshadowed` in the same run are the
//! currency on a software driver.

pub mod flicker;
mod measure;
mod plan;
pub mod plot;
mod report;
pub mod stats;
pub mod suite;

use std::path::Path;

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use zoo_host::render::RenderError;
use zoo_host::{ShaderLibrary, TechniqueError};

use crate::cli::BenchArgs;
pub use crate::cli::PathMode;

pub use measure::*;
pub use plan::*;
pub use report::*;

/// A configuration this adapter cannot run (a technique, or a choice of one, needs a device
/// feature it lacks), left out of the results.
#[derive(Debug, Clone, PartialEq)]
pub struct Skipped {
    /// The configuration, as `run: label`.
    pub configuration: String,
    pub reason: String,
}

/// What a benchmark measured, and what it had to leave out.
pub struct BenchRun {
    pub results: Vec<ConfigResult>,
    pub skipped: Vec<Skipped>,
}

/// Whether `error` says the technique cannot run on this device (rather than that it failed).
fn is_unavailable(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        let technique = cause.downcast_ref::<TechniqueError>().or_else(|| {
            match cause.downcast_ref::<RenderError>() {
                Some(RenderError::Technique(t)) => Some(t),
                _ => None,
            }
        });
        matches!(technique, Some(TechniqueError::Unavailable { .. }))
    })
}

/// Runs plans with `shaders`, writes the outputs, and returns the results. Configurations this
/// adapter cannot run are skipped and listed beside the `absent` runs (those whose files are
/// missing); any other failure stops the benchmark.
pub fn run_plans(
    plans: &[BenchPlan],
    shaders: &ShaderLibrary,
    out: &Path,
    suite: Option<&suite::Suite>,
    absent: Vec<Skipped>,
) -> anyhow::Result<BenchRun> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output folder {}", out.display()))?;
    let probe = out.join("bench.csv");
    std::fs::write(&probe, "")
        .with_context(|| format!("output folder {} is not writable", out.display()))?;
    let configs: Vec<(usize, Configuration)> = plans
        .iter()
        .enumerate()
        .map(|(i, plan)| expand(plan).map(|c| c.into_iter().map(move |c| (i, c))))
        .collect::<anyhow::Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let gpu = crate::setup::headless_gpu()?;
    let total: u64 = configs
        .iter()
        .map(|(i, _)| (plans[*i].frames + plans[*i].warmup) as u64)
        .sum();
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {msg} [{elapsed}<{eta}]")
            .expect("valid template"),
    );
    let mut results = Vec::new();
    let mut skipped = absent;
    for (i, config) in &configs {
        bar.set_message(config.label());
        match run_configuration(&gpu, shaders, &plans[*i], config, || bar.inc(1)) {
            Ok(result) => results.push(result),
            Err(e) if is_unavailable(&e) => {
                bar.inc(u64::from(plans[*i].frames + plans[*i].warmup));
                skipped.push(Skipped {
                    configuration: format!("{}: {}", config.run, config.label()),
                    reason: format!("{e:#}"),
                });
            }
            Err(e) => return Err(e.context(format!("{} in run {}", config.label(), config.run))),
        }
    }
    bar.finish_and_clear();
    let adapter = gpu.describe();
    std::fs::write(out.join("bench.csv"), bench_csv(&results))?;
    std::fs::write(out.join("summary.csv"), summary_csv(&results))?;
    std::fs::write(
        out.join("bench.md"),
        bench_md(plans, &results, &skipped, &adapter, suite),
    )?;
    write_plots(plans, &results, out)?;
    Ok(BenchRun { results, skipped })
}

/// How suite runs are measured: `bench`'s flags, or the claims report's choices.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// Measured frames instead of each run's own.
    pub frames: Option<u32>,
    /// Whether to measure flicker (against the judge's reference, frame by frame).
    pub flicker: bool,
    pub cpu_timing: bool,
    pub reuse_unchanged: bool,
    /// Whether `unshadowed` is measured beside every run (the ratios to it in `bench.md`).
    pub baseline: bool,
}

impl RunOptions {
    /// The options `bench`'s flags give.
    fn of(args: &BenchArgs) -> RunOptions {
        RunOptions {
            frames: args.frames,
            flicker: !args.no_flicker,
            cpu_timing: args.cpu_timing,
            reuse_unchanged: args.reuse_unchanged,
            baseline: true,
        }
    }
}

/// The plans of suite `name`'s runs, the suite, and the runs skipped because files they need
/// are absent.
fn suite_plans(
    name: &str,
    args: &BenchArgs,
) -> anyhow::Result<(Vec<BenchPlan>, suite::Suite, Vec<Skipped>)> {
    let path = suite::locate(name)?;
    let s = suite::load(&path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let (plans, absent) = plans_of_runs(&s.runs, dir, &RunOptions::of(args))
        .with_context(|| format!("suite {}", path.display()))?;
    Ok((plans, s, absent))
}

/// The plans of `runs` (their scenes relative to the suite's folder `dir`), and the runs
/// skipped because files they need are absent.
pub fn plans_of_runs(
    runs: &[suite::SuiteRun],
    dir: &Path,
    options: &RunOptions,
) -> anyhow::Result<(Vec<BenchPlan>, Vec<Skipped>)> {
    let absent = (runs.iter())
        .filter_map(|run| {
            let reason = run.missing(dir)?;
            let configuration = format!("{}: every configuration", run.name);
            Some(Skipped {
                configuration,
                reason,
            })
        })
        .collect();
    let plans = (runs.iter())
        .filter(|run| run.missing(dir).is_none())
        .map(|run| suite_run_plan(run, dir, options))
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok((plans, absent))
}

/// The plan of one suite run (its scene relative to the suite's folder `dir`).
fn suite_run_plan(
    run: &suite::SuiteRun,
    dir: &Path,
    options: &RunOptions,
) -> anyhow::Result<BenchPlan> {
    let scene_path = dir.join(&run.scene);
    let mut techniques = (run.techniques.iter())
        .map(|t| zoo_host::find_technique(t).map_err(anyhow::Error::from))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let baseline = zoo_host::find_technique(zoo_host::builtin::UNSHADOWED_ID)?;
    if options.baseline && !techniques.iter().any(|t| t.id == baseline.id) {
        techniques.insert(0, baseline);
    }
    Ok(BenchPlan {
        run: run.name.clone(),
        description: zoo_host::scene::read_description(&scene_path)?,
        scene_path,
        size: zoo_host::glam::UVec2::new(run.size.0, run.size.1),
        frames: options.frames.unwrap_or(run.frames),
        warmup: run.warmup,
        path: run.path,
        sweeps: (run.sweeps.iter())
            .map(|(k, v)| parse_sweep(k, v))
            .collect::<anyhow::Result<_>>()?,
        set: split_sets(&run.set, &techniques)?,
        techniques,
        flicker: options.flicker,
        cpu_timing: options.cpu_timing,
        reuse_unchanged: options.reuse_unchanged || run.reuse_unchanged,
    })
}

/// Runs `shadow-zoo bench`.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let (plans, suite, absent) = match (&args.suite, &args.scene) {
        (Some(name), _) => {
            let (plans, suite, absent) = suite_plans(name, args)?;
            (plans, Some(suite), absent)
        }
        (None, Some(scene)) => (vec![plan_from_args(args, scene)?], None, Vec::new()),
        (None, None) => bail!("give --scene FILE or --suite NAME"),
    };
    if plans.iter().any(|p| p.frames == 0) {
        bail!("--frames must be at least 1");
    }
    let shaders = crate::setup::shader_library(args.shaders.as_deref())?;
    let BenchRun { results, skipped } =
        run_plans(&plans, &shaders, &args.out, suite.as_ref(), absent)?;
    for r in &results {
        println!(
            "  {:10} {:50} frame {:8.2} ms  {}  flicker {}",
            r.config.run,
            r.config.label(),
            r.frame_gpu.median,
            ratio_to_baseline(&results, r).map_or("         ".into(), |x| format!("x{x:7.2}")),
            r.flicker.map_or("-".into(), |f| format!("{f:.5}"))
        );
    }
    for s in &skipped {
        println!("  skipped {}: {}", s.configuration, s.reason);
    }
    println!(
        "wrote {}/bench.csv, summary.csv, bench.md and plots",
        args.out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_what_the_device_cannot_run_is_skipped() {
        let unavailable = TechniqueError::Unavailable {
            id: "rt-shadows".into(),
            reason: "needs hardware ray queries".into(),
        };
        let wrapped = anyhow::Error::from(RenderError::Technique(unavailable.clone()))
            .context("rt-shadows in run ray-queries");
        assert!(is_unavailable(&wrapped));
        assert!(is_unavailable(&anyhow::Error::from(unavailable)));
        let failed = TechniqueError::Validation {
            id: "rt-shadows".into(),
            message: "bad binding".into(),
        };
        assert!(!is_unavailable(&anyhow::Error::from(
            RenderError::Technique(failed)
        )));
        assert!(!is_unavailable(&anyhow::anyhow!(
            "scene.lights=8 but the scene has 1"
        )));
    }
}
