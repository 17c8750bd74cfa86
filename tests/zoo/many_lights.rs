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
