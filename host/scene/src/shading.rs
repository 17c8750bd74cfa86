//! CPU mirror of `shaders/common/lighting.wgsl`: which surfaces a light reaches and how much
//! light it adds. The judge uses it to decide which pixels a light contributes to; tests use it
//! to check the GPU lighting pass.

use glam::Vec3;

use super::{Light, LightKind};

/// Distance and cone falloff in [0, 1]; exactly 0 outside the range and the spot cone.
pub fn falloff(light: &Light, p: Vec3) -> f32 {
    if light.kind == LightKind::Directional {
        return 1.0;
    }
    let d = light.position.distance(p);
    let ratio = d / light.range;
    let window = (1.0 - ratio.powi(4)).clamp(0.0, 1.0);
    let mut value = window * window / (d * d).max(1e-4);
    if light.kind == LightKind::Spot {
        let cos_angle = (p - light.position)
            .normalize_or_zero()
            .dot(light.direction);
        let cos_outer = light.spot_angle.cos();
        if cos_angle <= cos_outer {
            return 0.0;
        }
        let cos_inner = (light.spot_angle * (1.0 - light.spot_softness)).cos();
        value *= smoothstep(cos_outer, cos_inner, cos_angle);
    }
    value
}

fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Whether `light` adds anything at a surface point `p` with normal `n` (ignoring occlusion).
pub fn contributes(light: &Light, p: Vec3, n: Vec3) -> bool {
    n.dot(light.direction_to_light(p)) > 0.0 && falloff(light, p) > 0.0
}

/// Material of a shaded point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub albedo: Vec3,
    pub specular: f32,
    pub shininess: f32,
}

/// Unshadowed Lambert + Blinn-Phong radiance from one light.
pub fn direct_light(light: &Light, p: Vec3, n: Vec3, view_dir: Vec3, m: &Material) -> Vec3 {
    let l = light.direction_to_light(p);
    let n_dot_l = n.dot(l);
    if n_dot_l <= 0.0 {
        return Vec3::ZERO;
    }
    let h = (l + view_dir).normalize_or_zero();
    let spec = m.specular * n.dot(h).max(0.0).powf(m.shininess.max(1.0));
    light.radiance * falloff(light, p) * (m.albedo * n_dot_l + Vec3::splat(spec * n_dot_l))
}

/// The display curve of the lighting pass.
pub fn tonemap(c: Vec3) -> Vec3 {
    Vec3::ONE - (-c).exp()
}

/// sRGB-encoded [0, 1] to linear [0, 1].
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear [0, 1] to sRGB-encoded [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}
