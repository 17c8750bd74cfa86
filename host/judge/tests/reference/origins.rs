//! Ray origins off surfaces at any scale: a surface point never shadows itself toward a light
//! in front of its triangle, always shadows itself toward a light behind it (the terminator
//! convention: exact visibility of the triangle mesh), and an occluder however close is found.

use glam::Vec3;
use zoo_judge::{Occluders, Surfaces};

use crate::Rng;

/// A random triangle of size about `size` around `centre`, not too thin.
fn triangle(rng: &mut Rng, centre: Vec3, size: f32) -> [Vec3; 3] {
    loop {
        let t = [0; 3].map(|_| centre + rng.direction() * size);
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        let longest = [t[1] - t[0], t[2] - t[1], t[0] - t[2]]
            .map(|e| e.length_squared())
            .into_iter()
            .fold(0.0, f32::max);
        if n.length() > 0.05 * longest {
            break t;
        }
    }
}

/// Whether the ray from `origin` along `d` crosses the plane of `tri` inside it with a margin
/// of 1 % of its barycentric range (computed in f64).
fn crosses_inside(tri: &[Vec3; 3], origin: Vec3, d: Vec3) -> bool {
    let [a, b, c] = tri.map(|v| v.as_dvec3());
    let (o, d) = (origin.as_dvec3(), d.as_dvec3());
    let (e1, e2) = (b - a, c - a);
    let n = e1.cross(e2);
    let t = n.dot(a - o) / n.dot(d);
    let p = o + d * t - a;
    // Barycentrics of p in the (e1, e2) frame.
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (p1, p2) = (p.dot(e1), p.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let u = (d22 * p1 - d12 * p2) / det;
    let v = (d11 * p2 - d12 * p1) / det;
    t > 0.0 && u > 0.01 && v > 0.01 && u + v < 0.99
}

/// Scene scales from a millimetre model to a continent, each with triangles far from the
/// world origin (coordinates up to 1e4 times the triangle's size).
const SCALES: [f32; 6] = [1e-3, 1e-1, 1.0, 1e2, 1e4, 1e6];

#[test]
fn a_surface_never_shadows_itself_toward_the_front_and_always_toward_the_back() {
    let mut rng = Rng(0x0f_f5e7);
    let (mut front, mut back) = (0, 0);
    let mut failures = Vec::new();
    for scale in SCALES {
        for _ in 0..300 {
            let far = rng.range(0.0, 1e4);
            let centre = rng.direction() * far * scale;
            let tri = triangle(&mut rng, centre, scale);
            let surfaces = Surfaces::from_triangles(vec![tri]);
            let occluders = Occluders::from_triangles(&[tri]);
            // A point well inside the triangle, seen from a random eye in front of it.
            let (b1, b2) = (rng.range(0.1, 0.45), rng.range(0.1, 0.45));
            let target = tri[0] + b1 * (tri[1] - tri[0]) + b2 * (tri[2] - tri[0]);
            let eye = target + rng.direction() * rng.range(0.5, 20.0) * scale;
            let Some(hit) = surfaces.closest(eye, (target - eye).normalize()) else {
                failures.push(format!("scale {scale}: the eye ray missed"));
                continue;
            };
            let point = hit.point;
            let origin = point.ray_origin();
            for _ in 0..20 {
                let d = rng.direction();
                let cosine = d.dot(point.geometric_normal);
                if cosine.abs() < 0.05 {
                    continue;
                }
                let occluded = occluders.occluded(origin, d, f32::INFINITY);
                if cosine > 0.0 {
                    front += 1;
                    if occluded {
                        failures.push(format!("scale {scale}: self-shadow toward {d}"));
                    }
                } else if crosses_inside(&tri, origin, d) {
                    back += 1;
                    if !occluded {
                        failures.push(format!("scale {scale}: light behind {d} leaks"));
                    }
                }
            }
        }
    }
    assert!(
        front > 10_000 && back > 10_000,
        "{front} front, {back} back"
    );
    assert!(
        failures.is_empty(),
        "{} failures, first: {:?}",
        failures.len(),
        &failures[..failures.len().min(5)]
    );
}

#[test]
fn an_occluder_a_hundred_thousandth_of_the_coordinates_away_is_found_at_every_scale() {
    for scale in SCALES {
        // A floor far from the origin and a plate just above it: the gap is 1e-5 of the
        // coordinates' magnitude, far above their rounding (6e-8) and far below any fixed
        // fraction of a scene's size the judge used to cut off.
        let at = Vec3::new(3.0e3, 0.0, -2.0e3) * scale;
        let gap = 1e-5 * 3.0e3 * scale;
        let quad = |y: f32, half: f32| {
            let [a, b, c, d] = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(x, z)| at + Vec3::new(x * half, y, z * half));
            [[a, c, b], [a, d, c]]
        };
        let floor = quad(0.0, 10.0 * scale);
        let plate = quad(gap, 1.0 * scale);
        let surfaces = Surfaces::from_triangles(floor.to_vec());
        let eye = at + Vec3::new(0.3, 5.0, 0.2) * scale;
        let hit = surfaces.closest(eye, (at - eye).normalize()).unwrap();
        assert!(
            hit.point.offset < 0.1 * gap,
            "scale {scale}: offset {} against a gap of {gap}",
            hit.point.offset
        );
        let origin = hit.point.ray_origin();
        let with_plate = Occluders::from_triangles(&[floor, plate].concat());
        let sun = Vec3::new(0.3, 1.0, 0.1).normalize();
        assert!(
            with_plate.occluded(origin, sun, f32::INFINITY),
            "scale {scale}"
        );
        let without = Occluders::from_triangles(&floor);
        assert!(
            !without.occluded(origin, sun, f32::INFINITY),
            "scale {scale}"
        );
    }
}

#[test]
fn a_closed_mesh_shadows_its_terminator_where_its_triangles_face_away() {
    // A coarse closed octahedron-like sphere: at points whose triangle faces away from the
    // light the reference is shadow (the light is behind the visible side), whatever the
    // shading normal says; at points whose triangle faces the light, lit.
    let mesh = zoo_scene::mesh::sphere(1.0, 12, 6);
    let triangles: Vec<[Vec3; 3]> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize] * 1000.0))
        .collect();
    let surfaces = Surfaces::from_triangles(triangles.clone());
    let occluders = Occluders::from_triangles(&triangles);
    let sun = Vec3::new(1.0, 0.2, 0.0).normalize();
    let eye = Vec3::new(0.0, 300.0, 5000.0);
    let mut rng = Rng(7);
    let (mut lit, mut shadowed) = (0, 0);
    for _ in 0..4000 {
        let target = rng.direction() * 1000.0;
        let Some(hit) = surfaces.closest(eye, (target - eye).normalize()) else {
            continue;
        };
        let faces_light = hit.point.geometric_normal.dot(sun);
        if faces_light.abs() < 1e-3 {
            continue;
        }
        let occluded = occluders.occluded(hit.point.ray_origin(), sun, f32::INFINITY);
        assert_eq!(occluded, faces_light < 0.0, "at {}", hit.point.position);
        if occluded {
            shadowed += 1;
        } else {
            lit += 1;
        }
    }
    assert!(
        lit > 300 && shadowed > 300,
        "{lit} lit, {shadowed} shadowed"
    );
}
