//! Instances: the judge traces rays into each instance's shared triangles through the inverse
//! of its placement, and must find what it finds on copies of those triangles placed in world
//! space.

use std::path::Path;

use glam::Vec3;
use zoo_judge::{Occluders, Surfaces};
use zoo_scene::Scene;

use crate::Rng;

/// A scene of instanced casters (rotated, non-uniformly scaled, far from the origin and small),
/// each object's own transform the identity.
const INSTANCED: &str = r#"(
    camera: (position: (0, 6, 14), target: (0, 0, 0)),
    lights: [Directional(direction: (0.3, -1, 0.2))],
    objects: [
        (name: "floor", mesh: Plane(size: 30)),
        (name: "ball", mesh: Sphere(radius: 0.8, segments: 24, rings: 12),
         instances: [
            (translation: (-4, 1, 0)),
            (translation: (3, 2, -2), rotation_degrees: (20, 40, 10), scale: (1.5, 0.6, 1.0)),
            (translation: (0.5, 0.3, 4), scale: (0.02, 0.02, 0.02)),
         ]),
        (name: "ring", mesh: Torus(major_radius: 1.0, minor_radius: 0.25, segments: 32, rings: 12),
         instances: [
            (translation: (0, 1.5, 0), rotation_degrees: (70, 0, 0)),
            (translation: (5, 0.5, 3), rotation_degrees: (0, 45, 30), scale: (2, 1, 1)),
            (translation: (-6, 3, -5), rotation_degrees: (90, 10, 0), scale: (0.5, 0.5, 0.5)),
         ]),
    ],
)"#;

fn scenes() -> (Scene, Scene) {
    let path = Path::new("instances.ron");
    let description = zoo_scene::parse_description(INSTANCED, path).unwrap();
    let instanced = Scene::from_description(&description, path, Path::new(".")).unwrap();
    let copies = description.instances_copied().unwrap();
    let copied = Scene::from_description(&copies, path, Path::new(".")).unwrap();
    assert_eq!(instanced.objects.len(), copied.objects.len());
    assert!(instanced.triangle_count() < copied.triangle_count());
    assert_eq!(instanced.drawn_triangle_count(), copied.triangle_count());
    (instanced, copied)
}

/// A random point in the box of half-width `extent` above the ground.
fn point(rng: &mut Rng, extent: f32) -> Vec3 {
    Vec3::new(rng.range(-1.0, 1.0), rng.unit(), rng.range(-1.0, 1.0)) * extent
}

#[test]
fn instances_block_and_are_seen_where_their_copies_are() {
    let (instanced, copied) = scenes();
    let (a, b) = (Occluders::new(&instanced), Occluders::new(&copied));
    assert_eq!(
        a.len(),
        b.len(),
        "the instances' triangles, counted once per instance"
    );
    let (sa, sb) = (Surfaces::new(&instanced), Surfaces::new(&copied));
    let mut rng = Rng(17);
    let (mut rays, mut blocked, mut differ, mut seen) = (0, 0, 0, 0);
    for _ in 0..40_000 {
        let origin = point(&mut rng, 8.0);
        let target = point(&mut rng, 8.0);
        let length = origin.distance(target);
        if length < 1e-3 {
            continue;
        }
        let direction = (target - origin) / length;
        rays += 1;
        let (x, y) = (
            a.occluded(origin, direction, length),
            b.occluded(origin, direction, length),
        );
        blocked += usize::from(y);
        differ += usize::from(x != y);
        match (sa.closest(origin, direction), sb.closest(origin, direction)) {
            (Some(p), Some(q)) => {
                seen += 1;
                let scale = 1.0 + p.distance.max(q.distance);
                assert!(
                    (p.distance - q.distance).abs() <= 1e-5 * scale,
                    "{p:?} {q:?}"
                );
                assert!(p.point.position.abs_diff_eq(q.point.position, 1e-4 * scale));
                assert!(
                    p.point.normal.abs_diff_eq(q.point.normal, 1e-3),
                    "{p:?} {q:?}"
                );
                let (ca, cb) = (sa.corners(p.triangle), sb.corners(q.triangle));
                for (u, v) in ca.iter().zip(&cb) {
                    assert!(u.abs_diff_eq(*v, 1e-4 * (1.0 + v.abs().max_element())));
                }
            }
            (None, None) => {}
            (p, q) => {
                // Only a ray grazing an edge may fall on either side.
                differ += 1;
                eprintln!("one hit only: {p:?} {q:?}");
            }
        }
    }
    eprintln!("{rays} rays, {blocked} blocked, {seen} hit a surface, {differ} disagree");
    assert!(
        blocked > rays / 25 && seen > rays / 4,
        "the rays meet the instances"
    );
    assert!(differ <= rays / 10_000, "{differ} of {rays} rays disagree");
}

/// A stretched instance far from the origin, and a tiny one: every point the judge finds on
/// a face turned to the light is lit, although its shadow ray enters the instance's space
/// through a placement that rounds and stretches its error.
#[test]
fn stretched_and_distant_instances_do_not_shadow_themselves() {
    for (placement, eye_offset) in [
        (
            "(translation: (10000, 5, -7000), rotation_degrees: (10, 30, 5), scale: (4, 0.5, 1))",
            6.0,
        ),
        (
            "(translation: (120, 0.02, 80), rotation_degrees: (0, 60, 8), scale: (0.01, 0.0025, 0.005))",
            0.05,
        ),
        (
            "(translation: (30000, 2, -20000), rotation_degrees: (10, 30, 5), scale: (20, 0.05, 3))",
            25.0,
        ),
        (
            "(translation: (3000, 0.2, -2000), rotation_degrees: (3, 17, 2), scale: (0.5, 0.005, 2))",
            3.0,
        ),
    ] {
        let text = format!(
            r#"(
                camera: (position: (0, 10, 10), target: (0, 0, 0)),
                lights: [Directional(direction: (0.2, -1, 0.1))],
                objects: [(mesh: Box(size: (1, 1, 1)), instances: [{placement}])],
            )"#
        );
        let scene = Scene::from_ron(&text, Path::new("far.ron"), Path::new(".")).unwrap();
        let (occluders, surfaces) = (Occluders::new(&scene), Surfaces::new(&scene));
        let (lo, hi) = scene.bounds();
        let centre = (lo + hi) * 0.5;
        let to_light = -Vec3::new(0.2, -1.0, 0.1).normalize();
        let mut rng = Rng(3);
        let (mut lit_faces, mut shadowed) = (0, 0);
        for _ in 0..4000 {
            // Eyes above the instance, looking at random points of its box.
            let eye = centre + Vec3::new(rng.unit() - 0.5, 1.0, rng.unit() - 0.5) * eye_offset;
            let target = lo + (hi - lo) * Vec3::new(rng.unit(), rng.unit(), rng.unit());
            let Some(hit) = surfaces.closest(eye, (target - eye).normalize()) else {
                continue;
            };
            if hit.point.geometric_normal.dot(to_light) <= 0.05 {
                continue;
            }
            lit_faces += 1;
            if occluders.occluded(hit.point.ray_origin(), to_light, f32::INFINITY) {
                shadowed += 1;
            }
        }
        eprintln!("{placement}: {shadowed} of {lit_faces} points on lit faces shadowed");
        assert!(lit_faces > 500, "{lit_faces}");
        assert_eq!(shadowed, 0, "{placement}");
    }
}
