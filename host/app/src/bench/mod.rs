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
use zoo_host::ShaderLibrary;

use crate::cli::BenchArgs;
pub use crate::cli::PathMode;

pub use measure::*;
pub use plan::*;
pub use report::*;

/// Runs plans with `shaders`, writes the outputs, and returns the results.
pub fn run_plans(
    plans: &[BenchPlan],
    shaders: &ShaderLibrary,
    out: &Path,
    suite: Option<&suite::Suite>,
) -> anyhow::Result<Vec<ConfigResult>> {
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
    for (i, config) in &configs {
        bar.set_message(config.label());
        let result = run_configuration(&gpu, shaders, &plans[*i], config, || bar.inc(1))
            .with_context(|| format!("{} in run {}", config.label(), config.run))?;
        results.push(result);
    }
    bar.finish_and_clear();
    let adapter = gpu.describe();
    std::fs::write(out.join("bench.csv"), bench_csv(&results))?;
    std::fs::write(out.join("summary.csv"), summary_csv(&results))?;
    std::fs::write(
        out.join("bench.md"),
        bench_md(plans, &results, &adapter, suite),
    )?;
    write_plots(plans, &results, out)?;
    Ok(results)
}

/// Runs `shadow-zoo bench`.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let (plans, suite) = match (&args.suite, &args.scene) {
        (Some(name), _) => {
            let path = suite::locate(name)?;
            let s = suite::load(&path)?;
            let dir = path.parent().unwrap_or(Path::new("."));
            let plans = s
                .runs
                .iter()
                .map(|run| {
                    let scene_path = dir.join(&run.scene);
                    let mut techniques = run
                        .techniques
                        .iter()
                        .map(|t| zoo_host::find_technique(t).map_err(anyhow::Error::from))
                        .collect::<anyhow::Result<Vec<_>>>()?;
                    let baseline = zoo_host::find_technique(zoo_host::builtin::UNSHADOWED_ID)?;
                    if !techniques.iter().any(|t| t.id == baseline.id) {
                        techniques.insert(0, baseline);
                    }
                    Ok(BenchPlan {
                        run: run.name.clone(),
                        description: zoo_host::scene::read_description(&scene_path)?,
                        scene_path,
                        size: zoo_host::glam::UVec2::new(run.size.0, run.size.1),
                        frames: args.frames.unwrap_or(run.frames),
                        warmup: run.warmup,
                        path: run.path,
                        sweeps: run
                            .sweeps
                            .iter()
                            .map(|(k, v)| parse_sweep(k, v))
                            .collect::<anyhow::Result<_>>()?,
                        set: split_sets(&run.set, &techniques)?,
                        techniques,
                        flicker: !args.no_flicker,
                        cpu_timing: args.cpu_timing,
                        reuse_unchanged: args.reuse_unchanged,
                    })
                })
                .collect::<anyhow::Result<Vec<_>>>()
                .with_context(|| format!("suite {}", path.display()))?;
            (plans, Some(s))
        }
        (None, Some(scene)) => (vec![plan_from_args(args, scene)?], None),
        (None, None) => bail!("give --scene FILE or --suite NAME"),
    };
    if plans.iter().any(|p| p.frames == 0) {
        bail!("--frames must be at least 1");
    }
    let shaders = crate::setup::shader_library(args.shaders.as_deref())?;
    let results = run_plans(&plans, &shaders, &args.out, suite.as_ref())?;
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
    println!(
        "wrote {}/bench.csv, summary.csv, bench.md and plots",
        args.out.display()
    );
    Ok(())
}
