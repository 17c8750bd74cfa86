//! The hybrid technique against the reference judge, with sv-zfail's bound, and its
//! classification against the reference's shadow boundaries.

// Link the plugin so its technique registers.
use zoo_plugin_hybrid_edge as _;

use zoo_host::glam::UVec2;
use zoo_host::judging::{DEFAULT_SAMPLES, SceneReference};
use zoo_host::params::{ParamValues, apply_assignments, defaults};
use zoo_host::test_support::{JudgeRun, Metric, gpu, judge, judge_scene, scene_path};
use zoo_host::wgpu::Features;
use zoo_host::{Renderer, Scene, View};

const CLIP_DISTANCES: Features = Features::CLIP_DISTANCES;

const SIZE: UVec2 = UVec2::new(256, 256);

fn assert_volume_bounds(run: &JudgeRun) {
    run.assert_every_light(&[
        (Metric::FalseShadowCore, 0.001),
        (Metric::FalseLitCore, 0.001),
    ]);
}

const SCENES: [&str; 4] = [
    "planar-room.ron",
    "curved.ron",
    "inside-shadow.ron",
    "dense.ron",
];

#[test]
fn exact_edge_tests_hold_the_shadow_volume_bound() {
    for scene in SCENES {
        assert_volume_bounds(&judge(
            scene,
            "hybrid-edge",
            &[("restriction", "TriangleIds")],
            SIZE,
        ));
    }
}

#[test]
fn banded_shadow_volumes_hold_the_shadow_volume_bound() {
    for scene in SCENES {
        assert_volume_bounds(&judge(
            scene,
            "hybrid-edge",
            &[("restriction", "DepthBand")],
            SIZE,
        ));
    }
}

/// Seed 003's own restriction: the band marked in the stencil and the volumes counted where
/// the stencil test finds the mark, the camera inside a volume included.
#[test]
fn stencil_marked_shadow_volumes_hold_the_shadow_volume_bound() {
    for scene in ["planar-room.ron", "inside-shadow.ron", "curved.ron"] {
        assert_volume_bounds(&judge(
            scene,
            "hybrid-edge",
            &[("restriction", "Stencil")],
            SIZE,
        ));
    }
}

/// Whether the test device clips by clip distances, which the `Tiles` restriction needs (a
/// skip is printed where it does not).
fn has_clip_distances() -> bool {
    let has = gpu().device.features().contains(CLIP_DISTANCES);
    if !has {
        eprintln!("SKIPPED (Tiles): this device has no CLIP_DISTANCES");
    }
    has
}

#[test]
fn everywhere_and_tiled_shadow_volumes_hold_the_shadow_volume_bound() {
    // Volumes everywhere through the same passes: plain shadow volumes.
    let everywhere = [("restriction", "Everywhere")];
    assert_volume_bounds(&judge("planar-room.ron", "hybrid-edge", &everywhere, SIZE));
    if !has_clip_distances() {
        return;
    }
    // A tile size that is not a multiple of the list pass's 8 x 8 steps is rounded up.
    let odd = [("restriction", "Tiles"), ("tile_size", "20")];
    assert_volume_bounds(&judge("curved.ron", "hybrid-edge", &odd, SIZE));
}

/// The `Tiles` restriction at its default tile size on every scene the other restrictions are
/// judged on, thin casters included.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn tiled_shadow_volumes_hold_the_shadow_volume_bound_everywhere() {
    if !has_clip_distances() {
        return;
    }
    let tiles = [("restriction", "Tiles")];
    for scene in SCENES {
        assert_volume_bounds(&judge(scene, "hybrid-edge", &tiles, SIZE));
    }
    for (scene, assignments) in THINNER_THAN_A_TEXEL {
        let with = [assignments, &tiles[..]].concat();
        assert_volume_bounds(&judge(scene, "hybrid-edge", &with, SIZE));
    }
}

fn values(assignments: &[(&str, &str)]) -> ParamValues {
    let schema = (zoo_host::find_technique("hybrid-edge").unwrap().params)();
    let mut values = defaults(&schema);
    let assignments: Vec<(String, String)> = assignments
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    apply_assignments(&schema, &mut values, &assignments).unwrap();
    values
}

/// Classes in the classification view by colour (`hybrid-edge/band.wgsl`'s CLASS_*).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Class {
    Lit,
    Shadowed,
    Edge,
    Other,
}

fn class_of(p: [u8; 4]) -> Class {
    match p {
        [r, g, b, _] if r > 200 && g > 200 && b > 120 => Class::Lit,
        [r, g, _, _] if r > 200 && g < 100 => Class::Edge,
        [r, _, b, _] if r < 80 && b > 90 => Class::Shadowed,
        _ => Class::Other,
    }
}

