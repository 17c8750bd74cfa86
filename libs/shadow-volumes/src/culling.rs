//! Which casters a light needs volumes of. A caster outside a point or spot light's range, or
//! outside a spot light's cone, shadows only points on the rays from the light through it,
//! which lie beyond it and so outside the range or the cone too: the light reaches none of
//! them, and its volume changes nothing.

use zoo_host::glam::Vec3;
use zoo_host::scene::{Light, LightKind};

/// Whether `light` may reach some point of the box `bounds` (lower and upper corners):
/// conservative, never false where it does.
pub fn reaches_box(light: &Light, (lo, hi): (Vec3, Vec3)) -> bool {
    if light.kind == LightKind::Directional {
        return true;
    }
    let nearest = light.position.clamp(lo, hi);
    if nearest.distance(light.position) > light.range {
        return false;
    }
    light.kind != LightKind::Spot
        || cone_meets_sphere(light, (lo + hi) / 2.0, (hi - lo).length() / 2.0)
}

/// Whether a spot light's cone meets the sphere at `center` with `radius`.
fn cone_meets_sphere(light: &Light, center: Vec3, radius: f32) -> bool {
    let to_center = center - light.position;
    let distance = to_center.length();
    if distance <= radius {
        return true;
    }
    let angle = (to_center.dot(light.direction) / distance)
        .clamp(-1.0, 1.0)
        .acos();
    // The sphere's angular radius as seen from the light, with a margin for rounding.
    let spread = (radius / distance).asin();
    angle <= light.spot_angle + spread + 1e-3
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot() -> Light {
        Light {
            kind: LightKind::Spot,
            position: Vec3::new(0.0, 10.0, 0.0),
            direction: Vec3::NEG_Y,
            radiance: Vec3::ONE,
            range: 20.0,
            spot_angle: 30f32.to_radians(),
            spot_softness: 0.2,
            radius: 0.0,
        }
    }

    fn unit_box(center: Vec3) -> (Vec3, Vec3) {
        (center - Vec3::splat(0.5), center + Vec3::splat(0.5))
    }

    #[test]
    fn boxes_in_the_cone_and_range_are_reached() {
        let light = spot();
        assert!(reaches_box(&light, unit_box(Vec3::ZERO)));
        // Straddling the cone's side (tan 30° x 10 = 5.77).
        assert!(reaches_box(&light, unit_box(Vec3::new(6.0, 0.0, 0.0))));
        // Around the light itself.
        assert!(reaches_box(&light, unit_box(light.position)));
    }

    #[test]
    fn boxes_outside_the_cone_or_range_are_not() {
        let light = spot();
        assert!(!reaches_box(&light, unit_box(Vec3::new(8.0, 0.0, 0.0))));
        assert!(!reaches_box(&light, unit_box(Vec3::new(0.0, 20.0, 0.0))));
        assert!(!reaches_box(&light, unit_box(Vec3::new(0.0, -11.0, 0.0))));
        let point = Light {
            kind: LightKind::Point,
            ..light
        };
        assert!(reaches_box(&point, unit_box(Vec3::new(0.0, 20.0, 0.0))));
        assert!(!reaches_box(&point, unit_box(Vec3::new(0.0, 31.0, 0.0))));
    }

    #[test]
    fn every_box_is_reached_by_a_directional_light() {
        let sun = Light {
            kind: LightKind::Directional,
            ..spot()
        };
        assert!(reaches_box(&sun, unit_box(Vec3::splat(1e6))));
    }
}
