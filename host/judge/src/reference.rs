//! Reference visibility of one light for every pixel.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use zoo_scene::shading::contributes;
use zoo_scene::{Light, LightKind};

use crate::occluders::Occluders;
use crate::robust::to_light;
use crate::sampling::stratified_disk;
use crate::surfaces::SurfacePoint;

/// Area samples per pixel unless configured otherwise (an 8 x 8 stratified grid).
pub const DEFAULT_AREA_SAMPLES: u32 = 64;

/// Reference visibility of one light.
#[derive(Debug, Clone, PartialEq)]
pub struct LightReference {
    /// Whether the light reaches the pixel's surface (facing it, in range and cone). Pixels
    /// where it does not are left out of every metric.
    pub contributing: Vec<bool>,
    /// Point-light visibility: 0 or 1 (1 where not contributing); behind translucent casters,
    /// the mean over the colour channels of the light they let through.
    pub hard: Vec<f32>,
    /// Fraction of the light's area visible, each part weighted by its cosine to the normal
    /// (equals `hard` for lights of radius 0); behind translucent casters, the mean over the
    /// colour channels of [`Self::color`].
    pub area: Vec<f32>,
    /// In scenes with translucent casters: the colour fraction of the light's area that
    /// arrives (weighted as `area`), per pixel.
    pub color: Option<Vec<Vec3>>,
    /// Area samples used per contributing pixel.
    pub samples: u32,
}

impl LightReference {
    /// Number of contributing pixels.
    pub fn pixels(&self) -> usize {
        self.contributing.iter().filter(|c| **c).count()
    }

    /// Fraction of contributing pixels in hard shadow.
    pub fn shadowed_fraction(&self) -> f64 {
        let shadowed = self
            .contributing
            .iter()
            .zip(&self.hard)
            .filter(|(c, h)| **c && **h < 0.5)
            .count();
        shadowed as f64 / self.pixels().max(1) as f64
    }
}

/// Two unit vectors perpendicular to `w` and to each other.
fn basis(w: Vec3) -> (Vec3, Vec3) {
    let helper = if w.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let u = w.cross(helper).normalize();
    (u, w.cross(u))
}

/// The colour fraction of light that travels from `origin` along unit `direction` for
/// `distance` (infinite for directional lights): 0 or 1, or filtered by translucent casters.
fn transmitted(occluders: &Occluders, origin: Vec3, direction: Vec3, distance: f32) -> Vec3 {
    if occluders.has_translucent() {
        return occluders.transmittance(origin, direction, distance);
    }
    Vec3::splat(if occluders.occluded(origin, direction, distance) {
        0.0
    } else {
        1.0
    })
}

/// [`transmitted`] from `origin` to the point `target`.
fn transmitted_to(occluders: &Occluders, origin: Vec3, target: Vec3) -> Vec3 {
    let to = target - origin;
    let distance = to.length();
    if distance <= 0.0 {
        return Vec3::ONE;
    }
    transmitted(occluders, origin, to / distance, to_light(distance))
}

/// Cosine-weighted mean of the samples' transmitted light: each sample direction counts with
/// max(0, n . direction), so the part of an emitter below the surface's horizon (which lights
/// nothing, shadowed or not) does not count as shadow. For a light at grazing incidence the
/// plain fraction would be about 0.5 (half the disk below the horizon) where the ratio of
/// shadowed to unshadowed irradiance is 1. `None` when no sample lies above the horizon.
fn weighted_fraction(samples: impl Iterator<Item = (Vec3, Vec3)>, normal: Vec3) -> Option<Vec3> {
    let (mut arrived, mut total) = (Vec3::ZERO, 0.0f32);
    for (direction, light) in samples {
        let weight = normal.dot(direction).max(0.0);
        total += weight;
        arrived += weight * light;
    }
    (total > 0.0).then(|| arrived / total)
}

/// Visibility of `light` from one surface point: (hard, area) colour fractions.
fn point_visibility(
    occluders: &Occluders,
    light: &Light,
    point: &SurfacePoint,
    grid: u32,
    seed: u32,
) -> (Vec3, Vec3) {
    let origin = point.ray_origin();
    match light.kind {
        LightKind::Directional => {
            let toward = -light.direction;
            let hard = transmitted(occluders, origin, toward, f32::INFINITY);
            if light.radius <= 0.0 {
                return (hard, hard);
            }
            let (u, v) = basis(toward);
            let spread = light.radius.tan();
            let samples = stratified_disk(grid, seed).map(|d: Vec2| {
                let dir = (toward + spread * (u * d.x + v * d.y)).normalize();
                (dir, transmitted(occluders, origin, dir, f32::INFINITY))
            });
            (
                hard,
                weighted_fraction(samples, point.normal).unwrap_or(hard),
            )
        }
        LightKind::Point | LightKind::Spot => {
            let hard = transmitted_to(occluders, origin, light.position);
            if light.radius <= 0.0 {
                return (hard, hard);
            }
            let (u, v) = basis((light.position - origin).normalize_or_zero());
            let samples = stratified_disk(grid, seed).map(|d: Vec2| {
                let target = light.position + light.radius * (u * d.x + v * d.y);
                let dir = (target - origin).normalize_or_zero();
                (dir, transmitted_to(occluders, origin, target))
            });
            (
                hard,
                weighted_fraction(samples, point.normal).unwrap_or(hard),
            )
        }
    }
}

/// Mean of the colour channels.
fn mean(c: Vec3) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// Reference visibility of `light` at every point (`None` = background pixel). `samples` is
/// rounded up to a square number for stratification.
pub fn reference_visibility(
    occluders: &Occluders,
    light: &Light,
    points: &[Option<SurfacePoint>],
    samples: u32,
) -> LightReference {
    let grid = (samples.max(1) as f32).sqrt().ceil() as u32;
    let results: Vec<(bool, Vec3, Vec3)> = points
        .par_iter()
        .enumerate()
        .with_min_len(64)
        .map(|(i, point)| match point {
            Some(p) if contributes(light, p.position, p.normal) => {
                let (hard, area) = point_visibility(occluders, light, p, grid, i as u32);
                (true, hard, area)
            }
            _ => (false, Vec3::ONE, Vec3::ONE),
        })
        .collect();
    // Without translucent casters every channel is the same: keep it exactly.
    let scalar = |c: Vec3| {
        if occluders.has_translucent() {
            mean(c)
        } else {
            c.x
        }
    };
    LightReference {
        contributing: results.iter().map(|r| r.0).collect(),
        hard: results.iter().map(|r| scalar(r.1)).collect(),
        area: results.iter().map(|r| scalar(r.2)).collect(),
        color: occluders
            .has_translucent()
            .then(|| results.iter().map(|r| r.2).collect()),
        samples: grid * grid,
    }
}
