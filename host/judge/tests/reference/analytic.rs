//! The reference against closed-form shadows: the outline of a sphere's shadow on a plane and
//! the penumbra profile behind a straight edge under a disk light.

use std::path::Path;

use glam::{Vec2, Vec3};
use zoo_judge::{LightReference, Metrics, Occluders, SurfacePoint, reference_visibility};
use zoo_scene::Scene;

const GRID: usize = 192;

fn scene(objects: &str, light: &str) -> Scene {
    let text = format!(
        "(camera: (position: (0, 5, 5), target: (0, 0, 0)), lights: [{light}], objects: [{objects}])"
    );
    Scene::from_ron(&text, Path::new("analytic.ron"), Path::new(".")).unwrap()
}

/// A `GRID` x `GRID` patch of the plane y = 0 over [-half, half]^2, facing up.
fn floor_points(center: Vec2, half: f32) -> Vec<Option<SurfacePoint>> {
    (0..GRID * GRID)
        .map(|i| {
            let (x, z) = ((i % GRID) as f32, (i / GRID) as f32);
            let t = (Vec2::new(x, z) + 0.5) / GRID as f32 * 2.0 - 1.0;
            let p = center + t * half;
            Some(SurfacePoint::on_plane(
                Vec3::new(p.x, 0.0, p.y),
                Vec3::Y,
                10.0,
            ))
        })
        .collect()
}

/// Whether the ray from `p` along `dir` (up to `tmax`) meets the exact sphere.
fn hits_sphere(p: Vec3, dir: Vec3, tmax: f32, center: Vec3, radius: f32) -> bool {
    let t = (center - p).dot(dir).clamp(0.0, tmax);
    (p + dir * t).distance(center) < radius
}

/// Checks `reference` against the analytic hard shadow everywhere outside the one-pixel band
/// around the analytic shadow boundary, and that the shadow has a sensible size.
fn assert_hard_agrees(
    reference: &LightReference,
    analytic: &[bool],
    expected_fraction: (f64, f64),
) {
    let boundary = |i: usize| {
        let (x, y) = ((i % GRID) as i64, (i / GRID) as i64);
        (-1..=1).any(|dy: i64| {
            (-1..=1).any(|dx: i64| {
                let (nx, ny) = (x + dx, y + dy);
                (0..GRID as i64).contains(&nx)
                    && (0..GRID as i64).contains(&ny)
                    && analytic[(ny * GRID as i64 + nx) as usize] != analytic[i]
            })
        })
    };
    let mut disagreements = 0;
    for (i, &shadowed) in analytic.iter().enumerate() {
        assert!(reference.contributing[i]);
        let reference_shadowed = reference.hard[i] < 0.5;
        if reference_shadowed != shadowed && !boundary(i) {
            disagreements += 1;
        }
    }
    assert_eq!(disagreements, 0, "pixels outside the edge band disagree");
    let fraction = reference.shadowed_fraction();
    assert!(
        fraction > expected_fraction.0 && fraction < expected_fraction.1,
        "shadowed fraction {fraction}"
    );
}

const SPHERE: &str =
    "(mesh: Sphere(radius: 0.5, segments: 256, rings: 128), transform: (translation: (0, 1.5, 0)))";

#[test]
fn sphere_shadow_under_a_point_light_matches_closed_form() {
    let s = scene(SPHERE, "Point(position: (0.6, 4.0, 0.3), range: 100)");
    let occluders = Occluders::new(&s);
    let points = floor_points(Vec2::ZERO, 1.6);
    let light = s.lights[0];
    let reference = reference_visibility(&occluders, &light, &points, 1);
    let analytic: Vec<bool> = points
        .iter()
        .map(|p| {
            let p = p.unwrap().position;
            let to = light.position - p;
            hits_sphere(
                p,
                to.normalize(),
                to.length(),
                Vec3::new(0.0, 1.5, 0.0),
                0.5,
            )
        })
        .collect();
    // The shadow is a disk of radius about 0.5 * 4 / 2.5 = 0.8 on a 3.2 x 3.2 patch.
    assert_hard_agrees(&reference, &analytic, (0.15, 0.30));
}

