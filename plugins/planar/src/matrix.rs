//! Blinn's planar projection matrix.

use zoo_host::glam::{Mat4, Vec4};

/// Projects points onto `plane` (a, b, c, d with a x + b y + c z + d = 0) from the homogeneous
/// light `light`: (x, y, z, 1) for point and spot lights, (dx, dy, dz, 0) toward the light for
/// directional ones. `M = (P . L) I - L P^T`; the result needs the homogeneous divide.
pub fn shadow_matrix(plane: Vec4, light: Vec4) -> Mat4 {
    let dot = plane.dot(light);
    // Column j of L P^T is L * P[j].
    Mat4::from_diagonal(Vec4::splat(dot))
        - Mat4::from_cols(
            light * plane.x,
            light * plane.y,
            light * plane.z,
            light * plane.w,
        )
}

/// Signed height of `point` above `plane` (positive on the front side).
pub fn height(plane: Vec4, point: Vec4) -> f32 {
    plane.dot(point)
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::glam::Vec3;

    fn planes() -> Vec<Vec4> {
        let tilted = Vec3::new(0.3, 1.0, -0.2).normalize();
        vec![
            Vec4::new(0.0, 1.0, 0.0, 0.0),
            Vec4::new(1.0, 0.0, 0.0, 6.0),
            tilted.extend(-0.7),
        ]
    }

    fn points() -> Vec<Vec3> {
        (0..20)
            .map(|i| {
                let t = i as f32;
                Vec3::new(
                    (t * 0.7).sin() * 2.0,
                    0.5 + (t * 0.3).cos().abs() * 2.0,
                    (t * 1.3).cos() * 2.0,
                )
            })
            .collect()
    }

    #[test]
    fn projected_points_lie_on_the_plane_and_the_light_ray() {
        let light = Vec3::new(0.5, 6.0, 1.0);
        for plane in planes() {
            let m = shadow_matrix(plane, light.extend(1.0));
            for p in points() {
                let s = m * p.extend(1.0);
                let s = s.truncate() / s.w;
                assert!(plane.dot(s.extend(1.0)).abs() < 1e-4, "off the plane: {s}");
                // s, p and the light are collinear.
                let cross = (p - light).cross(s - light);
                assert!(
                    cross.length() < 1e-3 * (s - light).length(),
                    "not on the light ray"
                );
            }
        }
    }

    #[test]
    fn directional_form_projects_along_the_light_direction() {
        let toward_light = Vec3::new(-0.3, 1.0, 0.4).normalize();
        for plane in planes() {
            let m = shadow_matrix(plane, toward_light.extend(0.0));
            for p in points() {
                let s = m * p.extend(1.0);
                assert!(
                    (s.w - plane.truncate().dot(toward_light)).abs() < 1e-6,
                    "w is P . L"
                );
                let s = s.truncate() / s.w;
                assert!(plane.dot(s.extend(1.0)).abs() < 1e-4);
                assert!(
                    (s - p).cross(toward_light).length() < 1e-4,
                    "not along the light"
                );
            }
        }
    }

    #[test]
    fn the_homogeneous_weight_flags_anti_and_false_shadows() {
        // w = P.L - P.p: positive between plane and light, negative beyond the light.
        let plane = Vec4::new(0.0, 1.0, 0.0, 0.0);
        let light = Vec4::new(0.0, 4.0, 0.0, 1.0);
        let m = shadow_matrix(plane, light);
        assert!((m * Vec4::new(0.0, 2.0, 0.0, 1.0)).w > 0.0);
        assert!(
            (m * Vec4::new(0.0, 5.0, 0.0, 1.0)).w < 0.0,
            "beyond the light: anti-shadow"
        );
        assert!(
            height(plane, Vec4::new(0.0, -1.0, 0.0, 1.0)) < 0.0,
            "below the plane"
        );
    }
}
