//! Floating-point error bounds and ray origins that stay off their own surface at any scale.
//!
//! Bounds use Higham's γₙ = n·u / (1 − n·u) with the unit roundoff u = 2⁻²⁴ of f32: a value
//! computed with n roundings is within γₙ of its exact magnitude (Pharr, Jakob and Humphreys,
//! "Physically Based Rendering", 3rd ed., section 3.9).

use glam::Vec3;

/// The unit roundoff of f32 (half an ulp of 1).
const UNIT_ROUNDOFF: f32 = f32::EPSILON * 0.5;

/// Higham's γₙ: the relative error bound of n successive f32 roundings.
pub(crate) const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

/// `p` moved along unit `n` by at least `distance`, each coordinate rounded away from `p` so
/// that the rounding of the sum cannot take back any of the offset.
pub(crate) fn offset_along(p: Vec3, n: Vec3, distance: f32) -> Vec3 {
    let offset = n * distance;
    let mut out = p + offset;
    for axis in 0..3 {
        if offset[axis] > 0.0 {
            out[axis] = out[axis].next_up();
        } else if offset[axis] < 0.0 {
            out[axis] = out[axis].next_down();
        }
    }
    out
}

/// The fraction of the distance to a light that a shadow ray covers: all of it but the
/// distance's own rounding, so a caster through the light's point (a lamp on a wall's plane)
/// does not stop rays that reach the light (lights have no geometry: nothing at the light is
/// missed). The GPU's shadow rays end at the same fraction (`ray-tracing/shadow_ray.wgsl`).
pub const SHADOW_RAY_TO_LIGHT: f32 = 1.0 - gamma(4);

/// The length of a shadow ray to a light `distance` away ([`SHADOW_RAY_TO_LIGHT`] of it).
pub(crate) fn to_light(distance: f32) -> f32 {
    distance * SHADOW_RAY_TO_LIGHT
}

/// The distance a ray origin must keep from the plane of triangle `corners` so that the
/// ray-triangle test (Möller-Trumbore, as obvhs computes it) finds the origin on the correct
/// side of the triangle's plane: the test's sign is n · (v0 − o) with n = (v0 − v1) × (v2 − v0),
/// wrong by at most about γ₈ of the coordinates' magnitude `magnitude` (rounding v0 − o) plus
/// γ₈ of the triangle's diameter over the sine of its angle at v0 (rounding n).
pub(crate) fn plane_test_error(corners: &[Vec3; 3], magnitude: f32) -> f32 {
    let [a, b, c] = *corners;
    let (e1, e2) = (a - b, c - a);
    let diameter = e1.length().max(e2.length()).max((c - b).length());
    let sine = e1.cross(e2).length() / (e1.length() * e2.length());
    let sine = if sine.is_finite() && sine > 0.0 {
        sine
    } else {
        1.0
    };
    gamma(8) * magnitude + gamma(8) * diameter / sine
}

/// The largest absolute coordinate of any of `points`.
pub(crate) fn magnitude<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> f32 {
    points
        .into_iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_grows_with_the_rounding_count() {
        assert!(gamma(1) > UNIT_ROUNDOFF && gamma(1) < 1.0001 * UNIT_ROUNDOFF);
        assert!(gamma(8) > 8.0 * UNIT_ROUNDOFF && gamma(8) < gamma(9));
    }

    #[test]
    fn offsets_keep_at_least_their_distance_after_rounding() {
        // A tiny offset from a large coordinate would round back to it without the next-float
        // step.
        let p = Vec3::new(1.0e6, -3.0e5, 7.0);
        let n = Vec3::new(1.0, -1.0, 0.0).normalize();
        let o = offset_along(p, n, 1e-9);
        assert!(o.x > p.x && o.y < p.y && o.z == p.z, "{o} from {p}");
        let far = offset_along(p, n, 10.0);
        assert!(((far - p).dot(n) - 10.0).abs() < 0.2);
    }
}
