//! The viewer's panels, driven headless with egui_kittest.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use shadow_zoo::viewer::ViewerState;
use zoo_host::glam::UVec2;
use zoo_host::params::{ParamSpec, ParamValue, ParamValues};
use zoo_host::test_support::{gpu, scene_path};
use zoo_host::{
    Changes, GpuContext, LightKind, PassInfo, PassRecorder, RenderContext, Scene, ShadowTechnique,
    TechniqueError,
};

/// A test-only technique that panics while recording.
struct Panics;

impl ShadowTechnique for Panics {
    fn passes(&self) -> Vec<PassInfo> {
        Vec::new()
    }
    fn prepare(&mut self, _: &RenderContext<'_>, _: Changes) -> Result<(), TechniqueError> {
        Ok(())
    }
    fn record(
        &mut self,
        _: &RenderContext<'_>,
        _: &mut PassRecorder<'_>,
    ) -> Result<(), TechniqueError> {
        panic!("deliberate viewer test panic")
    }
}

fn create_panics(
    _: &GpuContext,
    _: &ParamValues,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    Ok(Box::new(Panics))
}

zoo_host::register_technique! {
    id: "test-viewer-panics",
    name: "Test: panics in the viewer",
    description: "Panics while recording (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    required_features: zoo_host::wgpu::Features::empty,
    optional_features: zoo_host::wgpu::Features::empty,
    required_limits: zoo_host::wgpu::Limits::downlevel_defaults,
    params: Vec::<ParamSpec>::new,
    create: create_panics,
}

const SIZE: UVec2 = UVec2::new(96, 64);

fn harness() -> Harness<'static, ViewerState> {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let state = ViewerState::new(gpu(), scene, SIZE).unwrap();
    Harness::builder()
        .with_size(egui::vec2(1200.0, 1400.0))
        .build_ui_state(
            |ui, state: &mut ViewerState| {
                state.render(SIZE);
                state.ui(ui, None);
            },
            state,
        )
}

#[test]
fn clicking_a_technique_switches_it_on_the_next_frame() {
    let mut harness = harness();
    harness.run();
    assert_eq!(harness.state().renderer.technique().id, "unshadowed");
    harness.get_by_label("sm-pcf").click();
    harness.run();
    assert_eq!(harness.state().technique, "sm-pcf");
    assert_eq!(harness.state().renderer.technique().id, "sm-pcf");
    // Its passes were rendered and timed.
    let timings = harness.state().timings.clone().unwrap();
    assert!(
        timings
            .passes
            .iter()
            .any(|p| p.name.starts_with("Shadow map"))
    );
    // Its parameter panel is generated from the schema.
    assert!(harness.query_all_by_label("map_size").next().is_some());
    harness.get_by_label("cull_front");
}

#[test]
fn editing_a_parameter_applies_it_and_reset_restores_defaults() {
    let mut harness = harness();
    harness.run();
    harness.get_by_label("sm-pcf").click();
    harness.run();
    harness.get_by_label("cull_front").click();
    harness.run();
    let params = harness.state().renderer.technique_params().clone();
    assert_eq!(params.get("cull_front"), Some(&ParamValue::Bool(true)));
    assert_eq!(
        harness.state().settings["sm-pcf"]["cull_front"],
        ParamValue::Bool(true)
    );
    harness.get_by_label("Reset to defaults").click();
    harness.run();
    let params = harness.state().renderer.technique_params().clone();
    assert_eq!(params.get("cull_front"), Some(&ParamValue::Bool(false)));
}

#[test]
fn a_failing_plugin_shows_a_banner_and_falls_back() {
    let mut harness = harness();
    harness.run();
    harness.get_by_label("test-viewer-panics").click();
    harness.run();
    let state = harness.state();
    assert_eq!(state.renderer.technique().id, "unshadowed");
    let error = state.error.clone().unwrap();
    assert!(error.contains("deliberate viewer test panic"), "{error}");
    harness.get_by_label(&format!("Technique failed: {error}"));
    // The next frames render normally.
    harness.run();
    assert!(harness.state().timings.is_some());
}

#[test]
fn settings_save_and_reload() {
    let mut harness = harness();
    harness.run();
    harness.get_by_label("planar").click();
    harness.run();
    harness
        .state_mut()
        .set_param("opacity", ParamValue::Float(0.5));
    let path = std::env::temp_dir().join(format!("zoo-viewer-settings-{}.ron", std::process::id()));
    harness.state().save_settings(&path).unwrap();
    harness.state_mut().reset_params();
    assert_eq!(
        harness.state().renderer.technique_params()["opacity"],
        ParamValue::Float(1.0)
    );
    harness.state_mut().load_settings(&path).unwrap();
    assert_eq!(
        harness.state().renderer.technique_params()["opacity"],
        ParamValue::Float(0.5)
    );
    // Out-of-range values are clamped, not rejected, in the viewer.
    harness
        .state_mut()
        .set_param("opacity", ParamValue::Float(7.0));
    assert_eq!(
        harness.state().renderer.technique_params()["opacity"],
        ParamValue::Float(1.0)
    );
    // A malformed file is a clear error.
    std::fs::write(&path, "{ \"planar\": ").unwrap();
    let err = harness
        .state_mut()
        .load_settings(&path)
        .unwrap_err()
        .to_string();
    assert!(err.starts_with(&path.display().to_string()), "{err}");
}

#[test]
fn switching_two_hundred_times_frees_the_old_resources() {
    // A device of its own, so other tests' resources do not move the counts.
    let own = std::sync::Arc::new(GpuContext::new_headless().unwrap());
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1200.0, 1400.0))
        .build_ui_state(
            |ui, state: &mut ViewerState| {
                state.render(SIZE);
                state.ui(ui, None);
            },
            ViewerState::new(own, scene, SIZE).unwrap(),
        );
    harness.run();
    let ids = ["sm-pcf", "sv-zfail", "planar", "unshadowed"];
    let cycle = |harness: &mut Harness<'_, ViewerState>, switches: usize| {
        for i in 0..switches {
            harness.state_mut().select_technique(ids[i % 4]);
            harness.state_mut().render(SIZE);
        }
        harness.state().renderer.gpu().wait_idle();
        let c = harness
            .state()
            .renderer
            .gpu()
            .device
            .get_internal_counters()
            .hal;
        // (wgpu-hal's Vulkan backend does not count ordinary textures; views stand in for them.)
        [
            c.buffers.read(),
            c.texture_views.read(),
            c.bind_groups.read(),
            c.render_pipelines.read(),
        ]
    };
    // One round creates every technique once (and any lazily created host objects).
    let warm = cycle(&mut harness, 4);
    let after = cycle(&mut harness, 200);
    eprintln!("buffers, views, bind groups, pipelines: {warm:?} -> {after:?}");
    assert!(
        warm.iter().all(|c| *c > 0),
        "counters are not counting: {warm:?}"
    );
    for (k, name) in [
        "buffers",
        "texture views",
        "bind groups",
        "render pipelines",
    ]
    .iter()
    .enumerate()
    {
        assert!(
            after[k] <= warm[k],
            "{name} grew over 200 switches: {} -> {}",
            warm[k],
            after[k]
        );
    }
}