#[test]
fn sphere_shadow_under_a_directional_light_matches_closed_form() {
    let s = scene(SPHERE, "Directional(direction: (0.4, -1.0, -0.2))");
    let occluders = Occluders::new(&s);
    let points = floor_points(Vec2::new(0.6, -0.3), 1.2);
    let light = s.lights[0];
    let reference = reference_visibility(&occluders, &light, &points, 1);
    let analytic: Vec<bool> = points
        .iter()
        .map(|p| {
            hits_sphere(
                p.unwrap().position,
                -light.direction,
                f32::INFINITY,
                Vec3::new(0.0, 1.5, 0.0),
                0.5,
            )
        })
        .collect();
    assert_hard_agrees(&reference, &analytic, (0.10, 0.30));
}

/// Fraction of the unit disk with x >= s (a circular segment).
fn disk_fraction_beyond(s: f32) -> f32 {
    let s = s.clamp(-1.0, 1.0);
    (s.acos() - s * (1.0 - s * s).sqrt()) / std::f32::consts::PI
}

/// A thin slab covering x < 0 at height `EDGE_HEIGHT`: its edge is the line x = 0.
const EDGE_HEIGHT: f32 = 1.0;
const SLAB: &str = "(mesh: Box(size: (6, 0.002, 6)), transform: (translation: (-3, 1.0, 0)))";

fn assert_penumbra(
    reference: &LightReference,
    points: &[Option<SurfacePoint>],
    profile: impl Fn(f32) -> f32,
) {
    let mut total = 0.0;
    let mut in_penumbra = 0;
    for (i, p) in points.iter().enumerate() {
        let x = p.unwrap().position.x;
        let expected = profile(x);
        total += (reference.area[i] - expected).abs();
        if expected > 0.05 && expected < 0.95 {
            in_penumbra += 1;
        }
    }
    let mean = total / points.len() as f32;
    eprintln!(
        "mean penumbra error {mean:.4} over {} samples",
        points.len()
    );
    assert!(
        in_penumbra > points.len() / 4,
        "penumbra covers only {in_penumbra} samples"
    );
    assert!(mean < 0.02, "mean penumbra error {mean}");
}

#[test]
fn penumbra_behind_an_edge_under_a_directional_disk_light() {
    // Sun straight down with a 5 degree angular radius: a ray tilted by tan(a) * d (d in the
    // unit disk) passes the edge height at x + h tan(a) d.x, so the visible fraction is the
    // part of the disk with d.x >= -x / (h tan a).
    let s = scene(
        SLAB,
        "Directional(direction: (0, -1, 0), angular_radius_degrees: 5)",
    );
    let occluders = Occluders::new(&s);
    let points = floor_points(Vec2::new(0.0, 0.0), 0.15);
    let reference = reference_visibility(&occluders, &s.lights[0], &points, 64);
    assert_eq!(reference.samples, 64);
    let spread = EDGE_HEIGHT * 5f32.to_radians().tan();
    assert_penumbra(&reference, &points, |x| disk_fraction_beyond(-x / spread));
}

#[test]
fn penumbra_behind_an_edge_under_a_spherical_point_light() {
    // Light of radius r at height H above x = 0: a ray from floor point x to light point X
    // crosses the edge height where x + (X - x) h / H, blocked when that is negative, so the
    // visible part of the light is X >= x (1 - H / h).
    let (height, radius) = (3.0, 0.3);
    let s = scene(
        SLAB,
        &format!("Point(position: (0, {height}, 0), range: 100, radius: {radius})"),
    );
    let occluders = Occluders::new(&s);
    // The penumbra spans |x| < r / (H / h - 1) = 0.15.
    let points = floor_points(Vec2::ZERO, 0.3);
    let reference = reference_visibility(&occluders, &s.lights[0], &points, 64);
    assert_penumbra(&reference, &points, |x| {
        disk_fraction_beyond(x * (1.0 - height / EDGE_HEIGHT) / radius)
    });
}

