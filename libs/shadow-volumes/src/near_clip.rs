//! Everitt and Kilgard's choice of counting (seed 000 §8): z-pass counts a light's volumes
//! right unless a volume reaches the camera's near plane, which a volume does only when its
//! caster meets the near-clip volume: the convex hull of the near-plane rectangle and the light
//! (the rectangle swept towards a directional light). Z-fail is exact wherever the camera is;
//! z-pass fills less (no caps, nothing behind the surfaces), so a light whose near-clip volume
//! meets no caster can take it.

use zoo_host::glam::Vec3;
use zoo_host::scene::{Camera, Light, LightKind};

/// The near-plane rectangle is widened by this fraction, so casters touching it count.
const RECTANGLE_MARGIN: f32 = 0.01;

/// The near-clip volume of a light and a camera: its bounding planes (a point p lies inside
/// when `normal · p <= offset` for every plane) and its corners, the rectangle's and the light's
/// position, or the direction it runs off to towards a directional light.
#[derive(Debug, Clone, PartialEq)]
pub struct NearClipVolume {
    planes: Vec<(Vec3, f32)>,
    corners: Vec<Vec3>,
    sweep: Option<Vec3>,
}

impl NearClipVolume {
    /// The near-clip volume of `light` seen by `camera` with aspect ratio `aspect`; `None`
    /// where it is flat (a point light in the near plane's plane, a directional light
    /// parallel to it) and no test can clear z-pass.
    pub fn new(light: &Light, camera: &Camera, aspect: f32) -> Option<NearClipVolume> {
        let forward = (camera.target - camera.position).normalize_or_zero();
        let centre = camera.position + forward * camera.near;
        let inverse = camera.view().inverse();
        let h = camera.near * (camera.fov_y * 0.5).tan() * (1.0 + RECTANGLE_MARGIN);
        let w = h * aspect;
        let corners = [(-w, -h), (w, -h), (w, h), (-w, h)]
            .map(|(x, y)| inverse.transform_point3(Vec3::new(x, y, -camera.near)));
        // How the hull leaves the rectangle: towards the light's position, or against a
        // directional light's travel.
        let (towards, apex) = match light.kind {
            LightKind::Directional => (-light.direction.normalize_or_zero(), None),
            _ => (
                (light.position - centre).normalize_or_zero(),
                Some(light.position),
            ),
        };
        let side = towards.dot(forward);
        if side.abs() < 1e-4 {
            return None;
        }
        // The rectangle's plane, facing away from the hull.
        let base = -forward * side.signum();
        let mut planes = vec![(base, base.dot(centre))];
        for k in 0..4 {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let normal = match apex {
                Some(light) => (a - light).cross(b - light),
                None => (b - a).cross(towards),
            }
            .normalize_or_zero();
            // Facing away from the rectangle's centre.
            let normal = if normal.dot(centre - a) > 0.0 {
                -normal
            } else {
                normal
            };
            planes.push((normal, normal.dot(a)));
        }
        let mut corners = corners.to_vec();
        corners.extend(apex);
        let sweep = apex.is_none().then_some(towards);
        Some(NearClipVolume {
            planes,
            corners,
            sweep,
        })
    }

    /// Whether the box `lo`..`hi` may meet the volume: false only when a plane of the volume or
    /// of the box separates them (conservative: true for some boxes that miss it).
    pub fn meets_box(&self, (lo, hi): (Vec3, Vec3)) -> bool {
        let slack = |v: f32| 1e-5 * (v.abs() + 1.0);
        let beyond_a_plane = self.planes.iter().any(|&(normal, offset)| {
            // The box's corner furthest against the normal.
            let nearest = Vec3::select(normal.cmpge(Vec3::ZERO), lo, hi);
            normal.dot(nearest) > offset + slack(offset)
        });
        // The volume's extent along each axis of the box (endless where it sweeps that way).
        let mut low = self.corners.iter().fold(Vec3::INFINITY, |m, c| m.min(*c));
        let mut high = self
            .corners
            .iter()
            .fold(Vec3::NEG_INFINITY, |m, c| m.max(*c));
        if let Some(sweep) = self.sweep {
            high = Vec3::select(sweep.cmpgt(Vec3::splat(1e-6)), Vec3::INFINITY, high);
            low = Vec3::select(sweep.cmplt(Vec3::splat(-1e-6)), Vec3::NEG_INFINITY, low);
        }
        let apart = (0..3).any(|k| high[k] < lo[k] - slack(lo[k]) || low[k] > hi[k] + slack(hi[k]));
        !beyond_a_plane && !apart
    }
}

