//! The leak measure's unlit set against cases whose answer is known by construction: a room
//! behind a wall from the light is unlit everywhere, surfaces beside the lit room never are,
//! a wall that sees only a small sunlit patch through a skylight is not unlit even where every
//! cosine ray misses the patch; and the measure's arithmetic.

use glam::Vec3;
use zoo_judge::{
    Occluders, Reflectors, SurfacePoint, leak, lit_points, one_bounce, unlit_by_one_bounce,
};
use zoo_scene::{Light, LightKind};

/// The 12 triangles of the axis-aligned box from `lo` to `hi`.
fn box_triangles(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 3]> {
    let v =
        |x: usize, y: usize, z: usize| Vec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z]);
    let quads = [
        [v(0, 0, 0), v(1, 0, 0), v(1, 1, 0), v(0, 1, 0)],
        [v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1)],
        [v(0, 0, 0), v(0, 1, 0), v(0, 1, 1), v(0, 0, 1)],
        [v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1)],
        [v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1)],
        [v(0, 1, 0), v(1, 1, 0), v(1, 1, 1), v(0, 1, 1)],
    ];
    quads
        .iter()
        .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
        .collect()
}

/// The judge's occluders and grey reflectors over `triangles`.
fn world(triangles: &[[Vec3; 3]]) -> (Occluders, Reflectors) {
    let grey: Vec<([Vec3; 3], Vec3)> = triangles.iter().map(|t| (*t, Vec3::splat(0.6))).collect();
    (
        Occluders::from_triangles(triangles),
        Reflectors::from_triangles(&grey),
    )
}

fn light(kind: LightKind, position: Vec3, direction: Vec3) -> Light {
    Light {
        kind,
        position,
        direction,
        radiance: Vec3::splat(2.0),
        range: 100.0,
        spot_angle: 0.5,
        spot_softness: 0.2,
        radius: 0.0,
    }
}

/// Points on the inner faces of the box `lo`..`hi`: a grid on its floor and on its four walls,
/// each with the normal pointing into the box.
fn inner_points(lo: Vec3, hi: Vec3, per_side: usize) -> Vec<SurfacePoint> {
    let mut points = Vec::new();
    let at = |a: f32, b: f32, t: f32| a + (b - a) * t;
    for i in 0..per_side {
        for j in 0..per_side {
            let (s, t) = (
                (i as f32 + 0.5) / per_side as f32,
                (j as f32 + 0.5) / per_side as f32,
            );
            let (x, y, z) = (at(lo.x, hi.x, s), at(lo.y, hi.y, t), at(lo.z, hi.z, t));
            points.push(SurfacePoint::on_plane(Vec3::new(x, lo.y, z), Vec3::Y, 10.0));
            points.push(SurfacePoint::on_plane(
                Vec3::new(lo.x, y, at(lo.z, hi.z, s)),
                Vec3::X,
                10.0,
            ));
            points.push(SurfacePoint::on_plane(
                Vec3::new(hi.x, y, at(lo.z, hi.z, s)),
                Vec3::NEG_X,
                10.0,
            ));
            points.push(SurfacePoint::on_plane(Vec3::new(x, y, lo.z), Vec3::Z, 10.0));
            points.push(SurfacePoint::on_plane(
                Vec3::new(x, y, hi.z),
                Vec3::NEG_Z,
                10.0,
            ));
        }
    }
    points
}

#[test]
fn a_room_behind_a_wall_is_unlit_and_the_lit_room_is_not() {
    // Two closed rooms 2 m square side by side, 0.2 m apart; the light is in the first.
    let (a_lo, a_hi) = (Vec3::ZERO, Vec3::splat(2.0));
    let (b_lo, b_hi) = (Vec3::new(2.2, 0.0, 0.0), Vec3::new(4.2, 2.0, 2.0));
    let mut triangles = box_triangles(a_lo, a_hi);
    triangles.extend(box_triangles(b_lo, b_hi));
    let (occluders, reflectors) = world(&triangles);
    let lights = [
        // A bulb in the middle, lighting every face of the first room; a spot on its ceiling
        // pointing down, lighting only a disk of its floor.
        light(LightKind::Point, Vec3::new(1.0, 1.2, 1.0), Vec3::NEG_Y),
        light(LightKind::Spot, Vec3::new(1.0, 1.9, 1.0), Vec3::NEG_Y),
    ];
    for light in lights {
        let lights = [light];
        let lit = lit_points(&occluders, &reflectors, &lights);
        assert!(
            lit.len() > 500,
            "{:?}: {} lit points",
            light.kind,
            lit.len()
        );
        let inside =
            |p: Vec3, lo: Vec3, hi: Vec3| p.cmpge(lo - 1e-3).all() && p.cmple(hi + 1e-3).all();
        assert!(lit.iter().all(|q| inside(q.position, a_lo, a_hi)));
        let lit_room = inner_points(a_lo, a_hi, 6);
        let dark_room = inner_points(b_lo, b_hi, 6);
        let points: Vec<Option<SurfacePoint>> = lit_room
            .iter()
            .chain(&dark_room)
            .copied()
            .map(Some)
            .collect();
        let reference = one_bounce(&occluders, &reflectors, &lights, &points, 16);
        let unlit = unlit_by_one_bounce(&reflectors, &lit, &points, &reference);
        for (i, (&u, r)) in unlit.iter().zip(&reference).enumerate() {
            let in_dark_room = i >= lit_room.len();
            // Under the spot the lit room's floor sees only walls the cone barely grazes:
            // not a case with a known answer.
            if light.kind == LightKind::Spot && !in_dark_room && lit_room[i].normal == Vec3::Y {
                continue;
            }
            assert_eq!(u, in_dark_room, "{:?}: point {i} ({r})", light.kind);
            if in_dark_room {
                assert_eq!(*r, Vec3::ZERO);
            }
        }
    }
}

