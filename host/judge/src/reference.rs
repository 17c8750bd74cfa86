//! Reference visibility of one light for every pixel.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use zoo_scene::shading::contributes;
use zoo_scene::{Light, LightKind};

use crate::occluders::Occluders;
use crate::sampling::stratified_disk;

/// Area samples per pixel unless configured otherwise (an 8 x 8 stratified grid).
pub const DEFAULT_AREA_SAMPLES: u32 = 64;

/// The surface seen at a pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub position: Vec3,
    /// Unit normal on the side facing the camera.
    pub normal: Vec3,
}

/// Reference visibility of one light.
#[derive(Debug, Clone, PartialEq)]
pub struct LightReference {
    /// Whether the light reaches the pixel's surface (facing it, in range and cone). Pixels
    /// where it does not are left out of every metric.
    pub contributing: Vec<bool>,
    /// Point-light visibility: 0 or 1 (1 where not contributing).
    pub hard: Vec<f32>,
    /// Fraction of the light's area visible, each part weighted by its cosine to the normal
    /// (equals `hard` for lights of radius 0).
    pub area: Vec<f32>,
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

fn visible(occluders: &Occluders, origin: Vec3, target: Vec3) -> bool {
    let to = target - origin;
    let distance = to.length();
    distance <= 0.0 || !occluders.occluded(origin, to / distance, distance * (1.0 - 1e-4))
}

fn visible_direction(occluders: &Occluders, origin: Vec3, direction: Vec3) -> bool {
    !occluders.occluded(origin, direction, f32::INFINITY)
}

/// Cosine-weighted fraction of samples that are visible: each sample direction counts with
/// max(0, n . direction), so the part of an emitter below the surface's horizon (which lights
/// nothing, shadowed or not) does not count as shadow. For a light at grazing incidence the
/// plain fraction would be about 0.5 (half the disk below the horizon) where the ratio of
/// shadowed to unshadowed irradiance is 1. `None` when no sample lies above the horizon.
fn weighted_fraction(samples: impl Iterator<Item = (Vec3, bool)>, normal: Vec3) -> Option<f32> {
    let (mut visible, mut total) = (0.0f32, 0.0f32);
    for (direction, seen) in samples {
        let weight = normal.dot(direction).max(0.0);
        total += weight;
        if seen {
            visible += weight;
        }
    }
    (total > 0.0).then(|| visible / total)
}

/// Visibility of `light` from one surface point: (hard, area).
fn point_visibility(
    occluders: &Occluders,
    light: &Light,
    point: &SurfacePoint,
    grid: u32,
    seed: u32,
) -> (f32, f32) {
    let origin = point.position + point.normal * occluders.epsilon();
    let as_f32 = |b: bool| if b { 1.0 } else { 0.0 };
    match light.kind {
        LightKind::Directional => {
            let toward = -light.direction;
            let hard = as_f32(visible_direction(occluders, origin, toward));
            if light.radius <= 0.0 {
                return (hard, hard);
            }
            let (u, v) = basis(toward);
            let spread = light.radius.tan();
            let samples = stratified_disk(grid, seed).map(|d: Vec2| {
                let dir = (toward + spread * (u * d.x + v * d.y)).normalize();
                (dir, visible_direction(occluders, origin, dir))
            });
            (
                hard,
                weighted_fraction(samples, point.normal).unwrap_or(hard),
            )
        }
        LightKind::Point | LightKind::Spot => {
            let hard = as_f32(visible(occluders, origin, light.position));
            if light.radius <= 0.0 {
                return (hard, hard);
            }
            let (u, v) = basis((light.position - origin).normalize_or_zero());
            let samples = stratified_disk(grid, seed).map(|d: Vec2| {
                let target = light.position + light.radius * (u * d.x + v * d.y);
                let dir = (target - origin).normalize_or_zero();
                (dir, visible(occluders, origin, target))
            });
            (
                hard,
                weighted_fraction(samples, point.normal).unwrap_or(hard),
            )
        }
    }
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
    let results: Vec<(bool, f32, f32)> = points
        .par_iter()
        .enumerate()
        .with_min_len(64)
        .map(|(i, point)| match point {
            Some(p) if contributes(light, p.position, p.normal) => {
                let (hard, area) = point_visibility(occluders, light, p, grid, i as u32);
                (true, hard, area)
            }
            _ => (false, 1.0, 1.0),
        })
        .collect();
    LightReference {
        contributing: results.iter().map(|r| r.0).collect(),
        hard: results.iter().map(|r| r.1).collect(),
        area: results.iter().map(|r| r.2).collect(),
        samples: grid * grid,
    }
}
