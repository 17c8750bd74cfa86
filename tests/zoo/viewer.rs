//! The viewer's panels, driven headless with egui_kittest.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use shadow_zoo::viewer::camera::CameraMode;
use shadow_zoo::viewer::split::SplitMode;
use shadow_zoo::viewer::{ViewImages, ViewerState};
use zoo_host::glam::UVec2;
use zoo_host::params::{ParamSpec, ParamValue, ParamValues};
use zoo_host::test_support::{gpu, scene_path};
use zoo_host::{
    Changes, GpuContext, LightKind, PassRecorder, RenderContext, Scene, ShadowTechnique,
    TechniqueError,
};

/// A test-only technique that panics while recording.
struct Panics;

impl ShadowTechnique for Panics {
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

/// The viewer on planar-room with the embedded shaders.
fn harness() -> Harness<'static, ViewerState> {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    harness_for(ViewerState::new(gpu(), scene, SIZE).unwrap())
}

/// Drives `state` headless: each frame renders at `SIZE`, then draws the whole window.
fn harness_for(state: ViewerState) -> Harness<'static, ViewerState> {
    Harness::builder()
        .with_size(egui::vec2(1600.0, 2000.0))
        .build_ui_state(
            |ui, state: &mut ViewerState| {
                state.render(SIZE);
                state.ui(ui, ViewImages::default());
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
    // Its passes were rendered and timed; frames that change nothing keep the maps, until
    // the user asks for every map every frame.
    let map_passes = |harness: &Harness<'_, ViewerState>| {
        let timings = harness.state().timings.clone().unwrap();
        (timings.passes.iter())
            .filter(|p| p.name.starts_with("Shadow map"))
            .count()
    };
    assert_eq!(map_passes(&harness), 0, "a static frame renders no maps");
    harness.get_by_label("keep unchanged shadow maps").click();
    harness.run();
    assert!(!harness.state().renderer.reuse_unchanged());
    assert!(map_passes(&harness) > 0, "every frame renders the maps");
    // Its parameter panel is generated from the schema.
    assert!(harness.query_all_by_label("map_size").next().is_some());
    harness.get_by_label("cull_front");
    // Its README opens under "About sm-pcf".
    harness.get_by_label("About sm-pcf").click();
    harness.run();
    let readme = zoo_host::find_technique("sm-pcf").unwrap().readme;
    harness.get_by_label(readme);
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
fn the_viewer_opens_on_a_shadowing_technique_then_on_the_last_one_used() {
    let dir = std::env::temp_dir().join(format!("zoo-viewer-first-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("settings.ron");
    let _ = std::fs::remove_file(&path);
    // First run: no settings, so the shadow-map technique rather than `unshadowed`.
    let mut first = harness();
    first.state_mut().restore_settings(&path);
    first.run();
    assert_eq!(first.state().technique, "sm-pcf");
    assert_eq!(first.state().renderer.technique().id, "sm-pcf");
    // The user switches and quits; the next run opens where they left off.
    first.get_by_label("sv-zfail").click();
    first.run();
    first.state().save_settings(&path).unwrap();
    let mut second = harness();
    second.state_mut().restore_settings(&path);
    assert_eq!(second.state().renderer.technique().id, "sv-zfail");
    // Unreadable settings are reported and the first-run technique is used.
    std::fs::write(&path, "(technique: ").unwrap();
    let mut third = harness();
    third.state_mut().restore_settings(&path);
    assert_eq!(third.state().renderer.technique().id, "sm-pcf");
    assert!(
        third.state().status.contains("ignored saved settings"),
        "{}",
        third.state().status
    );
}

#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn switching_two_hundred_times_frees_the_old_resources() {
    // A device of its own, so other tests' resources do not move the counts.
    let own = std::sync::Arc::new(GpuContext::new_headless().unwrap());
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let mut harness = harness_for(ViewerState::new(own, scene, SIZE).unwrap());
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

#[test]
fn lights_panel_adds_edits_and_removes_lights() {
    let mut harness = harness();
    harness.run();
    assert_eq!(harness.state().renderer.lights().len(), 3);
    harness.get_by_label("Add light").click();
    harness.run();
    let state = harness.state();
    assert_eq!(state.lights.len(), 4);
    assert_eq!(state.selected_light, 3);
    assert_eq!(
        state.renderer.lights().len(),
        4,
        "the renderer draws the new light"
    );
    // The new light's fields are in the panel; editing them reaches the renderer.
    for field in ["intensity", "range", "radius"] {
        assert!(
            harness.query_all_by_label(field).next().is_some(),
            "{field}"
        );
    }
    harness.state_mut().lights[3].radiance = zoo_host::glam::Vec3::new(1.0, 2.0, 3.0);
    harness.run();
    assert_eq!(
        harness.state().renderer.lights()[3].radiance,
        zoo_host::glam::Vec3::new(1.0, 2.0, 3.0)
    );
    // The spot light (light 1) shows its cone angle.
    harness.get_by_label("1: spot").click();
    harness.run();
    assert!(
        harness
            .query_all_by_label("spot angle (°)")
            .next()
            .is_some()
    );
    harness.get_by_label("Remove light").click();
    harness.run();
    let state = harness.state();
    assert_eq!(state.lights.len(), 3);
    assert_eq!(state.renderer.lights().len(), 3);
    let kinds: Vec<_> = state.lights.iter().map(|l| l.kind).collect();
    use zoo_host::LightKind::{Directional, Point};
    assert_eq!(
        kinds,
        [Point, Directional, Point],
        "the spot light was removed"
    );
}

#[test]
fn dragging_a_light_handle_moves_the_light() {
    let mut harness = harness();
    harness.run();
    let (index, pos) = *harness
        .state()
        .light_handles
        .first()
        .expect("a light has a handle in the view");
    let before = harness.state().lights[index];
    let camera = harness.state().camera;
    harness.hover_at(pos);
    harness.drag_at(pos);
    harness.step();
    harness.hover_at(pos + egui::vec2(40.0, 0.0));
    harness.step();
    harness.drop_at(pos + egui::vec2(40.0, 0.0));
    harness.run();
    let state = harness.state();
    let after = state.lights[index];
    assert_ne!(before, after, "the light moved");
    assert_eq!(
        state.camera, camera,
        "dragging a handle does not orbit the camera"
    );
    assert_eq!(state.selected_light, index);
    assert_eq!(state.renderer.lights()[index], after);
    // Away from any handle, a drag orbits the camera instead.
    let corner = pos + egui::vec2(-200.0, 150.0);
    assert!(
        state
            .light_handles
            .iter()
            .all(|(_, p)| p.distance(corner) > 20.0)
    );
    harness.hover_at(corner);
    harness.drag_at(corner);
    harness.step();
    harness.hover_at(corner + egui::vec2(30.0, 10.0));
    harness.step();
    harness.drop_at(corner + egui::vec2(30.0, 10.0));
    harness.run();
    assert_ne!(harness.state().camera, camera);
    assert_eq!(harness.state().lights[index], after);
}

#[test]
fn fly_camera_moves_with_the_keys_and_bookmarks_return() {
    let mut harness = harness();
    harness.run();
    let name_field = || (egui::accesskit::Role::TextInput, "bookmark name");
    harness
        .get_by_role_and_label(name_field().0, name_field().1)
        .focus();
    harness.step();
    harness
        .get_by_role_and_label(name_field().0, name_field().1)
        .type_text("start");
    harness.run();
    harness.get_by_label("Add bookmark").click();
    harness.run();
    let start = harness.state().camera;
    harness.get_by_label("fly").click();
    harness.run();
    assert_eq!(harness.state().camera.mode, CameraMode::Fly);
    let forward = harness.state().camera.forward();
    harness.key_down(egui::Key::W);
    harness.run_steps(5);
    harness.key_up(egui::Key::W);
    harness.run();
    let moved = harness.state().camera.position - start.position;
    assert!(
        moved.length() > 1e-3 && moved.normalize().dot(forward) > 0.999,
        "W moves along the view: {moved}"
    );
    harness.get_by_label("Go to start").click();
    harness.run();
    let back = harness.state().camera;
    assert!(back.position.abs_diff_eq(start.position, 1e-4));
    assert!(back.pivot().abs_diff_eq(start.pivot(), 1e-3));
    // Bookmarks are saved with the settings, per scene.
    let path = std::env::temp_dir().join(format!("zoo-viewer-marks-{}.ron", std::process::id()));
    harness.state().save_settings(&path).unwrap();
    harness.state_mut().bookmarks.clear();
    harness.state_mut().load_settings(&path).unwrap();
    assert_eq!(harness.state().bookmarks["planar-room"][0].name, "start");
}

#[test]
fn reference_overlay_judges_in_the_background() {
    let mut harness = harness();
    harness.run();
    harness.get_by_label("sm-pcf").click();
    harness.run();
    harness.get_by_label("Judge view").click();
    harness.step();
    // The click started a judgement (traced on its own thread) without an error.
    assert!(
        harness.state().error.is_none(),
        "{:?}",
        harness.state().error
    );
    assert!(harness.state().reference.is_running() || harness.state().reference.result.is_some());
    harness.state_mut().reference.wait().unwrap();
    harness.run();
    let state = harness.state();
    let result = state.reference.result.as_ref().unwrap();
    assert_eq!(result.view.technique, "sm-pcf");
    assert_eq!(result.metrics.len(), 3);
    for metrics in &result.metrics {
        let m = metrics.as_ref().unwrap();
        assert!(m.pixels > 0);
        assert!(
            m.false_shadow_core <= 0.005 && m.false_lit_core <= 0.01,
            "{m:?}"
        );
    }
    assert_eq!(result.error_maps[0].dimensions(), (SIZE.x, SIZE.y));
    harness.get_by_label("show error map");
    harness.get_by_label("false shadow");
    assert!(!state.reference.is_stale(&state.renderer));
    // Moving the camera makes the verdict stale.
    harness
        .state_mut()
        .camera
        .drag(zoo_host::glam::Vec2::new(10.0, 0.0));
    harness.run();
    assert!(
        harness
            .state()
            .reference
            .is_stale(&harness.state().renderer)
    );
    harness.get_by_label("stale: the view changed since it was judged (map hidden)");
}

/// The live judge traces on the GPU every frame the view changes: hard visibility at once,
/// then area rays frame by frame up to the GPU judge's samples; its verdict follows the camera
/// and agrees with the CPU judge's.
#[test]
fn live_reference_follows_the_camera_and_agrees_with_the_cpu_judge() {
    use shadow_zoo::gpu_judge::MAX_SAMPLES;
    let mut harness = harness();
    harness.run();
    harness.get_by_label("sm-pcf").click();
    harness.run();
    harness.get_by_label("live (GPU)").click();
    harness.step();
    harness.step();
    let current = |harness: &Harness<'_, ViewerState>| {
        let state = harness.state();
        assert!(state.error.is_none(), "{:?}", state.error);
        let result = state.reference.result.as_ref().expect("a live verdict");
        assert_eq!(result.view.technique, "sm-pcf");
        assert_eq!(&result.view.camera, state.renderer.camera());
        assert!(!state.reference.is_stale(&state.renderer));
        result.metrics.clone()
    };
    current(&harness);
    for _ in 0..2 * MAX_SAMPLES {
        if harness.state().reference.live_samples() == Some(MAX_SAMPLES) {
            break;
        }
        harness.step();
    }
    assert_eq!(harness.state().reference.live_samples(), Some(MAX_SAMPLES));
    harness.get_by_label_contains("live on the GPU, 64 area rays a pixel");
    let live = current(&harness);

    // The camera moves: the verdict follows at once, from hard visibility again.
    harness
        .state_mut()
        .camera
        .drag(zoo_host::glam::Vec2::new(12.0, 0.0));
    harness.step();
    current(&harness);
    assert_eq!(harness.state().reference.live_samples(), Some(0));
    harness
        .state_mut()
        .camera
        .drag(zoo_host::glam::Vec2::new(-12.0, 0.0));
    harness.step();

    // The CPU judge, the arbiter, replaces it and agrees.
    harness.get_by_label("Judge view").click();
    harness.step();
    assert_eq!(harness.state().reference.live_samples(), None);
    harness.state_mut().reference.wait().unwrap();
    let cpu = harness.state().reference.result.as_ref().unwrap();
    for (light, (live, cpu)) in live.iter().zip(&cpu.metrics).enumerate() {
        let (live, cpu) = (live.as_ref().unwrap(), cpu.as_ref().unwrap());
        eprintln!(
            "light {light}: live mae {:.4} fs {:.4} fl {:.4}; CPU judge mae {:.4} fs {:.4} fl {:.4}",
            live.mae, live.false_shadow, live.false_lit, cpu.mae, cpu.false_shadow, cpu.false_lit
        );
        assert!((live.mae - cpu.mae).abs() <= 0.01, "light {light}");
        assert!(
            (live.false_shadow - cpu.false_shadow).abs() <= 0.01,
            "light {light}"
        );
        assert!(
            (live.false_lit - cpu.false_lit).abs() <= 0.01,
            "light {light}"
        );
    }
}

/// Where nothing may wait for the GPU (the browser), the live judge's traces and judged frames
/// arrive frames later: no verdict in the frame of a change, then one for the view shown,
/// area rays added up to the GPU judge's samples, and the waiting judge's verdict.
#[test]
fn live_reference_without_waiting_arrives_frames_later_with_the_same_verdict() {
    use shadow_zoo::gpu_judge::MAX_SAMPLES;
    let verdict = |wait: bool| {
        let mut harness = harness();
        harness.run();
        harness.get_by_label("sm-pcf").click();
        harness.run();
        harness.state_mut().reference.set_live_waits(wait);
        harness.get_by_label("live (GPU)").click();
        harness.step();
        if !wait {
            // The click's frame started the trace; nothing has been read back in it.
            assert!(harness.state().reference.result.is_none());
        }
        let mut frames = 1;
        while harness.state().reference.live_samples() != Some(MAX_SAMPLES) {
            assert!(
                frames < 40 * MAX_SAMPLES,
                "{MAX_SAMPLES} area rays a pixel never arrived"
            );
            harness.step();
            frames += 1;
        }
        // The verdict for the last trace may still be on its way.
        for _ in 0..40 {
            let result = harness.state().reference.result.as_ref();
            if result.is_some_and(|r| r.live_samples == Some(MAX_SAMPLES)) {
                break;
            }
            harness.step();
        }
        let state = harness.state();
        assert!(state.error.is_none(), "{:?}", state.error);
        let result = state.reference.result.as_ref().expect("a live verdict");
        assert_eq!(result.live_samples, Some(MAX_SAMPLES));
        assert_eq!(&result.view.camera, state.renderer.camera());
        (frames, result.metrics.clone())
    };
    let (frames_waiting, waiting) = verdict(true);
    let (frames, later) = verdict(false);
    eprintln!("{MAX_SAMPLES} area rays: {frames_waiting} frames waiting, {frames} without");
    assert!(frames >= frames_waiting);
    for (light, (waiting, later)) in waiting.iter().zip(&later).enumerate() {
        let (waiting, later) = (waiting.as_ref().unwrap(), later.as_ref().unwrap());
        assert!((waiting.mae - later.mae).abs() <= 0.002, "light {light}");
        assert!(
            (waiting.false_shadow - later.false_shadow).abs() <= 0.002,
            "light {light}"
        );
        assert!(
            (waiting.false_lit - later.false_lit).abs() <= 0.002,
            "light {light}"
        );
    }
}

#[test]
fn ab_split_and_difference_compare_two_techniques() {
    let mut harness = harness();
    harness.run();
    harness.get_by_label("compare with B").click();
    harness.run();
    harness.get_by_label("B: sm-pcf").click();
    harness.run();
    {
        let state = harness.state();
        let ab = state.ab.as_ref().unwrap();
        assert_eq!(ab.renderer.technique().id, "sm-pcf");
        assert_eq!(state.technique_b, "sm-pcf");
        assert_eq!(ab.renderer.camera(), state.renderer.camera());
        assert!(state.b_timings.is_some());
    }
    harness.get_by_label("difference").click();
    harness.run();
    let state = harness.state();
    let ab = state.ab.as_ref().unwrap();
    assert_eq!(ab.mode, SplitMode::Difference);
    // A = unshadowed is never darker than B = sm-pcf: only blue differences.
    let diff = ab.difference.read(state.renderer.gpu()).unwrap();
    let blue = diff
        .pixels()
        .filter(|p| p[2] as i32 > p[0] as i32 + 40)
        .count();
    let red = diff
        .pixels()
        .filter(|p| p[0] as i32 > p[2] as i32 + 40)
        .count();
    assert!(
        blue > diff.pixels().len() / 50,
        "B's shadows show as blue: {blue}"
    );
    assert_eq!(red, 0, "A is never darker than B");
    // The same technique on both sides: no difference at all.
    harness.get_by_label("B: unshadowed").click();
    harness.run();
    let state = harness.state();
    let ab = state.ab.as_ref().unwrap();
    let diff = ab.difference.read(state.renderer.gpu()).unwrap();
    assert!(
        diff.pixels().all(|p| p[0] == p[2]),
        "identical sides differ"
    );
    harness.get_by_label("compare with B").click();
    harness.run();
    assert!(harness.state().ab.is_none());
}

#[test]
fn debug_views_can_be_overlaid_on_the_final_image() {
    let mut harness = harness();
    harness.run();
    let final_image = harness.state().renderer.read_output();
    harness.get_by_label("normals").click();
    harness.run();
    let normals = harness.state().renderer.read_output();
    harness.get_by_label("overlay").click();
    harness.run();
    let state = harness.state();
    let overlaid = state.renderer.read_output();
    let passes: Vec<_> = state
        .timings
        .as_ref()
        .unwrap()
        .passes
        .iter()
        .map(|p| p.name.clone())
        .collect();
    assert!(passes.iter().any(|p| p == "Lighting"), "{passes:?}");
    assert!(passes.iter().any(|p| p == "Debug overlay"), "{passes:?}");
    // At half opacity every pixel lies between the final image and the normals view.
    let mut between = 0;
    for ((o, f), n) in overlaid
        .pixels()
        .zip(final_image.pixels())
        .zip(normals.pixels())
    {
        let ok = (0..3).all(|c| {
            let (lo, hi) = (f[c].min(n[c]) as i32, f[c].max(n[c]) as i32);
            (lo - 2..=hi + 2).contains(&(o[c] as i32))
        });
        between += ok as usize;
    }
    assert!(between * 100 >= overlaid.pixels().len() * 99, "{between}");
    assert_ne!(overlaid, final_image);
    assert_ne!(overlaid, normals);
}

#[test]
fn settings_buttons_save_and_load_ron() {
    let mut harness = harness();
    harness.run();
    let path = std::env::temp_dir().join(format!("zoo-viewer-buttons-{}.ron", std::process::id()));
    harness.state_mut().settings_file = path.display().to_string();
    harness.get_by_label("planar").click();
    harness.run();
    harness
        .state_mut()
        .set_param("opacity", ParamValue::Float(0.25));
    harness.get_by_label("Save settings").click();
    harness.run();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("opacity") && text.contains("0.25"), "{text}");
    harness.get_by_label("unshadowed").click();
    harness.run();
    harness.state_mut().settings.clear();
    harness.get_by_label("Load settings").click();
    harness.run();
    let state = harness.state();
    assert_eq!(state.technique, "planar", "the saved technique is selected");
    assert_eq!(
        state.renderer.technique_params()["opacity"],
        ParamValue::Float(0.25)
    );
    assert!(state.status.starts_with("loaded"), "{}", state.status);
}

/// Copies the embedded shaders into a fresh folder the viewer reads and watches.
fn shader_folder(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("zoo-viewer-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let library = zoo_host::ShaderLibrary::embedded();
    for name in zoo_host::ShaderLibrary::names() {
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, library.source(name).unwrap()).unwrap();
    }
    dir
}

#[test]
fn editing_a_shader_reloads_it_and_errors_keep_the_old_pipeline() {
    let dir = shader_folder("hot-reload");
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let library = zoo_host::ShaderLibrary::from_disk(dir.clone());
    let mut harness = harness_for(ViewerState::with_shaders(gpu(), scene, SIZE, library).unwrap());
    harness.run();
    let lit = harness.state().renderer.read_output();
    assert!(lit.pixels().any(|p| p[0] > 20));
    // Waits (up to 10 s) for the watcher to notice and the viewer to react.
    let settle = |harness: &mut Harness<'_, ViewerState>, done: &dyn Fn(&ViewerState) -> bool| {
        for _ in 0..200 {
            std::thread::sleep(std::time::Duration::from_millis(50));
            harness.run();
            if done(harness.state()) {
                return;
            }
        }
        panic!("the viewer did not react to the shader edit");
    };
    // A broken edit: the error names file, line and column; the old pipeline keeps running.
    let lighting = dir.join("host/lighting.wgsl");
    let original = std::fs::read_to_string(&lighting).unwrap();
    std::fs::write(
        &lighting,
        format!("{original}\nfn broken() -> f32 {{ return nope; }}\n"),
    )
    .unwrap();
    settle(&mut harness, &|s| s.shader_error.is_some());
    let error = harness.state().shader_error.clone().unwrap();
    let line = original.lines().count() + 2;
    assert!(
        error.starts_with(&format!("shaders/host/lighting.wgsl:{line}:")),
        "{error}"
    );
    harness.get_by_label(&format!("Shader error: {error}"));
    assert_eq!(harness.state().renderer.read_output(), lit);
    // A working edit replaces the pipeline: the lighting now writes black.
    let entry = original.find("@fragment").unwrap();
    let body = original[entry..].find('{').unwrap() + entry + 1;
    let dark = format!(
        "{}\n    if true {{ return vec4<f32>(0.0, 0.0, 0.0, 1.0); }}{}",
        &original[..body],
        &original[body..]
    );
    std::fs::write(&lighting, dark).unwrap();
    settle(&mut harness, &|s| s.shader_error.is_none());
    let black = harness.state().renderer.read_output();
    assert!(black.pixels().all(|p| p[0] == 0 && p[1] == 0 && p[2] == 0));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn any_scene_file_opens_and_bad_ones_say_why() {
    let mut harness = harness();
    harness.run();
    let dir = std::env::temp_dir().join(format!("zoo-viewer-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("broken.ron");
    std::fs::write(&bad, "(\n  camera: (position: (0, 1, 2)\n").unwrap();
    harness.state_mut().scene_file = bad.display().to_string();
    harness.get_by_label("Open").click();
    harness.run();
    let state = harness.state();
    let error = state.scene_error.clone().unwrap();
    assert!(error.starts_with(&format!("{}:", bad.display())), "{error}");
    assert_eq!(
        state.renderer.scene().name,
        "planar-room",
        "the old scene stays"
    );
    harness.get_by_label(&format!("Scene error: {error}"));
    // A scene outside scenes/ opens, with its own camera and lights.
    let other = scene_path("curved.ron");
    let copy = dir.join("elsewhere.ron");
    let text = std::fs::read_to_string(&other).unwrap();
    std::fs::write(&copy, &text).unwrap();
    harness.state_mut().scene_file = copy.display().to_string();
    harness.get_by_label("Open").click();
    harness.run();
    let state = harness.state();
    assert!(state.scene_error.is_none());
    let curved = Scene::load(&other).unwrap();
    assert_eq!(state.lights, curved.lights);
    assert_eq!(state.renderer.lights(), curved.lights.as_slice());
    assert_eq!(
        state.renderer.scene().triangle_count(),
        curved.triangle_count()
    );
    let _ = std::fs::remove_dir_all(&dir);
}
