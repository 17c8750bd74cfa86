//! The one-bounce reference against closed forms: the light a point receives from a uniformly
//! lit square above it (a form factor), and its linearity in the reflector's albedo.

use glam::Vec3;
use zoo_judge::{Occluders, Reflectors, SurfacePoint, one_bounce, reflected_direct, relative_rmse};
use zoo_scene::{Light, LightKind};

/// A square of half side `half` at height `height` over the origin, as two triangles.
fn ceiling(half: f32, height: f32) -> Vec<[Vec3; 3]> {
    let v = |x: f32, z: f32| Vec3::new(x, height, z);
    vec![
        [v(-half, -half), v(half, -half), v(half, half)],
        [v(-half, -half), v(half, half), v(-half, half)],
    ]
}

/// A sun shining straight up, so the square's underside is lit and nothing else is.
fn upward_sun(radiance: f32) -> Light {
    Light {
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: Vec3::Y,
        radiance: Vec3::splat(radiance),
        range: f32::INFINITY,
        spot_angle: 0.0,
        spot_softness: 0.0,
        radius: 0.0,
    }
}

/// Form factor from a differential area to a parallel rectangle of half sides `a`, `b` at
/// distance `c` centred over it: four times the corner form.
fn centred_form_factor(a: f32, b: f32, c: f32) -> f32 {
    let (x, y) = (a / c, b / c);
    let corner = (x / (1.0 + x * x).sqrt() * (y / (1.0 + x * x).sqrt()).atan()
        + y / (1.0 + y * y).sqrt() * (x / (1.0 + y * y).sqrt()).atan())
        / (2.0 * std::f32::consts::PI);
    4.0 * corner
}

fn floor_points(count: usize) -> Vec<Option<SurfacePoint>> {
    (0..count)
        .map(|i| {
            Some(SurfacePoint::on_plane(
                Vec3::X * (i as f32 * 1e-3),
                Vec3::Y,
                1.0,
            ))
        })
        .collect()
}

#[test]
fn a_lit_square_gives_its_form_factor() {
    let (half, height, albedo, radiance) = (2.0, 1.0, 0.5, 1.5);
    let square = ceiling(half, height);
    let occluders = Occluders::from_triangles(&square);
    let reflectors = Reflectors::from_triangles(
        &square
            .iter()
            .map(|t| (*t, Vec3::splat(albedo)))
            .collect::<Vec<_>>(),
    );
    let lights = [upward_sun(radiance)];
    // The underside reflects albedo x radiance (n . l = 1, nothing in the way).
    let hit = reflectors
        .closest(Vec3::ZERO, Vec3::Y)
        .expect("the square is above");
    assert!((hit.distance - height).abs() < 1e-4);
    assert_eq!(hit.point.normal, Vec3::NEG_Y);
    let leaving = reflected_direct(&occluders, &lights, &hit.point, hit.albedo);
    assert!(
        (leaving - Vec3::splat(albedo * radiance))
            .abs()
            .max_element()
            < 1e-5
    );
    // What reaches the origin: the leaving radiance times the form factor.
    let expected = albedo * radiance * centred_form_factor(half, half, height);
    let points = floor_points(8);
    let estimate = one_bounce(&occluders, &reflectors, &lights, &points, 1024);
    for e in &estimate {
        let relative = (e.x - expected).abs() / expected;
        assert!(relative < 0.015, "{e} against {expected}");
        assert_eq!(e.x, e.y);
    }
    // Background pixels get nothing; a reference against itself has no error.
    let none = one_bounce(&occluders, &reflectors, &lights, &[None], 16);
    assert_eq!(none, vec![Vec3::ZERO]);
    assert_eq!(relative_rmse(&estimate, &estimate, &[true; 8]), 0.0);
    let doubled: Vec<Vec3> = estimate.iter().map(|e| *e * 1.1).collect();
    assert!((relative_rmse(&estimate, &doubled, &[true; 8]) - 0.1).abs() < 1e-6);
}

#[test]
fn a_shadowed_reflector_sends_nothing_and_albedo_scales_the_light() {
    let square = ceiling(2.0, 1.0);
    let lights = [upward_sun(1.0)];
    let points = floor_points(4);
    let bright: Vec<_> = square
        .iter()
        .map(|t| (*t, Vec3::new(0.8, 0.4, 0.2)))
        .collect();
    let occluders = Occluders::from_triangles(&square);
    let lit = one_bounce(
        &occluders,
        &Reflectors::from_triangles(&bright),
        &lights,
        &points,
        256,
    );
    // Colour follows the albedo channel by channel.
    for e in &lit {
        assert!(
            (e.y / e.x - 0.5).abs() < 1e-4 && (e.z / e.x - 0.25).abs() < 1e-4,
            "{e}"
        );
    }
    // An opaque plate between the sun and the square (a caster, not a reflector here) leaves
    // the square in shadow: it sends nothing.
    let mut blocked = square.clone();
    blocked.extend(ceiling(2.5, 0.9));
    let plate_above_points = Occluders::from_triangles(&blocked);
    let dark = one_bounce(
        &plate_above_points,
        &Reflectors::from_triangles(&bright),
        &lights,
        &points,
        256,
    );
    for e in &dark {
        assert_eq!(*e, Vec3::ZERO, "the reflector is in the plate's shadow");
    }
}