#[test]
fn a_wall_that_sees_a_small_sunlit_patch_is_not_unlit() {
    // A closed 2 m room with a 0.1 m square skylight in its 0.2 m thick roof: the sun lights a
    // 0.1 m patch of floor, 0.01 m², whose solid angle from the walls is so small that most
    // of their 16 cosine rays miss it. No wall point is unlit all the same; the space beside
    // the room (a closed box next to it) is.
    let (lo, hi) = (Vec3::ZERO, Vec3::splat(2.0));
    let mut triangles: Vec<[Vec3; 3]> = box_triangles(lo, hi)
        .into_iter()
        // Everything but the ceiling, which is rebuilt around the hole.
        .filter(|t| t.iter().any(|p| p.y < 2.0))
        .collect();
    let (h0, h1) = (0.95, 1.05);
    for (x0, x1, z0, z1) in [
        (0.0, 2.0, 0.0, h0),
        (0.0, 2.0, h1, 2.0),
        (0.0, h0, h0, h1),
        (h1, 2.0, h0, h1),
    ] {
        triangles.extend(box_triangles(
            Vec3::new(x0, 2.0, z0),
            Vec3::new(x1, 2.2, z1),
        ));
    }
    let (side_lo, side_hi) = (Vec3::new(2.5, 0.0, 0.0), Vec3::new(3.5, 1.0, 1.0));
    triangles.extend(box_triangles(side_lo, side_hi));
    let (occluders, reflectors) = world(&triangles);
    let sun = light(LightKind::Directional, Vec3::ZERO, Vec3::NEG_Y);
    let lights = [sun];
    let lit = lit_points(&occluders, &reflectors, &lights);
    let in_room: Vec<_> = lit.iter().filter(|q| q.position.y < 0.5).collect();
    assert!(
        in_room.len() >= 5,
        "{} lit points on the floor",
        in_room.len()
    );
    for q in &in_room {
        assert!((h0..=h1).contains(&q.position.x) && (h0..=h1).contains(&q.position.z));
    }
    // Wall points of the room away from the patch's corners, and inside the closed box.
    let walls: Vec<SurfacePoint> = inner_points(lo, Vec3::new(2.0, 1.8, 2.0), 5)
        .into_iter()
        .filter(|p| p.normal.y == 0.0)
        .collect();
    let closed = inner_points(side_lo, side_hi, 3);
    let points: Vec<Option<SurfacePoint>> =
        walls.iter().chain(&closed).copied().map(Some).collect();
    let reference = one_bounce(&occluders, &reflectors, &lights, &points, 16);
    let missed = reference[..walls.len()]
        .iter()
        .filter(|r| **r == Vec3::ZERO)
        .count();
    assert!(
        missed > walls.len() / 2,
        "most wall points miss the patch with every ray ({missed} of {})",
        walls.len()
    );
    let unlit = unlit_by_one_bounce(&reflectors, &lit, &points, &reference);
    for (i, u) in unlit.iter().enumerate() {
        assert_eq!(*u, i >= walls.len(), "point {i}: {:?}", points[i]);
    }
}

#[test]
fn the_leak_is_the_unlit_mean_over_the_reference_mean() {
    let reference = [
        Vec3::splat(2.0),
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::ZERO,
        Vec3::ZERO,
    ];
    let estimate = [
        Vec3::splat(9.0),
        Vec3::ZERO,
        Vec3::splat(0.3),
        Vec3::new(0.0, 0.0, 0.3),
    ];
    let mask = [true, true, true, false];
    let unlit = [false, false, true, true];
    // Reference mean over the masked pixels: (2 + 2 + 0) / 3; unlit mean: (0.3 + 0.1) / 2.
    let expected = 0.2 / (4.0 / 3.0);
    let got = leak(&reference, &estimate, &mask, &unlit);
    // The inputs are f32: agreement to their precision.
    assert!((got - expected).abs() < 1e-6, "{got} against {expected}");
    // Nothing unlit, or nothing leaked: 0. A black reference with light on unlit pixels: ∞.
    assert_eq!(leak(&reference, &estimate, &mask, &[false; 4]), 0.0);
    assert_eq!(leak(&reference, &[Vec3::ZERO; 4], &mask, &unlit), 0.0);
    assert_eq!(
        leak(&[Vec3::ZERO; 4], &estimate, &mask, &unlit),
        f64::INFINITY
    );
}