#[test]
fn hard_and_area_visibility_agree_for_lights_without_radius() {
    let s = scene(SLAB, "Point(position: (0.2, 3, 0), range: 100)");
    let occluders = Occluders::new(&s);
    let points = floor_points(Vec2::ZERO, 1.0);
    let r = reference_visibility(&occluders, &s.lights[0], &points, 64);
    assert_eq!(r.hard, r.area);
    // Metrics of the reference against itself are all zero.
    let m = Metrics::compute(&r, &r.hard, GRID, GRID, None);
    assert_eq!(
        (m.false_shadow, m.false_lit, m.mae, m.p95_error),
        (0.0, 0.0, 0.0, 0.0)
    );
}

#[test]
fn a_million_triangles_work() {
    // 1000 x 500 segments: about a million triangles.
    let s = scene(
        "(mesh: Sphere(radius: 0.5, segments: 1000, rings: 500), transform: (translation: (0, 1.5, 0)))",
        "Point(position: (0, 4.0, 0), range: 100)",
    );
    assert!(s.triangle_count() >= 998_000, "{}", s.triangle_count());
    let occluders = Occluders::new(&s);
    let points = floor_points(Vec2::ZERO, 1.6);
    let r = reference_visibility(&occluders, &s.lights[0], &points, 1);
    // Shadow disk radius 0.5 * 4 / 2.5 = 0.8 over a 3.2-wide patch: pi 0.64 / 10.24 = 0.196.
    let fraction = r.shadowed_fraction();
    assert!((fraction - 0.196).abs() < 0.01, "{fraction}");
}

/// A wall lit at grazing incidence by a sun with an angular radius: half of the sun's disk lies
/// below the wall's horizon, but that half lights nothing shadowed or not, so the area
/// visibility (the ratio of shadowed to unshadowed irradiance) is 1 on an unoccluded wall, as
/// is the hard visibility. A point light above the wall's plane behaves the same way.
#[test]
fn a_wall_at_grazing_incidence_is_fully_visible() {
    for light in [
        "Directional(direction: (0.0, -1.0, 0.0), angular_radius_degrees: 3)",
        "Point(position: (0, 20, 0.001), range: 100, radius: 1)",
    ] {
        // The back wall: the plane z = 0 facing +z, from y = 0 to 10.
        let s = scene(
            "(mesh: Plane(size: 10), transform: (translation: (0, 5, 0), rotation_degrees: (90, 0, 0)))",
            light,
        );
        let occluders = Occluders::new(&s);
        // Normals as a G-buffer stores them: a hair towards the light, so the light counts.
        let points: Vec<Option<SurfacePoint>> = (0..64)
            .map(|i| {
                Some(SurfacePoint::on_plane(
                    Vec3::new(-3.0 + i as f32 * 0.1, 1.0 + i as f32 * 0.05, 0.0),
                    Vec3::new(0.0, 1e-6, 1.0).normalize(),
                    10.0,
                ))
            })
            .collect();
        let r = reference_visibility(&occluders, &s.lights[0], &points, 64);
        for i in 0..points.len() {
            assert!(r.contributing[i], "{light}: point {i}");
            assert_eq!(r.hard[i], 1.0, "{light}: point {i}");
            assert!(r.area[i] > 0.999, "{light}: point {i} area {}", r.area[i]);
        }
    }
}

/// A unit box (12 triangles) centred at `c` with half-size `h`.
fn cube(c: Vec3, h: f32) -> Vec<[Vec3; 3]> {
    let v = |x: f32, y: f32, z: f32| c + Vec3::new(x, y, z) * h;
    let quads = [
        [
            v(-1., -1., -1.),
            v(1., -1., -1.),
            v(1., 1., -1.),
            v(-1., 1., -1.),
        ],
        [
            v(-1., -1., 1.),
            v(1., -1., 1.),
            v(1., 1., 1.),
            v(-1., 1., 1.),
        ],
        [
            v(-1., -1., -1.),
            v(-1., 1., -1.),
            v(-1., 1., 1.),
            v(-1., -1., 1.),
        ],
        [
            v(1., -1., -1.),
            v(1., 1., -1.),
            v(1., 1., 1.),
            v(1., -1., 1.),
        ],
        [
            v(-1., -1., -1.),
            v(1., -1., -1.),
            v(1., -1., 1.),
            v(-1., -1., 1.),
        ],
        [
            v(-1., 1., -1.),
            v(1., 1., -1.),
            v(1., 1., 1.),
            v(-1., 1., 1.),
        ],
    ];
    quads
        .iter()
        .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
        .collect()
}

