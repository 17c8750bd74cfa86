//! `compare --judge gpu`: the reference visibility traced on the GPU by the ray-tracing library,
//! through the `rt-shadows` technique: one ray to each light's centre for hard visibility, and
//! `samples` rays over its disk, cosine-weighted and unfiltered, for area visibility. Which
//! pixels each light reaches comes from the CPU judge's own located surfaces, so both judges
//! score the same pixels. The CPU judge stays the arbiter (`tests/zoo/gpu_judge.rs` measures
//! their agreement).

use std::time::Instant;

use anyhow::{Context, bail};
use zoo_host::judge::{LightReference, Surfaces};
use zoo_host::judging::{SceneReference, surface_points};
use zoo_host::params::{ParamValue, ParamValues, defaults};
use zoo_host::render::View;
use zoo_host::scene::shading::contributes;
use zoo_host::{Renderer, Scene, find_technique};

/// The technique that traces the GPU reference.
pub const TRACER: &str = "rt-shadows";

/// Most area rays per pixel the tracer takes.
pub const MAX_SAMPLES: u32 = 64;

/// An error, from `caller` and pointing to `instead`, when `scene` has translucent casters
/// (the tracer does not filter light through them yet).
pub fn check_traceable(scene: &Scene, caller: &str, instead: &str) -> anyhow::Result<()> {
    if scene.has_translucent_casters() {
        bail!(
            "{caller}: scene {} has translucent casters, which the GPU tracer does not filter \
             light through yet; use {instead}",
            scene.name
        );
    }
    Ok(())
}

/// The tracer's parameters for reference rays: `rays` a pixel and light each frame,
/// unfiltered, averaged over `frames` frames of a still view (1: each frame on its own).
pub fn tracer_values(rays: u32, frames: u32) -> anyhow::Result<ParamValues> {
    let tracer = find_technique(TRACER).context("the GPU judge traces with rt-shadows")?;
    let mut values: ParamValues = defaults(&(tracer.params)());
    values.insert("rays_per_pixel".into(), ParamValue::Int(i64::from(rays)));
    values.insert("denoise_radius".into(), ParamValue::Int(0));
    values.insert("accumulation".into(), ParamValue::Int(i64::from(frames)));
    Ok(values)
}

/// A light's reference from traced `hard` and `area` visibility (`samples` area rays a
/// pixel), counted where `contributing` and 1 elsewhere, as the CPU judge's.
pub fn light_reference(
    contributing: Vec<bool>,
    hard: Vec<f32>,
    area: Vec<f32>,
    samples: u32,
) -> LightReference {
    let keep = |values: Vec<f32>| -> Vec<f32> {
        (values.into_iter().zip(&contributing))
            .map(|(v, &c)| if c { v } else { 1.0 })
            .collect()
    };
    LightReference {
        hard: keep(hard),
        area: keep(area),
        contributing,
        color: None,
        samples,
    }
}

/// Traces the reference of `renderer`'s current view on the GPU with `samples` area rays per
/// pixel (at most [`MAX_SAMPLES`]). Scenes with translucent casters are refused: the tracer
/// does not filter light through them yet.
pub fn trace_reference(renderer: &mut Renderer, samples: u32) -> anyhow::Result<SceneReference> {
    check_traceable(renderer.scene(), "--judge gpu", "--judge cpu")?;
    // Any technique leaves the G-buffer the same; render one frame to fill it.
    renderer.render(&View::Final)?;
    let gbuffer = renderer.read_gbuffer();
    let points = surface_points(&gbuffer, &Surfaces::new(renderer.scene()));

    let start = Instant::now();
    let samples = samples.clamp(1, MAX_SAMPLES);
    let traced = |renderer: &mut Renderer, rays: u32| -> anyhow::Result<Vec<Vec<f32>>> {
        // One frame of unfiltered rays: the reference's samples, nothing averaged in.
        renderer.set_technique(TRACER, &tracer_values(rays, 1)?)?;
        renderer.render(&View::Final)?;
        Ok((0..renderer.lights().len())
            .map(|light| renderer.read_visibility(light))
            .collect())
    };
    let hard = traced(renderer, 1)?;
    let area = traced(renderer, samples)?;
    let seconds = start.elapsed().as_secs_f64();

    let lights = renderer
        .lights()
        .iter()
        .zip(hard.into_iter().zip(area))
        .map(|(light, (hard, area))| {
            let contributing: Vec<bool> = points
                .iter()
                .map(|p| p.is_some_and(|p| contributes(light, p.position, p.normal)))
                .collect();
            light_reference(contributing, hard, area, samples)
        })
        .collect();
    let casters = zoo_ray_tracing::CasterGeometry::of(renderer.scene())
        .triangles
        .len();
    Ok(SceneReference::from_traced(
        gbuffer, lights, casters, seconds,
    ))
}
