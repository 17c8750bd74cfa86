//! Every registered technique renders headless; the deferred lighting matches its CPU mirror.

use glam::{UVec2, Vec3};
use zoo_host::params::ParamValues;
use zoo_host::render::GBufferData;
use zoo_host::scene::shading;
use zoo_host::test_support::{gpu, scene_path, workspace_root};
use zoo_host::{Renderer, Scene, View, registry};

fn load(name: &str) -> Scene {
    Scene::load(&scene_path(name)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn every_plugin_crate_is_linked_and_registered() {
    // Touch the application library so its plugin links are part of this binary.
    let linked = shadow_zoo::LINKED_PLUGINS;
    let dir = workspace_root().join("plugins");
    let mut found = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("plugins/ exists") {
        let manifest = entry.unwrap().path().join("Cargo.toml");
        let Ok(text) = std::fs::read_to_string(&manifest) else {
            continue;
        };
        let table: toml::Table = text.parse().unwrap();
        let name = table["package"]["name"].as_str().unwrap().to_string();
        assert!(
            linked.contains(&name.as_str()),
            "{} is not a dependency of the application: add `{name} = {{ path = \"{}\" }}` to Cargo.toml",
            manifest.display(),
            manifest
                .parent()
                .unwrap()
                .strip_prefix(workspace_root())
                .unwrap()
                .display()
        );
        assert!(
            registry().iter().any(|r| r.package == name),
            "{name} is linked but registers no technique (missing `zoo_host::register_technique!`?)"
        );
        found.push(name);
    }
    assert_eq!(
        found.len(),
        linked.len(),
        "linked {linked:?}, found under plugins/ {found:?}"
    );
    assert!(registry().iter().any(|r| r.id == "unshadowed"));
}

/// Expected sRGB output of the lighting pass at every geometry pixel, from the G-buffer and
/// the CPU mirror of the shading model, with every light's visibility given by `visibility`.
fn expected_image(scene: &Scene, g: &GBufferData, visibility: &[Vec<f32>]) -> Vec<Option<Vec3>> {
    (0..g.positions.len())
        .map(|i| {
            let p = g.positions[i];
            if p.w < 0.5 {
                return None;
            }
            let m = &g.materials[i];
            let view_dir = (scene.camera.position - p.truncate()).normalize();
            let mut c = scene.ambient * m.albedo;
            for (l, light) in scene.lights.iter().enumerate() {
                c += visibility[l][i]
                    * shading::direct_light(light, p.truncate(), g.normals[i], view_dir, m);
            }
            Some(shading::tonemap(c).map(shading::linear_to_srgb) * 255.0)
        })
        .collect()
}

fn assert_matches_cpu_shading(scene_name: &str, size: UVec2) {
    let scene = load(scene_name);
    let mut renderer = Renderer::new(gpu(), scene.clone(), size).unwrap();
    renderer.render(&View::Final).unwrap();
    let image = renderer.read_output();
    let g = renderer.read_gbuffer();
    let visibility: Vec<_> = (0..scene.lights.len())
        .map(|l| renderer.read_visibility(l))
        .collect();
    let expected = expected_image(&scene, &g, &visibility);
    let (mut compared, mut off) = (0, 0);
    for (i, e) in expected.iter().enumerate() {
        let Some(e) = e else { continue };
        let px = image.as_raw()[i * 4..i * 4 + 3].iter().map(|&v| v as f32);
        compared += 1;
        if px.zip(e.to_array()).any(|(a, b)| (a - b).abs() > 3.0) {
            off += 1;
        }
    }
    assert!(
        compared > (size.x * size.y / 3) as usize,
        "{scene_name}: only {compared} geometry pixels"
    );
    let fraction = off as f64 / compared as f64;
    assert!(
        fraction < 0.002,
        "{scene_name}: {off} of {compared} pixels differ from the CPU shading by more than 3/255"
    );
}

#[test]
fn deferred_lighting_matches_cpu_shading_on_planar_room() {
    assert_matches_cpu_shading("planar-room.ron", UVec2::new(192, 144));
}

#[test]
fn deferred_lighting_matches_cpu_shading_with_64_packed_lights() {
    // `unshadowed` lets non-overlapping lights share visibility slots: the lighting pass must
    // still find every light's slot.
    let scene = load("many-lights.ron");
    assert!(scene.lights.len() >= 64);
    let renderer = Renderer::new(gpu(), scene.clone(), UVec2::new(64, 64)).unwrap();
    let slots = renderer.slots().slot_count();
    assert!(
        slots < scene.lights.len() as u32,
        "no packing: {slots} slots"
    );
    drop(renderer);
    assert_matches_cpu_shading("many-lights.ron", UVec2::new(128, 96));
}

/// Every technique at its cheapest renders planar-room lit, never brighter than unshadowed,
/// with every pass timed, and each of its viewable resources renders without disabling it
/// (one loop: each technique is set up and renders its first frame once).
#[test]
fn every_technique_renders_lit_and_finite_and_shows_its_resources() {
    let scene = load("planar-room.ron");
    let size = UVec2::new(160, 120);
    let mut renderer = Renderer::new(gpu(), scene.clone(), size).unwrap();
    renderer.render(&View::Final).unwrap();
    let baseline = renderer.read_output();
    let g = renderer.read_gbuffer();
    assert!(
        g.positions.iter().all(|p| p.is_finite()),
        "non-finite G-buffer position"
    );
    assert!(
        g.normals.iter().all(|n| n.is_finite()),
        "non-finite G-buffer normal"
    );
    let geometry: Vec<usize> = (0..g.positions.len())
        .filter(|&i| g.positions[i].w > 0.5)
        .collect();

    // At their cheapest settings: the contact sheet renders and judges every technique's
    // defaults.
    let mut without_views = Vec::new();
    for registration in crate::shipped_techniques() {
        let id = registration.id;
        let values = zoo_host::test_support::cheapest_params(&(registration.params)());
        renderer
            .set_technique(id, &values)
            .unwrap_or_else(|e| panic!("{id}: {e}"));
        let timings = renderer
            .render(&View::Final)
            .unwrap_or_else(|e| panic!("{id}: {e}"));
        assert_eq!(renderer.technique().id, id, "{id} fell back to unshadowed");
        let image = renderer.read_output();
        let raw = image.as_raw();
        // Shadows only take direct light away: never brighter than the unshadowed frame, unless
        // the technique adds light (which `tests/zoo/indirect_light.rs` checks against the CPU
        // mirror instead).
        let brighter = (0..raw.len())
            .filter(|&k| k % 4 != 3 && raw[k] as i32 > baseline.as_raw()[k] as i32 + 2)
            .count();
        assert!(
            brighter == 0 || registration.adds_light,
            "{id}: {brighter} channels brighter than unshadowed"
        );
        // Most of planar-room is lit by some light.
        let ambient_only = 0.04 * 0.8;
        let lit = geometry
            .iter()
            .filter(|&&i| {
                let luminance = raw[i * 4..i * 4 + 3]
                    .iter()
                    .map(|&v| v as f32 / 255.0)
                    .sum::<f32>()
                    / 3.0;
                luminance
                    > shading::linear_to_srgb(shading::tonemap(Vec3::splat(ambient_only)).x) + 0.05
            })
            .count();
        assert!(
            lit * 2 > geometry.len(),
            "{id}: only {lit} of {} geometry pixels are lit",
            geometry.len()
        );
        for light in 0..scene.lights.len() {
            let v = renderer.read_visibility(light);
            let shadowed = v.iter().filter(|&&x| x < 0.5).count();
            assert!(
                shadowed < v.len() * 9 / 10,
                "{id}: light {light} is shadowed almost everywhere"
            );
        }
        // Every pass it records is timed under its name.
        let recorded = timings.technique_pass_names();
        assert!(
            id == "unshadowed" || !recorded.is_empty(),
            "{id} recorded no passes"
        );
        if show_every_viewable_resource(&mut renderer) == 0 {
            without_views.push(id);
        }
    }
    // A technique without a debug view is a choice, named here.
    assert_eq!(without_views, WITHOUT_VIEWS);
}

/// The techniques that declare no viewable resource, in registry order: per-triangle volumes
/// and rt-shadows, whose buffers are per-pixel flags, boxes and a BVH, and the baseline.
const WITHOUT_VIEWS: [&str; 3] = ["per-triangle-volumes", "rt-shadows", "unshadowed"];

/// Renders every viewable resource of the technique set in `renderer` (after a frame), which
/// must not disable it; returns how many.
fn show_every_viewable_resource(renderer: &mut Renderer) -> usize {
    let id = renderer.technique().id;
    let viewable: Vec<String> = (renderer.technique_instance().resources().into_iter())
        .filter(|r| r.viewable)
        .map(|r| r.name)
        .collect();
    for name in &viewable {
        renderer
            .render(&View::Resource(name.clone()))
            .unwrap_or_else(|e| panic!("{id}: view `{name}`: {e}"));
        assert_eq!(
            renderer.technique().id,
            id,
            "`{name}` disabled the technique"
        );
    }
    viewable.len()
}

#[test]
fn debug_views_render_and_unknown_views_are_errors() {
    let scene = load("planar-room.ron");
    let mut renderer = Renderer::new(gpu(), scene, UVec2::new(64, 64)).unwrap();
    for view in ["normals", "depth", "albedo", "visibility:2"] {
        renderer
            .render(&view.parse().unwrap())
            .unwrap_or_else(|e| panic!("{view}: {e}"));
        let image = renderer.read_output();
        assert!(image.pixels().any(|p| p.0[0] > 20), "{view} is black");
    }
    // Views show their values as stored bytes (the output is sRGB; the view shader decodes
    // first): the albedo view holds the G-buffer's albedo exactly, mid values included.
    renderer.render(&View::Albedo).unwrap();
    let shown = renderer.read_output();
    let g = renderer.read_gbuffer();
    let mut checked = 0;
    for (i, pixel) in shown.pixels().enumerate() {
        if g.positions[i].w < 0.5 {
            continue;
        }
        let albedo = g.materials[i].albedo * 255.0;
        for c in 0..3 {
            assert!(
                (pixel.0[c] as f32 - albedo[c]).abs() <= 1.5,
                "pixel {i} channel {c}: shown {} for albedo {}",
                pixel.0[c],
                albedo[c]
            );
        }
        checked += usize::from((40.0..215.0).contains(&albedo.x));
    }
    assert!(
        checked > 100,
        "too few mid-grey albedo pixels checked: {checked}"
    );
    // Unshadowed: visibility is 1 everywhere, shown white.
    renderer.render(&View::Visibility { light: 0 }).unwrap();
    assert!(renderer.read_output().pixels().all(|p| p.0[0] == 255));
    let err = renderer
        .render(&View::Visibility { light: 9 })
        .unwrap_err()
        .to_string();
    assert!(err.contains("the scene has 3 lights"), "{err}");
    let err = renderer
        .render(&View::Resource("shadow map".into()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("not a view of `unshadowed`"), "{err}");
}

#[test]
fn every_standard_scene_loads_and_renders() {
    let mut renderer = Renderer::new(gpu(), load("planar-room.ron"), UVec2::new(64, 48)).unwrap();
    drop(renderer.render(&View::Final).unwrap());
    for name in [
        "planar-room",
        "curved",
        "dense",
        "atrium",
        "many-lights",
        "inside-shadow",
        "thin-casters",
        "contact",
        "stacked",
    ] {
        let scene = load(&format!("{name}.ron"));
        match name {
            "dense" => assert!(
                scene.triangle_count() >= 200_000,
                "dense has {}",
                scene.triangle_count()
            ),
            "many-lights" => assert!(scene.lights.len() >= 64),
            "planar-room" => assert_eq!(scene.receivers.len(), 3),
            _ => {}
        }
        renderer = Renderer::new(gpu(), scene, UVec2::new(64, 48)).unwrap();
        renderer
            .render(&View::Final)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let image = renderer.read_output();
        assert!(image.pixels().any(|p| p.0[0] > 60), "{name} renders dark");
    }
}

/// A parameter change reaches the live technique when it can take it (no rebuild), and the
/// frame is exactly the one a new instance with those values renders; others rebuild.
#[test]
fn parameter_changes_apply_in_place_or_rebuild() {
    let scene = load("planar-room.ron");
    let size = UVec2::new(96, 80);
    let fresh = |id: &str, assignments: &[(&str, &str)]| {
        let mut renderer = Renderer::new(gpu(), scene.clone(), size).unwrap();
        renderer
            .set_technique(id, &values_for(id, assignments))
            .unwrap();
        renderer.render(&View::Final).unwrap();
        renderer.read_output()
    };
    // Maps of 512² (the defaults are larger): the changes, not the maps, are tested.
    for (id, in_place, rebuilt) in [
        ("sm-pcf", ("filter", "Pcss"), Some(("slope_bias", "2.5"))),
        // The map set replans for a new resolution without a rebuild.
        ("sm-pcf", ("map_size", "1024"), Some(("cull_front", "true"))),
        ("planar", ("opacity", "0.4"), Some(("depth_offset", "32"))),
        (
            "sv-zfail",
            ("debug_light", "1"),
            Some(("counting", "ZPass")),
        ),
        ("vsm", ("map_size", "1024"), None),
        ("vsm", ("blur_radius", "4"), None),
    ] {
        let mut renderer = Renderer::new(gpu(), scene.clone(), size).unwrap();
        renderer.set_technique(id, &values_for(id, &[])).unwrap();
        renderer.render(&View::Final).unwrap();
        let before = renderer.read_output();
        let applied = renderer.set_params(&values_for(id, &[in_place])).unwrap();
        assert!(applied, "{id}: {in_place:?} should apply in place");
        renderer.render(&View::Final).unwrap();
        let after = renderer.read_output();
        assert_eq!(
            after,
            fresh(id, &[in_place]),
            "{id}: {in_place:?} in place differs from a new instance"
        );
        // Visible parameters do change the frame (the debug light only changes debug views).
        assert_eq!(after != before, id != "sv-zfail", "{id}: {in_place:?}");
        let Some(rebuilt) = rebuilt else { continue };
        let applied = renderer
            .set_params(&values_for(id, &[in_place, rebuilt]))
            .unwrap();
        assert!(!applied, "{id}: {rebuilt:?} should rebuild");
        renderer.render(&View::Final).unwrap();
        assert_eq!(
            renderer.read_output(),
            fresh(id, &[in_place, rebuilt]),
            "{id}"
        );
        assert_eq!(
            renderer.technique_params(),
            &values_for(id, &[in_place, rebuilt])
        );
    }
}

/// Technique `id`'s defaults with maps of 512² where it has a map size, then `assignments`.
fn values_for(id: &str, assignments: &[(&str, &str)]) -> ParamValues {
    let schema = (zoo_host::find_technique(id).unwrap().params)();
    let mut values = zoo_host::params::defaults(&schema);
    let small_maps =
        (schema.iter().any(|spec| spec.key == "map_size")).then_some(("map_size", "512"));
    let assignments: Vec<(String, String)> = (small_maps.iter().chain(assignments))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    zoo_host::params::apply_assignments(&schema, &mut values, &assignments).unwrap();
    values
}

/// Every shipped technique carries its crate's README for the viewer: a title, then its
/// parameters by name.
#[test]
fn every_shipped_technique_has_its_readme() {
    for r in crate::shipped_techniques() {
        if r.id == "unshadowed" {
            continue;
        }
        assert!(
            r.readme.starts_with("# "),
            "{} ({}) has no README (plugins/<name>/README.md)",
            r.id,
            r.package
        );
        for spec in (r.params)() {
            assert!(
                r.readme.contains(&format!("`{}`", spec.key)),
                "{}: its README does not document parameter `{}`",
                r.id,
                spec.key
            );
        }
    }
}

/// Every shader of the library validates, with the modules the plugins generate from their
/// `flags(shader)` parameters (which no file may shadow).
#[test]
fn every_shader_validates_with_the_generated_modules() {
    use zoo_host::ShaderLibrary;
    use zoo_host::params::shader::generated_shader_names;
    let library = ShaderLibrary::embedded();
    let names: Vec<_> = ShaderLibrary::names().collect();
    assert!(names.contains(&"host/lighting.wgsl"), "{names:?}");
    assert!(library.is_shared_module("common/gbuffer.wgsl"));
    assert!(library.is_shared_module("shadow-maps/filters.wgsl"));
    assert!(!library.is_shared_module("sm-pcf/lookup.wgsl"));
    let generated = generated_shader_names();
    for module in ["ssss/params.wgsl", "lpv/params.wgsl"] {
        assert!(generated.contains(&module), "{generated:?}");
    }
    for name in &generated {
        assert!(
            !names.contains(name),
            "the file {name} shadows a generated module"
        );
    }
    for name in names {
        // Shared modules are checked through the shaders that import them; the example
        // plugin's shader by the example's tests (this binary does not link the example, so
        // its generated `backfacing/pass.wgsl` is not registered here).
        let unlinked = library.needs_unlinked_module(name);
        assert_eq!(unlinked, name == "backfacing/mask.wgsl", "{name}");
        if library.is_shared_module(name) || unlinked {
            continue;
        }
        if let Err(e) = library.validate(name) {
            panic!("{e}");
        }
    }
}

/// Every GPU struct the linked crates declare with `gpu_struct!` is laid out in Rust exactly
/// as naga lays out its generated WGSL (offsets and size), and no file shadows its module.
#[test]
fn every_gpu_struct_is_laid_out_as_naga_lays_it_out() {
    use zoo_host::ShaderLibrary;
    use zoo_host::gpu::gpu_struct::{check_with_naga, registered_structs};
    let files: Vec<_> = ShaderLibrary::names().collect();
    let mut problems = Vec::new();
    for s in registered_structs() {
        assert!(
            !files.contains(&s.module),
            "{} shadows `{}`",
            s.module,
            s.name
        );
        if let Err(e) = check_with_naga(s) {
            problems.push(e);
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Parameter keys are unique within each technique (shared groups included).
#[test]
fn every_technique_has_unique_parameter_keys() {
    for r in crate::shipped_techniques() {
        let schema = (r.params)();
        for (k, spec) in schema.iter().enumerate() {
            assert!(
                !schema[..k].iter().any(|s| s.key == spec.key),
                "{}: `{}` declared twice",
                r.id,
                spec.key
            );
        }
    }
}
