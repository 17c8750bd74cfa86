//! `shadow-zoo claims`: the sources' headline claims reproduced in one report. Each claim of
//! `scenes/claims/claims.ron` is measured by a bench suite's ratio (its runs trimmed to the
//! configurations the ratio divides, a few frames each, in one benchmark; on a software
//! adapter timed on the CPU clock) or, for the claims
//! seed 000 makes without numbers, by the judge; `claims.md` and `claims.csv` put the source's
//! figure beside the one measured here, with the adapter and which way it skews the ratio.

mod judged;
mod list;
mod ratios;
mod report;

use web_time::Instant;

use anyhow::{Context, bail};

pub use list::{ClaimList, JudgedClaim, RatioClaim, load, locate};
pub use ratios::{CLAIM_FRAMES, ClaimPlans};
pub use report::{claims_csv, claims_md};

use crate::cli::ClaimsArgs;

/// One claim as measured here (a claim measured at several configurations has a row each).
#[derive(Debug, Clone, PartialEq)]
pub struct ClaimRow {
    pub claim: String,
    pub source: String,
    /// The source's figure.
    pub figure: String,
    /// The figure measured here; `None` where this adapter could not measure it.
    pub measured: Option<f64>,
    /// What was measured: sizes and sweep values, or the scene, technique and light judged.
    pub configuration: String,
    /// Which way the adapter skews it.
    pub skew: String,
}

/// Checks every claim of `list` (scenes relative to `dir`) without measuring: each ratio found
/// in its suite, its runs planned, each judged claim's scene, technique, parameters and metric.
pub fn check(list: &ClaimList, dir: &std::path::Path) -> anyhow::Result<ClaimPlans> {
    for claim in &list.judged {
        judged::prepare(claim, dir)
            .with_context(|| format!("claim `{}` ({})", claim.claim, claim.source))?;
    }
    ratios::plan(&list.ratios, false)
}

/// Whether passes are timed on the CPU clock on `gpu`: on a software adapter, whose
/// timestamps do not span compute dispatches (lavapipe's read near 0) and whose passes all run
/// on the CPU anyway.
pub fn times_on_cpu(gpu: &zoo_host::GpuContext) -> bool {
    gpu.info.device_type == zoo_host::wgpu::DeviceType::Cpu
}

/// Runs `shadow-zoo claims`.
pub fn run(args: &ClaimsArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let path = locate()?;
    let claims = load(&path)?.only(args.only.as_deref());
    if claims.ratios.is_empty() && claims.judged.is_empty() {
        bail!(
            "no claim in {} matches --only {}",
            path.display(),
            args.only.as_deref().unwrap_or_default()
        );
    }
    let dir = path.parent().unwrap_or(std::path::Path::new("."));
    // Every claim resolves before minutes of measuring.
    check(&claims, dir)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output folder {}", args.out.display()))?;
    let shaders = crate::setup::shader_library(args.shaders.as_deref())?;
    let gpu = crate::setup::headless_gpu()?;
    let cpu_timing = times_on_cpu(&gpu);
    let bench = args.out.join("bench");
    let (mut rows, skipped) = ratios::measure(&claims.ratios, &shaders, &bench, cpu_timing)?;
    rows.extend(judged::measure(&claims.judged, dir, &gpu, &shaders)?);
    let adapter = gpu.describe();
    let seconds = started.elapsed().as_secs_f64();
    std::fs::write(args.out.join("claims.csv"), claims_csv(&rows, &adapter))?;
    let timing = if cpu_timing {
        "CPU clock, each pass submitted on its own (a software adapter); counts of fragments \
         and samples from runs of their own with the GPU's statistics"
    } else {
        "GPU timestamps"
    };
    std::fs::write(
        args.out.join("claims.md"),
        claims_md(&rows, &skipped, &adapter, timing, seconds),
    )?;
    for row in &rows {
        let measured = row.measured.map_or("-".into(), |m| format!("{m:.3}"));
        println!(
            "  {measured:>9}  {} ({}): {}",
            row.claim, row.source, row.figure
        );
    }
    println!(
        "wrote {0}/claims.md and claims.csv ({1:.0} s; the benchmark's outputs in {0}/bench)",
        args.out.display(),
        seconds
    );
    Ok(())
}
