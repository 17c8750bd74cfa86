//! Which light layers the camera can see: frustum-frustum and sphere-frustum tests on
//! world-to-clip matrices (depth in [0, 1]), so techniques with many lights render only the
//! maps that can shadow a visible pixel; and which casters a layer's map can hold (a box
//! against the layer's side planes).

use zoo_host::glam::{Mat4, Vec3, Vec4};

/// The six planes (inward normals, `n . p + d >= 0` inside) of a clip volume with depth in
/// [0, 1], normalised.
pub fn frustum_planes(view_proj: Mat4) -> [Vec4; 6] {
    let r = [
        view_proj.row(0),
        view_proj.row(1),
        view_proj.row(2),
        view_proj.row(3),
    ];
    [
        r[3] + r[0],
        r[3] - r[0],
        r[3] + r[1],
        r[3] - r[1],
        r[2],
        r[3] - r[2],
    ]
    .map(|p| p / p.truncate().length().max(f32::MIN_POSITIVE))
}

/// The eight world-space corners of a clip volume (depth in [0, 1]).
pub fn frustum_corners(view_proj: Mat4) -> [Vec3; 8] {
    let inverse = view_proj.inverse();
    std::array::from_fn(|i| {
        let ndc = Vec3::new(
            if i & 1 == 0 { -1.0 } else { 1.0 },
            if i & 2 == 0 { -1.0 } else { 1.0 },
            if i & 4 == 0 { 0.0 } else { 1.0 },
        );
        inverse.project_point3(ndc)
    })
}

/// Whether all `points` lie outside one plane.
fn separated(planes: &[Vec4; 6], points: &[Vec3; 8]) -> bool {
    planes.iter().any(|plane| {
        points
            .iter()
            .all(|p| plane.truncate().dot(*p) + plane.w < 0.0)
    })
}

/// Whether two clip volumes may overlap: false only when a face plane of one has every
/// corner of the other outside it (conservative: some disjoint pairs are kept).
pub fn frusta_intersect(a: Mat4, b: Mat4) -> bool {
    !separated(&frustum_planes(a), &frustum_corners(b))
        && !separated(&frustum_planes(b), &frustum_corners(a))
}

/// Whether a sphere may touch the clip volume (false only when it lies wholly outside one of
/// its planes).
pub fn sphere_intersects(planes: &[Vec4; 6], centre: Vec3, radius: f32) -> bool {
    planes
        .iter()
        .all(|plane| plane.truncate().dot(centre) + plane.w >= -radius)
}

/// Whether a world box may project into a layer's map: false only when it lies wholly
/// outside one of the four side planes of `view_proj`'s clip volume widened by `margin` (in
/// normalised device units, so rasterisation grown beyond the box, as conservative coverage
/// is, stays inside). The near and far planes are not tested: casters nearer the light than
/// the near plane still cast.
pub fn box_meets_sides(view_proj: Mat4, margin: f32, (lo, hi): (Vec3, Vec3)) -> bool {
    let (x, y, w) = (view_proj.row(0), view_proj.row(1), view_proj.row(3));
    let widened = w * (1.0 + margin);
    [widened + x, widened - x, widened + y, widened - y]
        .iter()
        .all(|plane| {
            // The box corner farthest along the plane's inward normal.
            let n = plane.truncate();
            let corner = Vec3::select(n.cmpge(Vec3::ZERO), hi, lo);
            n.dot(corner) + plane.w >= 0.0
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::glam::camera::rh::proj::directx;

    fn camera(eye: Vec3, target: Vec3) -> Mat4 {
        directx::perspective(1.0, 1.0, 0.1, 10.0)
            * zoo_host::glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y)
    }

    #[test]
    fn corners_lie_on_the_planes() {
        let m = camera(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO);
        let planes = frustum_planes(m);
        for corner in frustum_corners(m) {
            for plane in planes {
                assert!(plane.truncate().dot(corner) + plane.w > -1e-3);
            }
        }
    }

    #[test]
    fn facing_frusta_meet_and_opposite_ones_do_not() {
        let a = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0));
        let b = camera(Vec3::new(0.0, 0.0, -8.0), Vec3::ZERO);
        assert!(frusta_intersect(a, b));
        let away = camera(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 5.0));
        assert!(!frusta_intersect(a, away));
        let planes = frustum_planes(a);
        assert!(sphere_intersects(&planes, Vec3::new(0.0, 0.0, -5.0), 0.5));
        assert!(sphere_intersects(&planes, Vec3::new(0.0, 0.0, 0.5), 0.6));
        assert!(!sphere_intersects(&planes, Vec3::new(0.0, 0.0, 2.0), 1.0));
        assert!(!sphere_intersects(&planes, Vec3::new(0.0, 0.0, -20.0), 5.0));
    }

    #[test]
    fn boxes_beside_a_layer_are_culled_and_those_in_front_of_it_kept() {
        // Looking down -z from the origin, 90 degrees wide, depth from 1 to 10.
        let view = zoo_host::glam::camera::rh::view::look_at_mat4(Vec3::ZERO, -Vec3::Z, Vec3::Y);
        let m = directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, 1.0, 10.0) * view;
        let unit = |c: Vec3| (c - Vec3::splat(0.5), c + Vec3::splat(0.5));
        assert!(box_meets_sides(m, 0.0, unit(Vec3::new(0.0, 0.0, -5.0))));
        // Beside the frustum (x > -z everywhere on the box), above it, behind the light.
        assert!(!box_meets_sides(m, 0.0, unit(Vec3::new(7.0, 0.0, -5.0))));
        assert!(!box_meets_sides(m, 0.0, unit(Vec3::new(0.0, 7.0, -5.0))));
        assert!(!box_meets_sides(m, 0.0, unit(Vec3::new(0.0, 0.0, 5.0))));
        // Nearer the light than the near plane, or past the far plane: kept (they may cast).
        assert!(box_meets_sides(m, 0.0, unit(Vec3::new(0.0, 0.0, -0.6))));
        assert!(box_meets_sides(m, 0.0, unit(Vec3::new(0.0, 0.0, -20.0))));
        // Just outside a side plane: kept once the margin reaches it. The box's corner nearest
        // the plane x = -z is (5.15, -5.05), 2 % of the half-width (5.05) beyond it.
        let beside = (Vec3::new(5.15, -0.05, -5.05), Vec3::new(5.25, 0.05, -4.95));
        assert!(!box_meets_sides(m, 0.0, beside));
        assert!(!box_meets_sides(m, 0.015, beside));
        assert!(box_meets_sides(m, 0.025, beside));
        // A box around the light meets every side.
        assert!(box_meets_sides(m, 0.0, unit(Vec3::ZERO)));
    }
}
