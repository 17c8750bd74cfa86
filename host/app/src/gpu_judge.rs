//! `compare --judge gpu`: the reference visibility traced on the GPU by the ray-tracing library,
//! through the `rt-shadows` technique: one ray to each light's centre for hard visibility, and
//! `samples` rays over its disk, cosine-weighted and unfiltered, for area visibility, filtered
//! by translucent casters as the CPU judge's. Which pixels each light reaches comes from the
//! CPU judge's own located surfaces, so both judges score the same pixels. The CPU judge stays
//! the arbiter (`tests/zoo/gpu_judge.rs` measures their agreement).

use web_time::Instant;

use anyhow::Context;
use zoo_host::glam::Vec3;
use zoo_host::judge::{LightReference, Surfaces};
use zoo_host::judging::{SceneReference, surface_points};
use zoo_host::params::{ParamValue, ParamValues, defaults};
use zoo_host::render::View;
use zoo_host::scene::shading::contributes;
use zoo_host::{Renderer, find_technique};

/// The technique that traces the GPU reference.
pub const TRACER: &str = "rt-shadows";

/// Most area rays per pixel the tracer takes.
pub const MAX_SAMPLES: u32 = 64;

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

/// What the tracer in `renderer` traced in its last frame, per light: the colour fraction of
/// the light that arrives (its visibility times its transmittance colour, white without
/// translucent casters).
pub fn read_traced(renderer: &Renderer) -> Vec<Vec<Vec3>> {
    let coloured = (renderer.technique_instance()).writes_transmittance(renderer.scene());
    (0..renderer.lights().len())
        .map(|light| {
            let colour = coloured.then(|| renderer.read_transmittance(light));
            traced_colour(&renderer.read_visibility(light), colour.as_deref())
        })
        .collect()
}

/// The colour fraction of a light that arrives: `visibility` times the `transmittance`
/// colour, where the tracer writes one.
pub fn traced_colour(visibility: &[f32], transmittance: Option<&[Vec3]>) -> Vec<Vec3> {
    match transmittance {
        Some(colour) => (visibility.iter().zip(colour))
            .map(|(v, c)| *v * *c)
            .collect(),
        None => visibility.iter().map(|v| Vec3::splat(*v)).collect(),
    }
}

/// A light's reference from traced `hard` and `area` colour fractions ([`read_traced`];
/// `samples` area rays a pixel), counted where `contributing` and 1 elsewhere, as the CPU
/// judge's: visibility is the mean over the colour channels, and scenes with translucent
/// casters (`coloured`) keep the area colour too.
pub fn light_reference(
    contributing: Vec<bool>,
    hard: &[Vec3],
    area: &[Vec3],
    samples: u32,
    coloured: bool,
) -> LightReference {
    let keep = |values: &[Vec3]| -> Vec<f32> {
        (values.iter().zip(&contributing))
            .map(|(v, &c)| if c { (v.x + v.y + v.z) / 3.0 } else { 1.0 })
            .collect()
    };
    let color = coloured.then(|| {
        (area.iter().zip(&contributing))
            .map(|(v, &c)| if c { *v } else { Vec3::ONE })
            .collect()
    });
    LightReference {
        hard: keep(hard),
        area: keep(area),
        contributing,
        color,
        samples,
    }
}

/// Traces the reference of `renderer`'s current view on the GPU with `samples` area rays per
/// pixel (at most [`MAX_SAMPLES`]).
pub fn trace_reference(renderer: &mut Renderer, samples: u32) -> anyhow::Result<SceneReference> {
    // Any technique leaves the G-buffer the same; render one frame to fill it.
    renderer.render(&View::Final)?;
    let gbuffer = renderer.read_gbuffer();
    let points = surface_points(&gbuffer, &Surfaces::new(renderer.scene()));

    let start = Instant::now();
    let samples = samples.clamp(1, MAX_SAMPLES);
    let traced = |renderer: &mut Renderer, rays: u32| -> anyhow::Result<Vec<Vec<Vec3>>> {
        // One frame of unfiltered rays: the reference's samples, nothing averaged in.
        renderer.set_technique(TRACER, &tracer_values(rays, 1)?)?;
        renderer.render(&View::Final)?;
        Ok(read_traced(renderer))
    };
    let hard = traced(renderer, 1)?;
    // One area ray is the hard ray: the same frame, not traced twice.
    let area = if samples == 1 {
        hard.clone()
    } else {
        traced(renderer, samples)?
    };
    let seconds = start.elapsed().as_secs_f64();

    let coloured = renderer.scene().has_translucent_casters();
    let lights = renderer
        .lights()
        .iter()
        .zip(hard.iter().zip(&area))
        .map(|(light, (hard, area))| {
            let contributing: Vec<bool> = points
                .iter()
                .map(|p| p.is_some_and(|p| contributes(light, p.position, p.normal)))
                .collect();
            light_reference(contributing, hard, area, samples, coloured)
        })
        .collect();
    // Counted as the CPU judge counts them: an instance's triangles each time.
    let casters = zoo_ray_tracing::CasterGeometry::of(renderer.scene()).traced_count();
    Ok(SceneReference::from_traced(
        gbuffer, lights, casters, seconds,
    ))
}
