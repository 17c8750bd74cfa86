//! Alpha-masked casters are judged exactly: a shadow ray passes through a mask's holes.

use std::path::Path;

use glam::Vec3;
use zoo_judge::Occluders;
use zoo_scene::Scene;

/// A scene with a 2 m square plate 1 m above the origin, masked by `mask.png` in `dir`.
fn masked_plate(dir: &Path, mask: &image::GrayImage, cutoff: f32) -> Scene {
    std::fs::create_dir_all(dir).unwrap();
    mask.save(dir.join("mask.png")).unwrap();
    let text = format!(
        r#"(
        camera: (position: (0, 5, 5), target: (0, 0, 0)),
        lights: [Directional(direction: (0, -1, 0))],
        objects: [(
            mesh: Plane(size: 2),
            transform: (translation: (0, 1, 0)),
            alpha_mask: Some("mask.png"),
            alpha_cutoff: {cutoff},
        )],
    )"#
    );
    Scene::from_ron(&text, &dir.join("masked.ron"), dir).unwrap_or_else(|e| panic!("{e}"))
}

/// The fraction of a 293² grid of points under the plate whose ray straight up is blocked (a
/// prime count, so that no point lies on a cell's edge).
fn shadowed_fraction(occluders: &Occluders) -> f64 {
    let n = 293;
    let blocked = (0..n * n)
        .filter(|i| {
            let (x, z) = ((i % n) as f32, (i / n) as f32);
            let p = Vec3::new(
                -1.0 + 2.0 * (x + 0.5) / n as f32,
                0.0,
                -1.0 + 2.0 * (z + 0.5) / n as f32,
            );
            occluders.occluded(p, Vec3::Y, f32::INFINITY)
        })
        .count();
    blocked as f64 / (n * n) as f64
}

#[test]
fn the_shadow_of_a_checkerboard_mask_covers_what_the_mask_covers() {
    let dir = std::env::temp_dir().join(format!("zoo-judge-masks-{}", std::process::id()));
    // 8-texel cells: every other cell (half), and one cell in four (a quarter).
    let checker = image::GrayImage::from_fn(64, 64, |x, y| {
        image::Luma([if (x / 8 + y / 8) % 2 == 0 { 255 } else { 0 }])
    });
    let quarter = image::GrayImage::from_fn(64, 64, |x, y| {
        image::Luma([if (x / 8) % 2 == 0 && (y / 8) % 2 == 0 {
            255
        } else {
            0
        }])
    });
    for (mask, coverage) in [(&checker, 0.5), (&quarter, 0.25)] {
        let scene = masked_plate(&dir, mask, 0.5);
        assert!(scene.objects[0].alpha_mask.is_some());
        let fraction = shadowed_fraction(&Occluders::new(&scene));
        assert!(
            (fraction - coverage).abs() <= 0.005,
            "shadowed {fraction}, the mask covers {coverage}"
        );
    }
    // A cutoff above every texel's alpha makes the plate a hole; a cutoff of 0 makes it block
    // as the same plate unmasked does.
    let scene = masked_plate(&dir, &checker, 1.0);
    let all_holes = {
        let mut s = scene.clone();
        s.objects[0].alpha_mask.as_mut().unwrap().cutoff = 1.01;
        s
    };
    assert_eq!(shadowed_fraction(&Occluders::new(&all_holes)), 0.0);
    let mut whole = scene.clone();
    whole.objects[0].alpha_mask.as_mut().unwrap().cutoff = 0.0;
    let mut unmasked = scene;
    unmasked.objects[0].alpha_mask = None;
    let opaque = shadowed_fraction(&Occluders::new(&unmasked));
    assert!(opaque > 0.999, "{opaque}");
    assert_eq!(shadowed_fraction(&Occluders::new(&whole)), opaque);
    std::fs::remove_dir_all(&dir).unwrap();
}
