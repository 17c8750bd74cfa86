//! Claims the judge shows: a technique rendered on a scene and judged, its worst light's metric.

use std::path::Path;
use std::sync::Arc;

use anyhow::Context;
use zoo_host::judge::Metric;
use zoo_host::judging::{DEFAULT_SAMPLES, SceneReference, judge_technique};
use zoo_host::{GpuContext, Renderer, Scene, ShaderLibrary, params};

use super::ClaimRow;
use super::list::JudgedClaim;

/// What the judge measures for `claims` (scenes relative to `dir`), one row each.
pub fn measure(
    claims: &[JudgedClaim],
    dir: &Path,
    gpu: &Arc<GpuContext>,
    shaders: &ShaderLibrary,
) -> anyhow::Result<Vec<ClaimRow>> {
    (claims.iter())
        .map(|claim| {
            judge(claim, dir, gpu, shaders)
                .with_context(|| format!("claim `{}` ({})", claim.claim, claim.source))
        })
        .collect()
}

/// What judging `claim` takes, checked without rendering: its metric, its technique's
/// parameters and its scene (relative to `dir`).
pub fn prepare(
    claim: &JudgedClaim,
    dir: &Path,
) -> anyhow::Result<(Metric, params::ParamValues, Scene)> {
    let metric = Metric::named(&claim.metric).with_context(|| {
        let names: Vec<_> = Metric::ALL.iter().map(|m| m.name()).collect();
        format!(
            "no metric `{}` (metrics: {})",
            claim.metric,
            names.join(", ")
        )
    })?;
    let registration = zoo_host::find_technique(&claim.technique)?;
    let schema = (registration.params)();
    let mut values = params::defaults(&schema);
    params::apply_assignments(&schema, &mut values, &claim.set)?;
    let scene = Scene::load(&dir.join(&claim.scene))?;
    Ok((metric, values, scene))
}

fn judge(
    claim: &JudgedClaim,
    dir: &Path,
    gpu: &Arc<GpuContext>,
    shaders: &ShaderLibrary,
) -> anyhow::Result<ClaimRow> {
    let (metric, values, scene) = prepare(claim, dir)?;
    let size = zoo_host::glam::UVec2::new(claim.size.0, claim.size.1);
    let mut renderer = Renderer::with_shaders(gpu.clone(), scene, size, shaders.clone())?;
    let reference = SceneReference::compute(&mut renderer, DEFAULT_SAMPLES, |_| {})?;
    let judged = judge_technique(&mut renderer, &reference, &claim.technique, &values)?;
    let worst = (judged.scores.iter())
        .filter_map(|s| s.metrics.map(|m| (s.light, metric.of(&m))))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    let set: Vec<String> = (claim.set.iter())
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    let configuration = format!(
        "{} at {}x{}, {}{}: {} of the worst light{}",
        claim.scene,
        size.x,
        size.y,
        claim.technique,
        if set.is_empty() {
            String::new()
        } else {
            format!(" [{}]", set.join(", "))
        },
        metric.name(),
        worst.map_or(" (no light it supports)".into(), |(light, _)| format!(
            " ({light})"
        )),
    );
    Ok(ClaimRow {
        claim: claim.claim.clone(),
        source: claim.source.clone(),
        figure: claim.figure.clone(),
        measured: worst.map(|(_, value)| value),
        configuration,
        skew: "none: visibility, not time".into(),
    })
}
