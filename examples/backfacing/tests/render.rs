//! The example technique writes exactly its idea into every light's slot.

use zoo_example_backfacing as _;

use zoo_host::glam::UVec2;
use zoo_host::params::{self, ParamValues};
use zoo_host::test_support::{gpu, scene_path};
use zoo_host::{Renderer, Scene, View};

#[test]
fn surfaces_facing_away_get_the_darkness_and_the_others_stay_lit() {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let mut renderer = Renderer::new(gpu(), scene, UVec2::new(96, 80)).unwrap();
    let registration = zoo_host::find_technique("backfacing").unwrap();
    let mut values = params::defaults(&(registration.params)());
    params::apply_assignments(
        &(registration.params)(),
        &mut values,
        &[("darkness".into(), "0.25".into())],
    )
    .unwrap();
    renderer.set_technique("backfacing", &values).unwrap();
    let timings = renderer.render(&View::Final).unwrap();
    assert_eq!(
        renderer.technique().id,
        "backfacing",
        "the technique was disabled"
    );
    // One pass per light.
    let recorded = timings.technique_pass_names();
    assert_eq!(
        recorded,
        [
            "Back-facing test: light 0",
            "Back-facing test: light 1",
            "Back-facing test: light 2"
        ]
    );
    let g = renderer.read_gbuffer();
    // The three lights share one layer's channels: each pass must leave the others alone.
    assert_eq!(renderer.slots().slot_count(), 3);
    for (l, light) in renderer.lights().to_vec().iter().enumerate() {
        let visibility = renderer.read_visibility(l);
        let (mut away, mut toward) = (0, 0);
        for (i, v) in visibility.iter().enumerate() {
            let p = g.positions[i];
            let facing = g.normals[i].dot(light.direction_to_light(p.truncate()));
            if p.w < 0.5 || facing.abs() < 1e-2 {
                continue;
            }
            let expected = if facing < 0.0 { 0.25 } else { 1.0 };
            assert!(
                (v - expected).abs() <= 1.0 / 255.0,
                "light {l} pixel {i}: {v}"
            );
            if facing < 0.0 { away += 1 } else { toward += 1 }
        }
        assert!(
            away > 20 && toward > 1000,
            "light {l}: {away} away, {toward} toward"
        );
    }
}

#[test]
fn out_of_range_darkness_is_rejected() {
    let schema = (zoo_host::find_technique("backfacing").unwrap().params)();
    let mut values = ParamValues::new();
    let err = params::apply_assignments(&schema, &mut values, &[("darkness".into(), "2".into())])
        .unwrap_err()
        .to_string();
    assert!(err.contains("darkness"), "{err}");
}

#[test]
fn the_docs_show_this_crate_and_its_shader_verbatim() {
    let root = zoo_host::test_support::workspace_root();
    let page = std::fs::read_to_string(root.join("docs/writing-a-technique.md")).unwrap();
    for file in [
        "examples/backfacing/src/lib.rs",
        "shaders/backfacing/mask.wgsl",
    ] {
        let text = std::fs::read_to_string(root.join(file)).unwrap();
        assert!(
            page.contains(&text),
            "docs/writing-a-technique.md must show {file} as it is"
        );
    }
    let lines = std::fs::read_to_string(root.join("examples/backfacing/src/lib.rs"))
        .unwrap()
        .lines()
        .count();
    assert!(
        lines <= 60,
        "the example has {lines} lines of Rust (at most 60)"
    );
}

#[test]
fn the_shader_validates_and_the_pass_is_laid_out_as_naga_lays_it_out() {
    use zoo_host::gpu::gpu_struct::{check_with_naga, registered_structs};
    let library = zoo_host::ShaderLibrary::embedded();
    library.validate("backfacing/mask.wgsl").unwrap();
    let pass = registered_structs()
        .find(|s| s.name == "Pass")
        .expect("the example registers `Pass`");
    check_with_naga(pass).unwrap();
}