#[test]
fn translucent_casters_filter_once_each_and_opaque_ones_block() {
    let red = Vec3::new(0.5, 0.0, 0.0);
    let cyan = Vec3::new(0.0, 0.8, 0.6);
    let occluders = Occluders::with_translucent(
        &cube(Vec3::new(4.0, 3.0, 0.0), 0.5),
        &[
            (cube(Vec3::new(0.0, 2.0, 0.0), 0.5), red),
            (cube(Vec3::new(0.0, 4.0, 0.0), 0.5), cyan),
            (cube(Vec3::new(-4.0, 2.0, 0.0), 0.5), cyan),
        ],
    );
    let up = Vec3::Y;
    // Through one closed box: two of its faces, one filter.
    assert_eq!(occluders.transmittance(Vec3::ZERO, up, 3.0), red);
    // Through both boxes above the origin: the product.
    assert_eq!(occluders.transmittance(Vec3::ZERO, up, 10.0), red * cyan);
    assert!(
        !occluders.occluded(Vec3::ZERO, up, 10.0),
        "translucent casters do not block"
    );
    // An opaque box stops everything, whatever is translucent on the way.
    assert_eq!(
        occluders.transmittance(Vec3::new(4.0, 0.0, 0.0), up, 10.0),
        Vec3::ZERO
    );
    assert!(occluders.occluded(Vec3::new(4.0, 0.0, 0.0), up, 10.0));
    // Nothing in the way, or the segment ends before the box.
    assert_eq!(
        occluders.transmittance(Vec3::new(2.0, 0.0, 0.0), up, 10.0),
        Vec3::ONE
    );
    assert_eq!(
        occluders.transmittance(Vec3::new(-4.0, 0.0, 0.0), up, 1.0),
        Vec3::ONE
    );
    assert_eq!(
        occluders.transmittance(Vec3::new(-4.0, 0.0, 0.0), up, 2.0),
        cyan
    );
}

#[test]
fn scenes_give_translucent_shadows_their_colour() {
    let pole = "(mesh: Box(size: (0.4, 2, 0.4)), transform: (translation: (0, 1, 0)), \
                opacity: 0.5, transmission: (1, 0.1, 0.1))";
    let s = scene(pole, "Point(position: (0, 6, 0), intensity: 10, range: 50)");
    let occluders = Occluders::new(&s);
    assert!(occluders.has_translucent());
    let points = floor_points(Vec2::ZERO, 2.0);
    let r = reference_visibility(&occluders, &s.lights[0], &points, 1);
    let color = r
        .color
        .as_ref()
        .expect("colour kept in scenes with translucent casters");
    let center = GRID / 2 * GRID + GRID / 2;
    let expected = Vec3::new(0.5, 0.05, 0.05);
    assert!(color[center].distance(expected) < 1e-6, "{}", color[center]);
    assert!((r.hard[center] - 0.2).abs() < 1e-6, "{}", r.hard[center]);
    assert_eq!(color[0], Vec3::ONE, "outside the shadow");
    // Opacity outside [0, 1] is refused with the field named.
    let bad = "(mesh: Box(size: (1, 1, 1)), opacity: 1.5)";
    let text = format!(
        "(camera: (position: (0, 5, 5), target: (0, 0, 0)), lights: [Point(position: (0, 6, 0))], objects: [{bad}])"
    );
    let e = Scene::from_ron(&text, Path::new("bad.ron"), Path::new(".")).unwrap_err();
    assert!(e.to_string().contains("objects[0].opacity"), "{e}");
}
