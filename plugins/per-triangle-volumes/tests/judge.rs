//! Per-triangle shadow volumes against the reference judge: exact hard shadows on every
//! standard scene (masked casters included), and a hierarchy that culls without changing a
//! pixel. (Its agreement with rt-shadows is `tests/zoo/exact_methods.rs`'.)

// Link the plugin so its technique registers.
use zoo_plugin_per_triangle_volumes as _;

use zoo_host::glam::UVec2;
use zoo_host::params::{apply_assignments, defaults};
use zoo_host::test_support::{counter, gpu, judge, scene_path, standard_scenes};
use zoo_host::{Renderer, Scene, View};

const SIZE: UVec2 = UVec2::new(128, 128);
const ID: &str = "per-triangle-volumes";

/// Most of a light's pixels off its shadow edges that may be judged wrongly (false shadow and
/// false lit together).
const CORE_BOUND: f64 = 0.0005;

/// Scenes the suite judges: alpha masks and contact (every standard scene, the kilometre scale
/// among them, is the long check's: `every_standard_scene_is_exact`; instances are the
/// suite's in `the_hierarchy_culls_without_changing_a_pixel` and `tests/zoo/exact_methods.rs`).
const SUITE_SCENES: [&str; 2] = ["foliage.ron", "contact.ron"];

/// Core error at most [`CORE_BOUND`] for every light of the [`SUITE_SCENES`] at 128x128.
#[test]
fn masks_and_contact_are_exact() {
    for scene in SUITE_SCENES {
        judge(scene, ID, &[], SIZE).assert_core_error(CORE_BOUND);
    }
}

/// Core error at most [`CORE_BOUND`] for every light of every standard scene at 128x128:
/// curved receivers, thin and masked casters, instances, lamps near walls, 64 lights, a
/// quarter of a million triangles, the kilometre scale (measured: at most 0.00033, the spot
/// light grazing `grazing-spot-facing`).
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn every_standard_scene_is_exact() {
    for path in standard_scenes() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        judge(&name, ID, &[], SIZE).assert_core_error(CORE_BOUND);
    }
}

/// Every light's visibility in `forest` at 64x64 (without the hierarchy every triangle tests
/// every sample), and the samples tested exactly, with the hierarchy on or off.
fn forest_frame(hierarchy: bool) -> (Vec<Vec<f32>>, f64) {
    let scene = Scene::load(&scene_path("forest.ron")).unwrap();
    let lights = scene.lights.len();
    let mut renderer = Renderer::new(gpu(), scene, UVec2::splat(64)).unwrap();
    let schema = (zoo_host::find_technique(ID).unwrap().params)();
    let mut values = defaults(&schema);
    let assignment = ("hierarchy".to_string(), hierarchy.to_string());
    apply_assignments(&schema, &mut values, &[assignment]).unwrap();
    renderer.set_technique(ID, &values).unwrap();
    renderer.render(&View::Final).unwrap();
    // The counters arrive a frame or two late.
    let tests = (0..8).find_map(|_| {
        renderer.gpu().wait_idle();
        let counters = renderer.technique_instance().counters();
        counter(&counters, "samples tested exactly")
    });
    let visibility = (0..lights).map(|l| renderer.read_visibility(l)).collect();
    (visibility, tests.expect("the counters arrive"))
}

/// Culling by the hierarchy leaves every pixel as testing every sample does, on a scene with
/// instances (planes carried from the mesh's space) and every light kind, and spares most
/// exact tests.
#[test]
fn the_hierarchy_culls_without_changing_a_pixel() {
    let (culled, culled_tests) = forest_frame(true);
    let (every, every_tests) = forest_frame(false);
    for (light, (a, b)) in culled.iter().zip(&every).enumerate() {
        assert!(a == b, "forest light {light}: culling changed pixels");
    }
    eprintln!("samples tested exactly: {culled_tests} culled, {every_tests} without culling");
    assert!(culled_tests > 0.0 && culled_tests * 4.0 < every_tests);
}
