//! The moment family against the reference judge, with vsm's bounds on planar-room (point,
//! spot and sun) and curved. Their light bleeding beside VSM is measured in the workspace's
//! `tests/zoo/filtered_shadow_maps.rs`, which links every plugin.

// Link the plugin so its techniques register.
use zoo_plugin_moments as _;

use zoo_host::glam::UVec2;
use zoo_host::test_support::{gpu, gpu_without, judge, judge_scene_on, scene_path};

const SIZE: UVec2 = UVec2::new(256, 256);
const METHODS: [&str; 4] = ["esm", "evsm2", "evsm4", "msm"];

#[test]
fn planar_room_within_bounds_with_2048_maps() {
    for method in METHODS {
        judge("planar-room.ron", method, &[("map_size", "2048")], SIZE)
            .assert_core_bounds(0.005, 0.01);
    }
}

#[test]
fn curved_within_bounds_with_2048_maps() {
    for method in METHODS {
        judge("curved.ron", method, &[("map_size", "2048")], SIZE).assert_core_bounds(0.005, 0.01);
    }
}

/// Bytes of the moments texture `technique` allocates on `gpu` for planar-room.
fn map_bytes(gpu: std::sync::Arc<zoo_host::GpuContext>, technique: &str) -> u64 {
    let scene = zoo_host::Scene::load(&scene_path("planar-room.ron")).unwrap();
    let mut renderer = zoo_host::Renderer::new(gpu, scene, UVec2::new(64, 64)).unwrap();
    let registration = zoo_host::find_technique(technique).unwrap();
    let values = zoo_host::params::defaults(&(registration.params)());
    renderer.set_technique(technique, &values).unwrap();
    renderer.render(&zoo_host::View::Final).unwrap();
    let resources = renderer.technique_instance().resources();
    let moments = resources.iter().find(|r| r.name == "moments");
    moments.expect("a moments texture").bytes
}

/// Where the device cannot filter 32-bit floats (WebGPU without `float32-filterable`, GL),
/// every method falls back to 16-bit maps: half the memory, exponents clamped to 5.5 and
/// larger biases, judged on planar-room. EVSM and MSM keep the core bounds; ESM cannot: with
/// exp(5.5 (z - 1)) its test is soft over the whole depth range, and light leaks under every
/// contact (measured false_lit_core 0.035 and 0.047 for the point and spot lights, against
/// at most 0.002 with 32-bit maps and exponent 40), so it gets its measured bound.
#[test]
fn sixteen_bit_fallback_halves_the_maps_and_stays_within_bounds() {
    let filterable = zoo_host::wgpu::Features::FLOAT32_FILTERABLE;
    if !gpu().device.features().contains(filterable) {
        eprintln!("skipped: this adapter has no 32-bit filtering, so every run falls back");
        return;
    }
    let restricted = gpu_without(filterable);
    assert!(!restricted.device.features().contains(filterable));
    let mut runs = Vec::new();
    // One method per format (two and four channels); EVSM2 and EVSM4 measured the same as
    // MSM here (false_lit_core at most 5e-5).
    for method in ["esm", "msm"] {
        let (full, half) = (
            map_bytes(gpu(), method),
            map_bytes(restricted.clone(), method),
        );
        assert!(full > 0, "{method} allocates maps");
        assert_eq!(2 * half, full, "{method}: 16-bit maps take half the bytes");
        let scene = zoo_host::Scene::load(&scene_path("planar-room.ron")).unwrap();
        let run = judge_scene_on(
            restricted.clone(),
            scene,
            method,
            &[("map_size", "2048")],
            SIZE,
        );
        for light in 0..3 {
            eprintln!("{method} 16-bit light {light}: {:?}", run.metrics(light));
        }
        runs.push((method, run));
    }
    for (method, run) in &runs {
        match *method {
            "esm" => run.assert_core_bounds(0.005, 0.05),
            _ => run.assert_core_bounds(0.005, 0.01),
        }
    }
}
