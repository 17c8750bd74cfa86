//! Alpha-tested casters: the foliage scene's generated textures, its masks in the G-buffer and
//! the shadow-map depth passes, and every technique judged on it.

use std::path::PathBuf;

use glam::UVec2;
use zoo_host::test_support::{judge, workspace_root};

/// Texels a side of the generated textures.
const SIDE: u32 = 128;

/// The scene's generated textures: (file under `scenes/textures/`, image).
fn generated() -> Vec<(&'static str, image::RgbaImage)> {
    let unit = |v: u32| (v as f32 + 0.5) / SIDE as f32;
    // Five vertical planks, 0.12 of the width each, with gaps between them.
    let fence = image::RgbaImage::from_fn(SIDE, SIDE, |x, _| {
        let plank = (unit(x) * 5.0).fract() < 0.6;
        let grain = 150 + (x * 7 % 23) as u8;
        image::Rgba([
            grain,
            (grain as f32 * 0.75) as u8,
            90,
            if plank { 255 } else { 0 },
        ])
    });
    // Diagonal wires 0.12 of a cell wide on a diamond lattice of 8 cells a side.
    let chain = image::RgbaImage::from_fn(SIDE, SIDE, |x, y| {
        let (u, v) = (unit(x) * 8.0, unit(y) * 8.0);
        let wire = |t: f32| (t - t.round()).abs() < 0.06;
        let on = wire((u + v) * 0.5) || wire((u - v) * 0.5);
        image::Rgba([170, 175, 180, if on { 255 } else { 0 }])
    });
    // A leaf: an ellipse pointed along its axis, with a vein.
    let leaf = image::RgbaImage::from_fn(SIDE, SIDE, |x, y| {
        let (u, v) = (unit(x) * 2.0 - 1.0, unit(y) * 2.0 - 1.0);
        let width = 0.55 * (1.0 - v * v).max(0.0).sqrt() * (1.0 - 0.35 * v);
        let inside = u.abs() < width;
        let vein = u.abs() < 0.03;
        let green = if vein { 150 } else { 110 + (y % 9) as u8 * 4 };
        image::Rgba([40, green, 35, if inside { 255 } else { 0 }])
    });
    vec![
        ("fence.png", fence),
        ("chain-link.png", chain),
        ("leaf.png", leaf),
    ]
}

fn texture_path(file: &str) -> PathBuf {
    workspace_root().join("scenes/textures").join(file)
}

/// The committed textures are what the generator makes; `UPDATE_SCENE_TEXTURES=1` rewrites
/// them.
#[test]
fn the_foliage_textures_are_generated() {
    for (file, image) in generated() {
        let path = texture_path(file);
        if std::env::var_os("UPDATE_SCENE_TEXTURES").is_some() {
            image.save(&path).unwrap();
            continue;
        }
        let committed = image::open(&path)
            .unwrap_or_else(|e| {
                panic!(
                    "{}: {e}; regenerate with UPDATE_SCENE_TEXTURES=1",
                    path.display()
                )
            })
            .to_rgba8();
        assert!(
            committed == image,
            "{} differs from its generator; regenerate with UPDATE_SCENE_TEXTURES=1",
            path.display()
        );
    }
}

/// The masks are holes in the G-buffer: through the fence's gaps the ground shows.
#[test]
fn masked_surfaces_have_holes_where_their_masks_do() {
    let scene = zoo_host::Scene::load(&zoo_host::test_support::scene_path("foliage.ron")).unwrap();
    let masked = scene
        .objects
        .iter()
        .filter(|o| o.alpha_mask.is_some())
        .count();
    assert!(masked >= 10, "{masked} masked objects");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let fence = zoo_host::test_support::scene_from_ron(
        "fence.ron",
        r#"(camera: (position: (0, 1, 4), target: (0, 1, 0), fov_y_degrees: 40),
        lights: [Directional(direction: (0, -1, -0.5))],
        objects: [
            (name: "ground", mesh: Plane(size: 40), transform: (translation: (0, 0, -2), rotation_degrees: (90, 0, 0))),
            (name: "fence", mesh: Plane(size: 2), alpha_mask: Some("textures/fence.png"),
             texture: Some("textures/fence.png"), transform: (translation: (0, 1, 0), rotation_degrees: (90, 0, 0))),
        ])"#,
    );
    let size = UVec2::new(128, 128);
    let mut renderer = zoo_host::Renderer::new(zoo_host::test_support::gpu(), fence, size).unwrap();
    renderer.render(&zoo_host::View::Final).unwrap();
    let gbuffer = renderer.read_gbuffer();
    // Along the middle row the fence (z = 0) covers 60 % of its width, and the ground (a wall
    // at z = -2) shows through the gaps.
    let row = size.y as usize / 2;
    let depths: Vec<f32> = (0..size.x as usize)
        .map(|x| gbuffer.positions[row * size.x as usize + x])
        // Where the ray through the pixel crosses the fence's plane (the camera is 4 m from it
        // and 6 m from the wall).
        .filter(|p| p.w > 0.0 && (p.x * 4.0 / (4.0 - p.z)).abs() < 0.95)
        .map(|p| p.z)
        .collect();
    let on_fence = depths.iter().filter(|z| z.abs() < 0.05).count();
    let on_ground = depths.iter().filter(|z| (**z + 2.0).abs() < 0.05).count();
    assert_eq!(on_fence + on_ground, depths.len(), "{depths:?}");
    let share = on_fence as f64 / depths.len() as f64;
    eprintln!("fence covers {share:.3} of the row");
    assert!((0.5..0.7).contains(&share), "fence share {share}");
}

/// Shadow maps with and without filtered moments keep the core error bound on the foliage
/// scene, where treating the masks as opaque shadows half of the lit ground.
#[test]
fn shadow_maps_test_alpha_on_the_foliage_scene() {
    for technique in ["sm-pcf", "vsm"] {
        let run = judge("foliage.ron", technique, &[], UVec2::new(192, 144));
        let judged = run.judged.scores.iter().filter(|s| s.metrics.is_some());
        assert_eq!(judged.count(), 2, "{technique} judges both lights");
        for score in &run.judged.scores {
            let Some(m) = score.metrics else { continue };
            eprintln!(
                "{technique} light {}: core {:.4}/{:.4} mae {:.4}",
                score.light, m.false_shadow_core, m.false_lit_core, m.mae
            );
            assert!(
                m.false_shadow_core + m.false_lit_core <= 0.01,
                "{technique} light {}: {m:?}",
                score.light
            );
        }
    }
}
