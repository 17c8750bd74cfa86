//! Hard ray-traced shadows of cards cut by fine alpha masks agree with the judge's: masks of
//! one-texel lines, texel-scale checkerboards and thresholded noise, at 64², 257² (not a power
//! of two: resampled to the scene's layer size) and 1024², under point, spot and directional
//! lights from 0.5 m to 3 m above the cards.

use std::path::Path;

use zoo_host::glam::UVec2;
use zoo_host::image::{GrayImage, Luma};
use zoo_host::judging::{SceneReference, judge_technique};
use zoo_host::params::{ParamValue, ParamValues, defaults};
use zoo_host::test_support::gpu;
use zoo_host::{Renderer, Scene};

const SIZE: UVec2 = UVec2::new(160, 128);

/// A small deterministic generator (an LCG's high bits).
fn noise(seed: u64) -> impl FnMut() -> u32 {
    let mut state = seed;
    move || {
        state = (state.wrapping_mul(6364136223846793005)).wrapping_add(1442695040888963407);
        (state >> 33) as u32
    }
}

/// The three masks at `side`²: one-texel lines (every seventh column and every fifth row), a
/// checkerboard of single texels, and noise covering about one texel in six.
fn masks(side: u32) -> [(&'static str, GrayImage); 3] {
    let covered = |on: bool| Luma([if on { 255 } else { 0 }]);
    let lines = GrayImage::from_fn(side, side, |x, y| covered(x % 7 == 3 || y % 5 == 1));
    let checker = GrayImage::from_fn(side, side, |x, y| covered((x + y).is_multiple_of(2)));
    let mut next = noise(u64::from(side));
    let speckled = GrayImage::from_fn(side, side, |_, _| covered(next().is_multiple_of(6)));
    [("lines", lines), ("checker", checker), ("noise", speckled)]
}

/// Three masked cards 0.5 m above a floor (flat, tilted, standing) under a point light and a
/// spot light `height` above them and a low sun; the masks are PNGs written to `dir`.
fn cards(dir: &Path, side: u32, height: f32) -> Scene {
    std::fs::create_dir_all(dir).unwrap();
    for (name, mask) in masks(side) {
        mask.save(dir.join(format!("{name}-{side}.png"))).unwrap();
    }
    let top = 0.5 + height;
    let text = format!(
        r#"(
        camera: (position: (0.4, 4.2, 3.6), target: (0, 0.2, 0), fov_y_degrees: 55),
        lights: [
            Point(position: (0.15, {top}, 0.1), range: 40),
            Spot(position: (-0.2, {top}, -0.15), direction: (0.05, -1, 0.1), range: 40, angle_degrees: 70),
            Directional(direction: (-0.4, -1, -0.3)),
        ],
        objects: [
            (mesh: Plane(size: 8)),
            (mesh: Plane(size: 1), alpha_mask: Some("lines-{side}.png"),
             transform: (translation: (-0.55, 0.5, 0.1), rotation_degrees: (0, 15, 0))),
            (mesh: Plane(size: 0.8), alpha_mask: Some("checker-{side}.png"),
             transform: (translation: (0.55, 0.55, -0.2), rotation_degrees: (25, -20, 0))),
            (mesh: Plane(size: 0.7), alpha_mask: Some("noise-{side}.png"),
             transform: (translation: (0.1, 0.5, 0.7), rotation_degrees: (70, 10, 0))),
        ],
    )"#
    );
    Scene::from_ron(&text, &dir.join("cards.ron"), dir).unwrap_or_else(|e| panic!("{e}"))
}

/// One ray to each light's centre: the core error against the judge's hard reference is at
/// most 0.0005 of each light's pixels for every mask size and light distance.
#[test]
fn hard_shadows_of_fine_masks_agree_with_the_judge() {
    let dir = std::env::temp_dir().join(format!("zoo-rt-fine-masks-{}", std::process::id()));
    let registration = zoo_host::find_technique("rt-shadows").unwrap();
    let mut values: ParamValues = defaults(&(registration.params)());
    values.insert("rays_per_pixel".into(), ParamValue::Int(1));
    let mut failures = Vec::new();
    for side in [64, 257, 1024] {
        for height in [0.5, 1.2, 3.0] {
            let scene = cards(&dir, side, height);
            let mut renderer = Renderer::new(gpu(), scene, SIZE).unwrap();
            let reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
            let judged = judge_technique(&mut renderer, &reference, "rt-shadows", &values).unwrap();
            for score in &judged.scores {
                let m = score.metrics.expect("every light kind is supported");
                let core = m.false_shadow_core + m.false_lit_core;
                eprintln!(
                    "{side}² masks, lights {height} m up, light {} ({}): core {:.5} (false lit {:.5}), all {:.5}",
                    score.light,
                    score.kind.name(),
                    core,
                    m.false_lit_core,
                    m.false_shadow + m.false_lit
                );
                if core > 0.0005 {
                    failures.push(format!(
                        "{side}² at {height} m, light {}: {m:?}",
                        score.light
                    ));
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failures.is_empty(), "{failures:#?}");
}
