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

/// The one-bounce reference sees surfaces as the G-buffer draws them: a ray through a mask's
/// hole reaches what lies behind, and a textured surface reflects its colour times the
/// texture's (decoded from sRGB, bilinear at full resolution).
#[test]
fn reflectors_are_textured_and_pass_rays_through_mask_holes() {
    let dir = std::env::temp_dir().join(format!("zoo-judge-reflectors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Left half covered, right half a hole; sRGB 188 is linear 0.5 (0.5029).
    image::RgbaImage::from_fn(8, 8, |x, _| {
        image::Rgba([188, 188, 188, if x < 4 { 255 } else { 0 }])
    })
    .save(dir.join("half.png"))
    .unwrap();
    let text = r#"(
        camera: (position: (0, 5, 5), target: (0, 0, 0)),
        lights: [Directional(direction: (0, -1, 0))],
        objects: [
            (mesh: Plane(size: 2), color: (0.8, 0.6, 0.4), transform: (translation: (0, 1, 0)),
             texture: Some("half.png"), alpha_mask: Some("half.png")),
            (mesh: Plane(size: 10), color: (0.2, 0.3, 0.4), transform: (translation: (0, 3, 0))),
        ],
    )"#;
    let scene = Scene::from_ron(text, &dir.join("reflectors.ron"), &dir).unwrap();
    let reflectors = zoo_judge::Reflectors::new(&scene);
    // Straight up from below the plate's covered half (x < 0): the plate, textured.
    let hit = reflectors
        .closest(Vec3::new(-0.5, 0.0, 0.2), Vec3::Y)
        .unwrap();
    assert!((hit.distance - 1.0).abs() < 1e-5, "{hit:?}");
    let expected = Vec3::new(0.8, 0.6, 0.4) * zoo_scene::shading::srgb_to_linear(188.0 / 255.0);
    assert!(hit.albedo.abs_diff_eq(expected, 1e-5), "{hit:?}");
    // Through the hole (x > 0): the plane above, untextured.
    let hit = reflectors
        .closest(Vec3::new(0.5, 0.0, 0.2), Vec3::Y)
        .unwrap();
    assert!((hit.distance - 3.0).abs() < 1e-5, "{hit:?}");
    assert_eq!(hit.albedo, Vec3::new(0.2, 0.3, 0.4));
    std::fs::remove_dir_all(&dir).unwrap();
}