/// Whether z-pass counts `light`'s volumes exactly for `camera` (aspect ratio `aspect`): no
/// caster box of `casters` meets the near-clip volume. Conservative: false where unsure.
pub fn zpass_is_exact(
    light: &Light,
    camera: &Camera,
    aspect: f32,
    mut casters: impl Iterator<Item = (Vec3, Vec3)>,
) -> bool {
    NearClipVolume::new(light, camera, aspect).is_some_and(|v| !casters.any(|b| v.meets_box(b)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.0, 2.0, 10.0),
            target: Vec3::new(0.0, 2.0, 0.0),
            fov_y: 1.0,
            near: 0.1,
            far: 100.0,
        }
    }

    fn light(kind: LightKind, position: Vec3, direction: Vec3) -> Light {
        Light {
            kind,
            position,
            direction: direction.normalize(),
            radiance: Vec3::ONE,
            range: 100.0,
            spot_angle: 0.5,
            spot_softness: 0.1,
            radius: 0.0,
        }
    }

    fn unit_box(centre: Vec3) -> (Vec3, Vec3) {
        (centre - Vec3::splat(0.5), centre + Vec3::splat(0.5))
    }

    #[test]
    fn a_caster_between_the_light_and_the_camera_needs_z_fail() {
        let c = camera();
        let above = light(LightKind::Point, Vec3::new(0.0, 8.0, 10.0), Vec3::NEG_Y);
        // On the segment from the camera to the light: its volume covers the camera.
        let between = unit_box(Vec3::new(0.0, 5.0, 10.0));
        assert!(!zpass_is_exact(&above, &c, 1.0, [between].into_iter()));
        // In front of the camera, away from the light's rays to the near plane.
        let ahead = unit_box(Vec3::new(0.0, 1.0, 0.0));
        assert!(zpass_is_exact(&above, &c, 1.0, [ahead].into_iter()));
        // Beside the hull.
        let beside = unit_box(Vec3::new(3.0, 5.0, 10.0));
        assert!(zpass_is_exact(&above, &c, 1.0, [beside].into_iter()));
        // A floor below everything, wider than the hull on every side: a plane of the box, not
        // of the hull, separates them.
        let floor = (Vec3::new(-20.0, -0.1, -20.0), Vec3::new(20.0, 0.0, 20.0));
        assert!(zpass_is_exact(&above, &c, 1.0, [floor].into_iter()));
        // Raised to the camera's height, it meets the hull.
        let raised = (Vec3::new(-20.0, 1.9, -20.0), Vec3::new(20.0, 2.1, 20.0));
        assert!(!zpass_is_exact(&above, &c, 1.0, [raised].into_iter()));
    }

    #[test]
    fn a_directional_light_sweeps_the_near_plane_towards_it() {
        let c = camera();
        let sun = light(
            LightKind::Directional,
            Vec3::ZERO,
            Vec3::new(0.0, -1.0, -1.0),
        );
        // The sun shines down and away from the camera: the hull rises up and back from it.
        let behind_above = unit_box(Vec3::new(0.0, 40.0, 48.0));
        assert!(!zpass_is_exact(&sun, &c, 1.0, [behind_above].into_iter()));
        let ahead = unit_box(Vec3::new(0.0, 2.0, 0.0));
        assert!(zpass_is_exact(&sun, &c, 1.0, [ahead].into_iter()));
        // A sun in the near plane's plane (travelling sideways) leaves no volume to test.
        let sideways = light(LightKind::Directional, Vec3::ZERO, Vec3::X);
        assert!(NearClipVolume::new(&sideways, &c, 1.0).is_none());
        assert!(!zpass_is_exact(&sideways, &c, 1.0, std::iter::empty()));
    }

    #[test]
    fn every_point_of_the_hull_is_inside_its_planes() {
        let c = camera();
        let l = light(LightKind::Spot, Vec3::new(2.0, 6.0, 4.0), Vec3::NEG_Y);
        let v = NearClipVolume::new(&l, &c, 1.5).unwrap();
        let centre = c.position + Vec3::NEG_Z * c.near;
        for t in [0.0, 0.25, 0.5, 0.99] {
            let p = centre.lerp(l.position, t);
            assert!(v.meets_box((p, p)), "{t}");
        }
        // Past the light, and behind the near plane.
        let past = centre.lerp(l.position, 1.2);
        assert!(!v.meets_box((past, past)));
        let behind = c.position + Vec3::Z;
        assert!(!v.meets_box((behind, behind)));
    }
}