#[test]
fn lit_and_shadowed_pixels_agree_with_the_reference_and_the_band_is_narrow() {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let size = UVec2::new(192, 192);
    for light in 0..scene.lights.len() {
        let mut renderer = Renderer::new(gpu(), scene.clone(), size).unwrap();
        let debug = light.to_string();
        let params = values(&[("debug_light", &debug), ("map_size", "1024")]);
        renderer.set_technique("hybrid-edge", &params).unwrap();
        let reference = SceneReference::compute(&mut renderer, DEFAULT_SAMPLES, |_| {}).unwrap();
        renderer
            .render(&View::Resource("classification".into()))
            .unwrap();
        let image = renderer.read_output();
        let hard = &reference.lights[light];
        let (w, h) = (size.x as usize, size.y as usize);
        let (mut counts, mut wrong) = ([0usize; 4], 0usize);
        for i in (0..w * h).filter(|&i| hard.contributing[i]) {
            let class = class_of(image.get_pixel((i % w) as u32, (i / w) as u32).0);
            counts[class as usize] += 1;
            let lit = hard.hard[i] >= 0.5;
            wrong +=
                usize::from((class == Class::Lit && !lit) || (class == Class::Shadowed && lit));
        }
        let total: usize = counts.iter().sum();
        eprintln!(
            "light {light}: lit {}, shadowed {}, edge {}, other {}; decided wrongly {wrong}",
            counts[0], counts[1], counts[2], counts[3]
        );
        assert_eq!(counts[3], 0, "light {light}: unclassified lit pixels");
        assert!(
            counts[1] > 0 && counts[2] > 0,
            "light {light} casts shadows in view"
        );
        // The map decides: its lit and shadowed pixels agree with the rays...
        assert!(
            (wrong as f64) <= 0.001 * total as f64,
            "light {light}: {wrong} decided wrongly"
        );
        // ...and leaves little to the exact pass.
        assert!(
            (counts[2] as f64) < 0.1 * total as f64,
            "light {light}: the band is not narrow"
        );
    }
}

/// Scenes whose casters are thinner than a shadow-map texel where they shadow: kilometre-scale
/// views with near detail (`kilometre`, `vista`, `power-lines`) and `thin-casters` with
/// 512² maps.
const THINNER_THAN_A_TEXEL: [(&str, &[(&str, &str)]); 4] = [
    ("kilometre.ron", &[]),
    ("vista.ron", &[]),
    ("power-lines.ron", &[]),
    ("thin-casters.ron", &[("map_size", "512")]),
];

/// The fraction of pixels in the edge band of the debug light (light 0) in the classification
/// view.
fn band_fraction(scene: &str, assignments: &[(&str, &str)]) -> f64 {
    let scene = Scene::load(&scene_path(scene)).unwrap();
    let mut renderer = Renderer::new(gpu(), scene, SIZE).unwrap();
    renderer
        .set_technique("hybrid-edge", &values(assignments))
        .unwrap();
    renderer
        .render(&View::Resource("classification".into()))
        .unwrap();
    let image = renderer.read_output();
    let edge = (image.pixels()).filter(|p| class_of(p.0) == Class::Edge);
    edge.count() as f64 / f64::from(SIZE.x * SIZE.y)
}

#[test]
fn casters_thinner_than_a_texel_keep_the_volume_bound_that_the_map_alone_misses() {
    let mut missed_without = Vec::new();
    for (scene, assignments) in THINNER_THAN_A_TEXEL {
        // (Tiles: the long check `tiled_shadow_volumes_hold_the_shadow_volume_bound_everywhere`.)
        let with = [assignments, &[("restriction", "DepthBand")]].concat();
        assert_volume_bounds(&judge(scene, "hybrid-edge", &with, SIZE));
        // Without the coverage maps, the map's samples miss the thin casters.
        let without = [assignments, &[("coverage", "false")]].concat();
        let run = judge(scene, "hybrid-edge", &without, SIZE);
        let worst = (0..run.loaded.lights.len())
            .map(|light| run.metrics(light).false_lit_core)
            .fold(0.0, f64::max);
        eprintln!("{scene}: false_lit_core without coverage {worst:.4}");
        if worst > 0.001 {
            missed_without.push(scene);
        }
    }
    // The scenes are of the class: on the kilometre-scale ones the map alone misses shadows.
    assert_eq!(
        missed_without,
        ["kilometre.ron", "vista.ron", "power-lines.ron"]
    );
}

/// The coverage maps send the pixels of casters thinner than a texel to the edge band: with
/// them, light 0's band is wider than without on every scene of the class.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn coverage_maps_widen_the_band_where_casters_are_thinner_than_a_texel() {
    for (scene, assignments) in THINNER_THAN_A_TEXEL {
        let without = [assignments, &[("coverage", "false")]].concat();
        let (band, band_without) = (
            band_fraction(scene, assignments),
            band_fraction(scene, &without),
        );
        eprintln!("{scene}: light 0's band {band:.4} of pixels ({band_without:.4} without)");
        assert!(band > band_without, "{scene}: {band} <= {band_without}");
    }
}

