//! Shadow maps are rendered only when what they hold changes: a static frame renders none, a
//! camera move only the maps that follow the camera (fitted directional maps, lights whose tier
//! changed), a light move that light's maps (and those sharing its atlas pages). What the
//! frames show always equals a frame that renders every map.

// Link the application, which links every plugin.
use shadow_zoo as _;
use zoo_host::glam::{Quat, UVec2, Vec3};
use zoo_host::test_support::{cheapest_params, counter, gpu, scene_path};
use zoo_host::{Renderer, View};

const SIZE: UVec2 = UVec2::new(128, 96);

/// The `maps rendered` counter of the last frame.
fn maps_rendered(renderer: &Renderer) -> f64 {
    counter(&renderer.wait_for_counters(), "maps rendered")
        .expect("the technique counts the maps it renders")
}

/// Every light's visibility of the last frame.
fn visibility(renderer: &Renderer) -> Vec<Vec<f32>> {
    (0..renderer.lights().len())
        .map(|light| renderer.read_visibility(light))
        .collect()
}

/// Asserts that `cached`'s frame shows what a renderer that renders every map shows for the
/// same camera and lights.
fn assert_same_as_fresh(cached: &Renderer, fresh: &mut Renderer, what: &str) {
    fresh.set_camera(*cached.camera());
    fresh.set_lights(cached.lights().to_vec());
    fresh.render(&View::Final).unwrap();
    for (light, (a, b)) in visibility(cached).iter().zip(visibility(fresh)).enumerate() {
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f32::max);
        assert!(
            worst <= 1.0 / 255.0,
            "{what}: light {light} differs from a frame that renders every map by {worst}"
        );
    }
}

/// Runs the frames on `scene` with `technique`; returns the maps rendered by the first frame
/// and after one light moved.
fn check(scene: &str, technique: &str, params: &[(&str, &str)]) -> (f64, f64) {
    let scene = zoo_host::Scene::load(&scene_path(scene)).unwrap();
    let registration = zoo_host::find_technique(technique).unwrap();
    let schema = (registration.params)();
    let mut values = cheapest_params(&schema);
    let params: Vec<_> = (params.iter())
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    zoo_host::params::apply_assignments(&schema, &mut values, &params).unwrap();
    let mut cached = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    let mut fresh = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    fresh.set_reuse_unchanged(false);
    for renderer in [&mut cached, &mut fresh] {
        renderer.set_technique(technique, &values).unwrap();
    }
    cached.render(&View::Final).unwrap();
    let first = maps_rendered(&cached);
    assert!(first > 0.0, "{technique}: the first frame renders the maps");
    cached.render(&View::Final).unwrap();
    assert_eq!(
        maps_rendered(&cached),
        0.0,
        "{technique}: a static frame renders no maps"
    );
    assert_same_as_fresh(&cached, &mut fresh, &format!("{technique}, static"));

    // The camera orbits its target, 3 degrees a frame.
    let mut along_camera = Vec::new();
    for step in 1..=4 {
        let mut camera = scene.camera;
        let turn = Quat::from_rotation_y((3.0 * step as f32).to_radians());
        camera.position = camera.target + turn * (camera.position - camera.target);
        cached.set_camera(camera);
        cached.render(&View::Final).unwrap();
        along_camera.push(maps_rendered(&cached));
        assert_same_as_fresh(
            &cached,
            &mut fresh,
            &format!("{technique}, camera step {step}"),
        );
    }
    let mut lights = cached.lights().to_vec();
    let moved = lights
        .iter()
        .position(|l| l.kind != zoo_host::LightKind::Directional)
        .unwrap();
    lights[moved].position += Vec3::new(0.3, -0.2, 0.25);
    cached.set_lights(lights);
    cached.render(&View::Final).unwrap();
    let light_move = maps_rendered(&cached);
    assert_same_as_fresh(
        &cached,
        &mut fresh,
        &format!("{technique}, light {moved} moved"),
    );
    eprintln!(
        "{technique}: {first} maps in the first frame, 0 when static, {along_camera:?} along the camera path, {light_move} after light {moved} moved"
    );
    assert!(
        along_camera.iter().sum::<f64>() < 4.0 * first,
        "{technique}: camera moves re-render every map"
    );
    assert!(
        light_move > 0.0 && light_move <= first,
        "{technique}: a light move"
    );
    (first, light_move)
}

#[test]
fn maps_are_rendered_again_only_when_their_content_changes() {
    // Depth maps of every kind, colour (moment) maps with their blur, ssss's culled and
    // batched layers with translucency maps, and the hybrid's triangle-id maps.
    check("planar-room.ron", "sm-pcf", &[]);
    check("translucent.ron", "ssss", &[]);
    check(
        "planar-room.ron",
        "hybrid-edge",
        &[("restriction", "TriangleIds")],
    );
    // With many lights, one light's move re-renders a small part of the atlas.
    assert_light_move_rerenders_little("sm-pcf");
}

/// [`maps_are_rendered_again_only_when_their_content_changes`]'s atlas of many lights with the
/// other atlas users: moment maps with their blur, and ssss's batched layers.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn one_light_move_rerenders_a_small_part_of_every_atlas() {
    for technique in ["vsm", "ssss"] {
        assert_light_move_rerenders_little(technique);
    }
}

/// On `many-lights`, `technique`'s maps are cached as [`check`] asks, and one light's move
/// re-renders under an eighth of the first frame's maps.
fn assert_light_move_rerenders_little(technique: &str) {
    let (first, light_move) = check("many-lights.ron", technique, &[]);
    assert!(
        light_move * 8.0 < first,
        "{technique}: {light_move} of {first} maps"
    );
}
