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
use zoo_scene::{AlphaMask, Light, Scene, Textures};

use crate::occluders::Occluders;
use crate::placed::DrawnTriangle;
use crate::robust::to_light;
use crate::sampling::stratified_disk;
use crate::surfaces::{SurfacePoint, Surfaces, texture_coordinates};

/// Every surface of a scene as a diffuse reflector: its triangles with their albedo, textured
/// and alpha-tested as the G-buffer draws them.
pub struct Reflectors {
    surfaces: Surfaces,
    /// Per part of `surfaces` (an object, or one triangle of [`Reflectors::from_triangles`]):
    /// its material.
    materials: Vec<ReflectorMaterial>,
    textures: Textures,
    /// The corners' least and greatest coordinates.
    bounds: (Vec3, Vec3),
}

/// The material of one reflecting object.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ReflectorMaterial {
    color: Vec3,
    albedo_texture: Option<u32>,
    alpha_mask: Option<AlphaMask>,
}

/// Where a ray meets a reflector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReflectorHit {
    /// The point, with its normal on the side the ray came from.
    pub point: SurfacePoint,
    pub albedo: Vec3,
    pub distance: f32,
}

impl Reflectors {
    /// Every object of `scene` (shadow casters or not): its colour times its albedo texture
    /// as albedo, its mask's holes passed through (texels read at full resolution, as the
    /// judge's alpha test does).
    pub fn new(scene: &Scene) -> Reflectors {
        let materials = (scene.objects.iter())
            .map(|object| ReflectorMaterial {
                color: object.color,
                albedo_texture: object.albedo_texture,
                alpha_mask: object.alpha_mask,
            })
            .collect();
        Reflectors {
            surfaces: Surfaces::new(scene),
            materials,
            textures: scene.textures.clone(),
            bounds: scene.bounds(),
        }
    }

    /// Reflectors from world-space triangles and their albedo.
    pub fn from_triangles(triangles: &[([Vec3; 3], Vec3)]) -> Reflectors {
        let materials = triangles
            .iter()
            .map(|(_, color)| ReflectorMaterial {
                color: *color,
                albedo_texture: None,
                alpha_mask: None,
            })
            .collect();
        let parts: Vec<Vec<[Vec3; 3]>> = triangles.iter().map(|(t, _)| vec![*t]).collect();
        let bounds = triangles.iter().flat_map(|(t, _)| t).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        Reflectors {
            surfaces: Surfaces::from_parts(&parts),
            materials,
            textures: Textures::default(),
            bounds,
        }
    }

    /// The least and greatest coordinates of every reflector (both the origin when there
    /// are none).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        if self.materials.is_empty() {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            self.bounds
        }
    }

    /// The nearest reflector from `origin` along unit `direction` (through mask holes).
    pub fn closest(&self, origin: Vec3, direction: Vec3) -> Option<ReflectorHit> {
        let uv_at = |triangle: &DrawnTriangle, t: f32| {
            texture_coordinates(&triangle.corners, &triangle.uvs, origin + direction * t)
        };
        let hit = self.surfaces.closest_where(origin, direction, |index, t| {
            let part = self.surfaces.part(index);
            self.materials[part].alpha_mask.is_none_or(|mask| {
                let triangle = self.surfaces.triangle(index);
                self.textures.alpha(mask.layer, uv_at(&triangle, t)) >= mask.cutoff
            })
        })?;
        let triangle = self.surfaces.triangle(hit.triangle);
        let material = &self.materials[triangle.part];
        let texel = material.albedo_texture.map_or(Vec3::ONE, |layer| {
            self.textures
                .linear_rgb(layer, uv_at(&triangle, hit.distance))
        });
        Some(ReflectorHit {
            point: hit.point,
            albedo: material.color * texel,
            distance: hit.distance,
        })
    }
}

/// The diffuse light a surface point with `albedo` reflects in every direction:
/// albedo × Σ radiance · falloff · max(n · l, 0), each light's share filtered by what lies
/// between (opaque casters block, translucent ones tint).
pub fn reflected_direct(
    occluders: &Occluders,
    lights: &[Light],
    point: &SurfacePoint,
    albedo: Vec3,
) -> Vec3 {
    let (p, n) = (point.position, point.normal);
    let origin = point.ray_origin();
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
            _ => to_light(origin.distance(light.position)),
        };
        let arrives = occluders.transmittance(origin, l, distance);
        sum += light.radiance * f * n_dot_l * arrives;
    }
    albedo * sum
}

/// Unit vectors perpendicular to `w` and to each other.
pub(crate) fn basis(w: Vec3) -> (Vec3, Vec3) {
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
    let origin = point.ray_origin();
    let mut sum = Vec3::ZERO;
    let mut count = 0;
    for d in stratified_disk(grid, seed ^ 0x1b0c_e5a1) {
        // A uniform disk point lifted onto the hemisphere is cosine-distributed.
        let d: Vec2 = d;
        let up = (1.0 - d.length_squared()).max(0.0).sqrt();
        let direction = (u * d.x + v * d.y + n * up).normalize_or_zero();
        count += 1;
        if let Some(hit) = reflectors.closest(origin, direction) {
            sum += reflected_direct(occluders, lights, &hit.point, hit.albedo);
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