/// Closed casters thinner than a texel (posts 3 cm wide, spheres 5 cm across, under texels of
/// about 16 cm: 256² maps over a 40 m floor and from a lamp 20 m up), the lamp inside the box
/// of a closed torus around it, and a sun: the coverage maps draw only the faces of closed
/// casters turned to a light outside their box, and still send every pixel whose ray crosses
/// one to the exact pass.
const CLOSED_THIN_CASTERS: &str = r#"(
    name: "closed-thin-casters",
    camera: (position: (0.4, 1.6, 2.6), target: (0, 0.1, 0), fov_y_degrees: 50),
    lights: [
        Point(position: (0.8, 20, 0.5), intensity: 600, range: 60),
        Directional(direction: (-0.5, -1, -0.35), intensity: 1),
    ],
    objects: [
        (mesh: Plane(size: 40), receiver: true),
        (mesh: Torus(major_radius: 0.6, minor_radius: 0.08, segments: 24, rings: 8),
         transform: (translation: (0.8, 20, 0.5))),
        (
            mesh: Box(size: (0.03, 0.4, 0.03)),
            transform: (translation: (0, 0.5, 0)),
            instances: [
            (translation: (-1.10, 0.0, -1.00)), (translation: (-1.10, 0.1, -0.50)),
            (translation: (-1.10, 0.2, 0.00)), (translation: (-1.10, 0.0, 0.50)),
            (translation: (-1.10, 0.1, 1.00)), (translation: (-0.55, 0.2, -1.00)),
            (translation: (-0.55, 0.0, -0.50)), (translation: (-0.55, 0.1, 0.00)),
            (translation: (-0.55, 0.2, 0.50)), (translation: (-0.55, 0.0, 1.00)),
            (translation: (0.00, 0.1, -1.00)), (translation: (0.00, 0.2, -0.50)),
            (translation: (0.00, 0.0, 0.00)), (translation: (0.00, 0.1, 0.50)),
            (translation: (0.00, 0.2, 1.00)), (translation: (0.55, 0.0, -1.00)),
            (translation: (0.55, 0.1, -0.50)), (translation: (0.55, 0.2, 0.00)),
            (translation: (0.55, 0.0, 0.50)), (translation: (0.55, 0.1, 1.00)),
            (translation: (1.10, 0.2, -1.00)), (translation: (1.10, 0.0, -0.50)),
            (translation: (1.10, 0.1, 0.00)), (translation: (1.10, 0.2, 0.50)),
            (translation: (1.10, 0.0, 1.00)),
            ],
        ),
        (
            mesh: Sphere(radius: 0.025, segments: 8, rings: 4),
            instances: [
            (translation: (-0.83, 0.3, -0.75)), (translation: (-0.83, 0.4, -0.25)),
            (translation: (-0.83, 0.5, 0.25)), (translation: (-0.83, 0.6, 0.75)),
            (translation: (-0.28, 0.3, -0.75)), (translation: (-0.28, 0.4, -0.25)),
            (translation: (-0.28, 0.5, 0.25)), (translation: (-0.28, 0.6, 0.75)),
            (translation: (0.27, 0.3, -0.75)), (translation: (0.27, 0.4, -0.25)),
            (translation: (0.27, 0.5, 0.25)), (translation: (0.27, 0.6, 0.75)),
            (translation: (0.82, 0.3, -0.75)), (translation: (0.82, 0.4, -0.25)),
            (translation: (0.82, 0.5, 0.25)), (translation: (0.82, 0.6, 0.75)),
            ],
        ),
    ],
)"#;

#[test]
fn closed_casters_thinner_than_a_texel_are_caught_by_their_faces_towards_the_light() {
    let scene = zoo_host::test_support::scene_from_ron("closed-thin-casters", CLOSED_THIN_CASTERS);
    let small_maps = [("map_size", "256"), ("restriction", "DepthBand")];
    let with = judge_scene(scene.clone(), "hybrid-edge", &small_maps, SIZE);
    let without = [small_maps[0], ("coverage", "false")];
    let without = judge_scene(scene, "hybrid-edge", &without, SIZE);
    for light in 0..with.loaded.lights.len() {
        let (m, missed) = (with.metrics(light), without.metrics(light).false_lit_core);
        eprintln!("light {light}: {m:?}; without coverage, false lit core {missed:.5}");
        // The scene is of the class: the map's samples alone miss some of the shadows...
        assert!(
            missed > 0.0002,
            "light {light}: without coverage, false lit {missed}"
        );
        // ...which the coverage maps send to the exact pass, every one.
        let core = m.false_lit_core + m.false_shadow_core;
        assert!(
            core < 0.00002,
            "light {light}: core error {core} with coverage"
        );
    }
}
