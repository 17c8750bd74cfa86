//! The one-bounce diffuse reference: the light that reaches each surface point after exactly
//! one diffuse reflection off another surface, for techniques that add indirect light.
//!
//! Units are those of the renderer's indirect target: irradiance over π, in the same units as
//! a light's direct term, so that the lighting pass adds `albedo × indirect`. A surface lit
//! directly sends `albedo × Σ radiance · falloff · max(n · l, 0) · visibility` towards every
//! direction (the diffuse part of the direct term), and the indirect value at a point is the
//! cosine-weighted mean of what arrives: (1/π) ∫ L cos θ dω, estimated with stratified
//! cosine-distributed rays (Malley's method) against every surface of the scene.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use zoo_scene::shading::falloff;
use zoo_scene::{Light, Scene};

use crate::occluders::{CanonicalFrame, Occluders, TriangleBvh};
use crate::reference::SurfacePoint;
use crate::sampling::stratified_disk;

/// Every surface of a scene as a diffuse reflector: triangles with their normals and albedo.
pub struct Reflectors {
    bvh: TriangleBvh,
    frame: CanonicalFrame,
    /// Per triangle: unit geometric normal and albedo.
    normals: Vec<Vec3>,
    albedo: Vec<Vec3>,
}

/// Where a ray meets a reflector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReflectorHit {
    pub position: Vec3,
    /// Unit normal on the side the ray came from.
    pub normal: Vec3,
    pub albedo: Vec3,
    pub distance: f32,
}

impl Reflectors {
    /// Every object of `scene` (shadow casters or not) with its colour as albedo.
    pub fn new(scene: &Scene) -> Reflectors {
        let mut triangles = Vec::new();
        for object in &scene.objects {
            for tri in scene.mesh.indices[object.indices.clone()].chunks_exact(3) {
                let corners = [tri[0], tri[1], tri[2]].map(|i| scene.mesh.positions[i as usize]);
                triangles.push((corners, object.color));
            }
        }
        Reflectors::from_triangles(&triangles)
    }

    /// Reflectors from world-space triangles and their albedo.
    pub fn from_triangles(triangles: &[([Vec3; 3], Vec3)]) -> Reflectors {
        let frame = CanonicalFrame::of(triangles.iter().map(|(t, _)| t));
        let canonical: Vec<_> = triangles.iter().map(|(t, _)| frame.triangle(t)).collect();
        Reflectors {
            bvh: TriangleBvh::new(&canonical),
            frame,
            normals: triangles
                .iter()
                .map(|([a, b, c], _)| (*b - *a).cross(*c - *a).normalize_or_zero())
                .collect(),
            albedo: triangles.iter().map(|(_, albedo)| *albedo).collect(),
        }
    }

    /// The nearest reflector from `origin` along unit `direction`.
    pub fn closest(&self, origin: Vec3, direction: Vec3) -> Option<ReflectorHit> {
        let ray = self.frame.ray(origin, direction, f32::INFINITY)?;
        let (index, t) = self.bvh.closest(ray)?;
        let distance = self.frame.world_distance(t);
        let normal = self.normals[index];
        Some(ReflectorHit {
            position: origin + direction * distance,
            normal: if normal.dot(direction) > 0.0 {
                -normal
            } else {
                normal
            },
            albedo: self.albedo[index],
            distance,
        })
    }
}

/// The diffuse light a surface at `p` (unit normal `n`, `albedo`) reflects in every direction:
/// albedo × Σ radiance · falloff · max(n · l, 0), each light's share filtered by what lies
/// between (opaque casters block, translucent ones tint).
pub fn reflected_direct(
    occluders: &Occluders,
    lights: &[Light],
    p: Vec3,
    n: Vec3,
    albedo: Vec3,
) -> Vec3 {
    let origin = p + n * occluders.epsilon();
    let mut sum = Vec3::ZERO;
    for light in lights {
        let l = light.direction_to_light(p);
        let n_dot_l = n.dot(l);
        let f = falloff(light, p);
        if n_dot_l <= 0.0 || f <= 0.0 {
            continue;
        }
        let distance = match light.kind {
            zoo_scene::LightKind::Directional => f32::INFINITY,
            _ => origin.distance(light.position) * (1.0 - 1e-4),
        };
        let arrives = occluders.transmittance(origin, l, distance);
        sum += light.radiance * f * n_dot_l * arrives;
    }
    albedo * sum
}

/// Unit vectors perpendicular to `w` and to each other.
fn basis(w: Vec3) -> (Vec3, Vec3) {
    let helper = if w.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let u = w.cross(helper).normalize();
    (u, w.cross(u))
}

/// One-bounce indirect light (irradiance over π) at every point (`Vec3::ZERO` on background
/// pixels), from `samples` cosine-weighted rays per point (rounded up to a square).
pub fn one_bounce(
    occluders: &Occluders,
    reflectors: &Reflectors,
    lights: &[Light],
    points: &[Option<SurfacePoint>],
    samples: u32,
) -> Vec<Vec3> {
    let grid = (samples.max(1) as f32).sqrt().ceil() as u32;
    points
        .par_iter()
        .enumerate()
        .with_min_len(16)
        .map(|(i, point)| match point {
            Some(point) => indirect_at(occluders, reflectors, lights, point, grid, i as u32),
            None => Vec3::ZERO,
        })
        .collect()
}

/// The estimate at one point with `grid`² stratified cosine-weighted rays.
fn indirect_at(
    occluders: &Occluders,
    reflectors: &Reflectors,
    lights: &[Light],
    point: &SurfacePoint,
    grid: u32,
    seed: u32,
) -> Vec3 {
    let n = point.normal;
    let (u, v) = basis(n);
    let origin = point.position + n * occluders.epsilon();
    let mut sum = Vec3::ZERO;
    let mut count = 0;
    for d in stratified_disk(grid, seed ^ 0x1b0c_e5a1) {
        // A uniform disk point lifted onto the hemisphere is cosine-distributed.
        let d: Vec2 = d;
        let up = (1.0 - d.length_squared()).max(0.0).sqrt();
        let direction = (u * d.x + v * d.y + n * up).normalize_or_zero();
        count += 1;
        if let Some(hit) = reflectors.closest(origin, direction) {
            sum += reflected_direct(occluders, lights, hit.position, hit.normal, hit.albedo);
        }
    }
    sum / count.max(1) as f32
}

/// Relative RMSE of `estimate` against `reference` over the pixels `mask` accepts:
/// sqrt(Σ |e − r|²) / sqrt(Σ |r|²) (0 when both are black).
pub fn relative_rmse(reference: &[Vec3], estimate: &[Vec3], mask: &[bool]) -> f64 {
    let (mut error, mut norm) = (0.0f64, 0.0f64);
    for ((r, e), keep) in reference.iter().zip(estimate).zip(mask) {
        if *keep {
            error += f64::from((*e - *r).length_squared());
            norm += f64::from(r.length_squared());
        }
    }
    if norm == 0.0 {
        if error == 0.0 { 0.0 } else { f64::INFINITY }
    } else {
        (error / norm).sqrt()
    }
}
