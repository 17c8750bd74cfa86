//! Light leaking: indirect light on surfaces that no directly lit surface can see.
//!
//! One diffuse bounce reaches a point only from surfaces it sees that a light reaches, so where
//! no such surface is in view the one-bounce reference is exactly 0 and any indirect light a
//! technique puts there came through a wall (the classic leak of light propagation volumes).
//! Zeros of the cosine-ray reference alone are not that set: a point that sees a small lit
//! patch can miss it with every ray. So a point counts as unlit only when its reference is 0
//! and none of a dense set of directly lit points, found by tracing from every light, is
//! mutually visible with it.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use zoo_scene::{Light, LightKind};

use crate::indirect::{Reflectors, basis, reflected_direct};
use crate::occluders::Occluders;
use crate::sampling::stratified_disk;
use crate::surfaces::SurfacePoint;

/// Rays traced from the lights, shared between them (at least [`MIN_RAYS_PER_LIGHT`] each).
pub const LIT_RAYS: u32 = 128 * 128;
/// The fewest rays traced from one light.
pub const MIN_RAYS_PER_LIGHT: u32 = 32 * 32;
/// Most lit points every unlit candidate is tested against.
pub const MAX_LIT_POINTS: usize = 8192;

/// Points that light reaches directly and that reflect some of it (non-black albedo), found
/// by tracing stratified rays from every light into the scene: for directional lights a
/// parallel beam over the scene's bounds, for point lights the sphere, for spot lights the cone.
/// At most [`MAX_LIT_POINTS`], evenly thinned.
pub fn lit_points(
    occluders: &Occluders,
    reflectors: &Reflectors,
    lights: &[Light],
) -> Vec<SurfacePoint> {
    let per_light = (LIT_RAYS / lights.len().max(1) as u32).max(MIN_RAYS_PER_LIGHT);
    let grid = (per_light as f32).sqrt().ceil() as u32;
    let (lo, hi) = reflectors.bounds();
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length() * 0.5 + f32::EPSILON;
    let found: Vec<SurfacePoint> = lights
        .par_iter()
        .enumerate()
        .flat_map_iter(|(index, light)| {
            let rays: Vec<(Vec3, Vec3)> = stratified_disk(grid, 0x5eed_0000 ^ index as u32)
                .zip(stratified_disk(grid, 0x0dd5_0000 ^ index as u32))
                .map(|(a, b)| light_ray(light, centre, radius, a, b))
                .collect();
            rays.into_iter().filter_map(move |(origin, direction)| {
                let hit = reflectors.closest(origin, direction)?;
                let single = std::slice::from_ref(light);
                let reflected = reflected_direct(occluders, single, &hit.point, hit.albedo);
                (reflected.max_element() > 0.0).then_some(hit.point)
            })
        })
        .collect();
    let stride = found.len().div_ceil(MAX_LIT_POINTS).max(1);
    found.into_iter().step_by(stride).collect()
}

/// One ray leaving `light` into a scene within `radius` of `centre`, from two uniform disk
/// samples: directional lights sample the beam's cross-section with `a`, point lights the
/// sphere and spot lights the cone of directions with `a` and `b`.
fn light_ray(light: &Light, centre: Vec3, radius: f32, a: Vec2, b: Vec2) -> (Vec3, Vec3) {
    match light.kind {
        LightKind::Directional => {
            let d = light.direction.normalize_or(Vec3::NEG_Y);
            let (u, v) = basis(d);
            let across = (u * a.x + v * a.y) * radius;
            (centre - d * (2.0 * radius) + across, d)
        }
        LightKind::Point | LightKind::Spot => {
            // The disk sample's angle is the azimuth; b's radius picks cos θ uniformly,
            // which spreads directions uniformly over the sphere (or the cone's cap).
            let cos_min = match light.kind {
                LightKind::Spot => light.spot_angle.cos(),
                _ => -1.0,
            };
            let cos_theta = 1.0 - (1.0 - cos_min) * b.length_squared();
            let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
            let azimuth = a.y.atan2(a.x);
            let axis = match light.kind {
                LightKind::Spot => light.direction.normalize_or(Vec3::NEG_Y),
                _ => Vec3::Y,
            };
            let (u, v) = basis(axis);
            let direction = (u * (azimuth.cos() * sin_theta) + v * (azimuth.sin() * sin_theta))
                + axis * cos_theta;
            (light.position, direction.normalize())
        }
    }
}

/// Per point: whether no directly lit surface sees it, that is its one-bounce `reference` is
/// exactly 0 and no point of `lit` lies in front of it, facing it, with nothing between.
/// Background points (`None`) are not unlit surfaces.
pub fn unlit_by_one_bounce(
    reflectors: &Reflectors,
    lit: &[SurfacePoint],
    points: &[Option<SurfacePoint>],
    reference: &[Vec3],
) -> Vec<bool> {
    points
        .par_iter()
        .zip(reference)
        .with_min_len(16)
        .map(|(point, value)| match point {
            Some(p) if *value == Vec3::ZERO => !lit.iter().any(|q| sees(reflectors, p, q)),
            _ => false,
        })
        .collect()
}

/// Whether surface points `p` and `q` see each other: each lies in front of the other's
/// surface and no surface lies between their ray origins.
fn sees(reflectors: &Reflectors, p: &SurfacePoint, q: &SurfacePoint) -> bool {
    let (from, to) = (p.ray_origin(), q.ray_origin());
    let between = to - from;
    if p.normal.dot(between) <= 0.0 || q.normal.dot(-between) <= 0.0 {
        return false;
    }
    let distance = between.length();
    if distance <= 0.0 {
        return false;
    }
    reflectors
        .closest(from, between / distance)
        .is_none_or(|hit| hit.distance >= distance * (1.0 - 1e-5))
}

/// The leak of `estimate`: its mean over the `unlit` pixels as a fraction of the reference's
/// mean over every pixel `mask` accepts (channels averaged). 0 where no pixel is unlit; infinite
/// where the reference is black and the estimate is not.
pub fn leak(reference: &[Vec3], estimate: &[Vec3], mask: &[bool], unlit: &[bool]) -> f64 {
    let mean = |values: &[Vec3], keep: &[bool]| {
        let (sum, count) = values
            .iter()
            .zip(keep)
            .filter(|(_, k)| **k)
            .fold((0.0f64, 0usize), |(s, n), (v, _)| {
                (s + f64::from(v.element_sum()) / 3.0, n + 1)
            });
        sum / count.max(1) as f64
    };
    let (leaked, typical) = (mean(estimate, unlit), mean(reference, mask));
    match (leaked > 0.0, typical > 0.0) {
        (false, _) => 0.0,
        (true, false) => f64::INFINITY,
        (true, true) => leaked / typical,
    }
}
