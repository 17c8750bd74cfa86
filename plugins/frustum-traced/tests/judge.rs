//! Frustum-traced shadows against the reference judge: exact hard shadows on every standard
//! scene (masked casters included), and the same pixels at any grid size. (Its agreement with
//! rt-shadows is `tests/zoo/exact_methods.rs`'.)

// Link the plugin so its technique registers.
use zoo_plugin_frustum_traced as _;

use zoo_host::glam::UVec2;
use zoo_host::params::{apply_assignments, defaults};
use zoo_host::test_support::{counter, gpu, judge, scene_path, standard_scenes};
use zoo_host::{Renderer, Scene, View};

const SIZE: UVec2 = UVec2::new(128, 128);
const ID: &str = "frustum-traced";

/// Most of a light's pixels off its shadow edges that may be judged wrongly (false shadow and
/// false lit together).
const CORE_BOUND: f64 = 0.0005;

/// Core error at most [`CORE_BOUND`] for every light of `foliage` (alpha masks, the sun and a
/// spot light) and `planar-room` (a point light beside walls, whose triangles pass beside it
/// across cube faces) at 128x128.
#[test]
fn masks_and_cube_faces_are_exact() {
    for scene in ["foliage.ron", "planar-room.ron"] {
        judge(scene, ID, &[], SIZE).assert_core_error(CORE_BOUND);
    }
}

/// Core error at most [`CORE_BOUND`] for every light of every standard scene at 128x128:
/// curved receivers, thin and masked casters, instances, lamps near walls, 64 lights, a
/// quarter of a million triangles, the kilometre scale.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn every_standard_scene_is_exact() {
    for path in standard_scenes() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        judge(&name, ID, &[], SIZE).assert_core_error(CORE_BOUND);
    }
}

/// Every light's visibility in `scene` at 64x64 with parameters `set`, and the longest list.
fn frame(scene: &str, set: &[(&str, &str)]) -> (Vec<Vec<f32>>, f64) {
    let scene = Scene::load(&scene_path(scene)).unwrap();
    let lights = scene.lights.len();
    let mut renderer = Renderer::new(gpu(), scene, UVec2::splat(64)).unwrap();
    let schema = (zoo_host::find_technique(ID).unwrap().params)();
    let mut values = defaults(&schema);
    let assignments: Vec<_> = (set.iter())
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    apply_assignments(&schema, &mut values, &assignments).unwrap();
    renderer.set_technique(ID, &values).unwrap();
    renderer.render(&View::Final).unwrap();
    // The counters arrive a frame or two late.
    let longest = (0..8).find_map(|_| {
        renderer.gpu().wait_idle();
        let counters = renderer.technique_instance().counters();
        counter(&counters, "longest list")
    });
    let visibility = (0..lights).map(|l| renderer.read_visibility(l)).collect();
    (visibility, longest.expect("the counters arrive"))
}

/// The grid's size changes how samples are listed, never which are shadowed: the coarsest and
/// a fine grid give the same pixels on a scene with instances (corners carried to world space)
/// and every light kind, the coarse one with longer lists.
#[test]
fn the_grid_size_changes_no_pixel() {
    let (coarse, coarse_longest) = frame("forest.ron", &[("grid", "16")]);
    let (fine, fine_longest) = frame("forest.ron", &[("grid", "512")]);
    for (light, (a, b)) in coarse.iter().zip(&fine).enumerate() {
        assert!(
            a == b,
            "forest light {light}: the grid's size changed pixels"
        );
    }
    eprintln!("longest list: {coarse_longest} at 16x16, {fine_longest} at 512x512");
    assert!(fine_longest > 0.0 && fine_longest < coarse_longest);
}

/// The raster path (each triangle drawn conservatively into the grid, each fragment walking
/// its texel's list) shadows exactly the pixels the compute path does, on `forest` (instances,
/// every light kind), `foliage` (masks) and `planar-room` (walls passing beside a point light,
/// drawn as their rectangles on the faces behind whose apex they reach).
#[test]
fn the_raster_path_shadows_the_same_pixels() {
    for scene in ["forest.ron", "foliage.ron", "planar-room.ron"] {
        let (compute, _) = frame(scene, &[]);
        let (raster, _) = frame(scene, &[("rasteriser", "Raster")]);
        for (light, (a, b)) in compute.iter().zip(&raster).enumerate() {
            let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
            assert_eq!(
                differ, 0,
                "{scene} light {light}: pixels the raster path changed"
            );
        }
    }
}
