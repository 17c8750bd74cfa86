//! Hundreds of lights: with over a thousand map passes sharing one frame's encoder, every light
//! keeps its own maps, cameras and per-light uniforms. Checked for sm-pcf (a lookup pass and
//! uniform slot per light) and ssss (one pass for all lights) against the hard reference of a
//! sample of lights across `lights-256`.

// Link the application, which links every plugin.
use shadow_zoo as _;
use zoo_host::glam::UVec2;
use zoo_host::judge::{Metrics, Occluders, Surfaces, reference_visibility};
use zoo_host::judging::surface_points;
use zoo_host::test_support::{gpu, scene_path};
use zoo_host::{Renderer, View};

#[test]
fn every_light_of_two_hundred_and_fifty_six_keeps_its_own_shadows() {
    let scene = zoo_host::Scene::load(&scene_path("lights-256.ron")).unwrap();
    let size = UVec2::new(320, 240);
    let mut renderer = Renderer::new(gpu(), scene.clone(), size).unwrap();
    // Each technique's second frame is counted: it renders every map again as the first did.
    renderer.set_reuse_unchanged(false);
    renderer.render(&View::Final).unwrap();
    let points = surface_points(&renderer.read_gbuffer(), &Surfaces::new(&scene));
    let occluders = Occluders::new(&scene);
    // Point and spot lights (140 and 170 are spots) across the middle of the plaza.
    let sample = [73usize, 85, 104, 140, 150, 170, 180, 199];
    let references: Vec<_> = sample
        .iter()
        .map(|&i| reference_visibility(&occluders, &scene.lights[i], &points, 1))
        .collect();
    for technique in ["sm-pcf", "ssss"] {
        renderer
            .set_technique(technique, &Default::default())
            .unwrap();
        renderer.render(&View::Final).unwrap();
        let timings = renderer.render(&View::Final).unwrap();
        assert!(
            timings.passes.len() > 1000,
            "{technique}: {} passes",
            timings.passes.len()
        );
        let mut shadowed = 0;
        for (k, &light) in sample.iter().enumerate() {
            let reference = &references[k];
            let v = renderer.read_visibility(light);
            let m = Metrics::compute(reference, &v, size.x as usize, size.y as usize, None);
            eprintln!(
                "{technique} light {light} ({}): {} pixels, {:.3} in shadow, core {:.4}/{:.4}",
                scene.lights[light].kind.name(),
                m.pixels,
                reference.shadowed_fraction(),
                m.false_shadow_core,
                m.false_lit_core
            );
            assert!(m.pixels > 150, "light {light} is in view");
            assert!(
                m.false_shadow_core <= 0.01 && m.false_lit_core <= 0.01,
                "{technique}: light {light} disagrees with its reference: {m:?}"
            );
            shadowed += usize::from(reference.shadowed_fraction() > 0.01);
        }
        assert!(
            shadowed >= sample.len() / 2,
            "the sampled lights cast shadows"
        );
    }
}

/// The scene format's limit: 1024 lights of every kind (767 cube maps, 256 spot maps, a sun),
/// far more map layers than a device has array layers. Every technique renders it on a device
/// with WebGPU's default limits (256 array layers, 8192² textures, 32 bytes of colour
/// attachments a sample, 4 bind groups) on the test adapter, or, where a technique declares it
/// needs more than those defaults, on the adapter's own limits (which give the same atlas: 64
/// pages at most). Small pages keep the test short on a software rasterizer: the tiles are
/// what is tested, not their size.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn a_thousand_and_twenty_four_lights_render_with_every_technique() {
    let scene = zoo_host::Scene::load(&scene_path("lights-1024.ron")).unwrap();
    assert_eq!(scene.lights.len(), 1024);
    // Small: the lights' maps and passes are the test, not the pixels.
    let size = UVec2::new(80, 60);
    let webgpu = zoo_host::test_support::gpu_with_webgpu_limits();
    let mut on_webgpu = Renderer::new(webgpu.clone(), scene.clone(), size).unwrap();
    let mut on_adapter = Renderer::new(gpu(), scene.clone(), size).unwrap();
    let mut on_defaults = 0;
    for registration in zoo_host::registry() {
        if registration.id.starts_with("test-") {
            continue;
        }
        let (renderer, limits) = match registration.unavailable_reason(&webgpu) {
            None => (&mut on_webgpu, "WebGPU default limits".to_string()),
            Some(why) => (&mut on_adapter, format!("adapter limits: {why}")),
        };
        on_defaults += usize::from(limits.starts_with("WebGPU"));
        let start = std::time::Instant::now();
        let values = zoo_host::test_support::cheapest_params(&(registration.params)());
        renderer
            .set_technique(registration.id, &values)
            .unwrap_or_else(|e| panic!("{} ({limits}): {e}", registration.id));
        renderer.render(&View::Final).unwrap();
        assert_eq!(
            renderer.technique().id,
            registration.id,
            "{} ({limits}) was disabled",
            registration.id
        );
        let counters = renderer.wait_for_counters();
        let atlas: Vec<_> = (counters.iter())
            .filter(|(name, _)| name.starts_with("atlas") || name.starts_with("lights with"))
            .collect();
        eprintln!(
            "{} ({limits}): {:.1} s, {atlas:?}",
            registration.id,
            start.elapsed().as_secs_f64()
        );
    }
    assert!(
        on_defaults >= 10,
        "most techniques run within WebGPU's defaults"
    );
}
