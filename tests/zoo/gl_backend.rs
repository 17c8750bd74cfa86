//! The host and the techniques on wgpu's GL backend (a machine with only an OpenGL driver, and
//! later WebGL2): the same frames as on Vulkan, and techniques that need more are reported as
//! unavailable with the reason instead of failing.

use std::sync::Arc;

use glam::UVec2;
use shadow_zoo::contact_sheet::{self, Layout};
use zoo_host::params::ParamValues;
use zoo_host::test_support::{Inert, gpu, scene_path};
use zoo_host::{GpuContext, LightKind, Renderer, Scene, View};

// A test-only technique that needs view formats, which wgpu's GL backend lacks.
zoo_host::register_technique! {
    id: "test-needs-view-formats",
    name: "Test: needs view formats",
    description: "Declares a downlevel capability the GL backend lacks (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    required_downlevel: || zoo_host::wgpu::DownlevelFlags::VIEW_FORMATS,
    create: |_, _| Ok(Box::new(Inert)),
}

/// A context on the GL backend, or `None` (with the reason printed) where there is none.
fn gl() -> Option<Arc<GpuContext>> {
    match GpuContext::new_headless_on(zoo_host::wgpu::Backends::GL) {
        Ok(gpu) => {
            eprintln!("GL tests run on {}", gpu.describe());
            Some(Arc::new(gpu))
        }
        Err(e) => {
            eprintln!("SKIPPED: no usable GL adapter on this machine ({e})");
            None
        }
    }
}

/// The largest fraction of pixels that may differ by more than 3/255 between GL and Vulkan,
/// for every technique: one that cannot run the same way on GL must say so (unavailable, with
/// the reason) rather than render another picture. (A looser bound for techniques missing an
/// optional feature once hid ESM's faded shadows on GL: 16-bit maps, exponent clamped to 5.5,
/// 0.089 of the pixels off at 128x96 and false_lit_core 0.038 against 0.0001.)
const PARITY: f64 = 0.001;

/// Fraction of pixels that differ by more than `threshold` in any channel.
fn differing(a: &image::RgbaImage, b: &image::RgbaImage, threshold: u8) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > threshold))
        .count() as f64
        / a.pixels().len() as f64
}

/// One point light: six square shadow-map layers and one visibility layer, the sizes from
/// which wgpu's GL backend would guess a cube map or a plain 2D texture.
const ONE_POINT_LIGHT: &str = "(
    camera: (position: (3, 4.5, 4), target: (0, 0.3, 0), fov_y_degrees: 50),
    lights: [Point(position: (1.5, 5, 1), intensity: 40, range: 50)],
    objects: [(mesh: Plane(size: 10), receiver: true),
              (mesh: Sphere(radius: 0.7), transform: (translation: (0, 1.2, 0)))],
)";

/// The techniques whose map formats the device decides (16- or 32-bit moments, filterable or
/// not, depth formats): the class of ESM's faded shadows on GL, checked in the suite.
const DEVICE_FORMATS: [&str; 6] = ["esm", "evsm2", "evsm4", "msm", "vsm", "sm-pcf"];

#[test]
fn techniques_with_device_chosen_map_formats_render_on_gl_as_on_vulkan() {
    let Some(gl) = gl() else { return };
    let scene = zoo_host::test_support::scene_from_ron("one-point-light.ron", ONE_POINT_LIGHT);
    compare_backends(&gl, scene, |id| DEVICE_FORMATS.contains(&id));
}

/// Every technique on GL, each compiled there once (most of the test's time on a fresh
/// machine: the GL driver's shader cache starts empty).
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn every_technique_renders_on_gl_as_on_vulkan() {
    let Some(gl) = gl() else { return };
    // The default scene (planar-room) is compared tile by tile, judge included, below.
    let scene = zoo_host::test_support::scene_from_ron("one-point-light.ron", ONE_POINT_LIGHT);
    compare_backends(&gl, scene, |_| true);
}

/// The techniques `chosen` by id render `scene` on GL as on Vulkan.
fn compare_backends(gl: &Arc<GpuContext>, scene: Scene, chosen: impl Fn(&str) -> bool) {
    let mut compared = 0;
    for registration in zoo_host::registry() {
        if registration.id.starts_with("test-") || !chosen(registration.id) {
            continue;
        }
        compared += 1;
        assert_parity(gl, &scene, registration, &[]);
    }
    assert!(compared > 0, "no technique chosen");
}

/// `registration` with its cheapest parameters and `assignments` renders `scene` on GL as on
/// Vulkan.
fn assert_parity(
    gl: &Arc<GpuContext>,
    scene: &Scene,
    registration: &zoo_host::TechniqueRegistration,
    assignments: &[(&str, &str)],
) {
    let size = UVec2::new(128, 96);
    let mut on_gl = Renderer::new(gl.clone(), scene.clone(), size).unwrap();
    let mut on_vulkan = Renderer::new(gpu(), scene.clone(), size).unwrap();
    assert_eq!(
        registration.unavailable_reason(gl),
        None,
        "{} should run on GL",
        registration.id
    );
    // Small maps: parity does not depend on their size.
    let schema = (registration.params)();
    let mut values = zoo_host::test_support::cheapest_params(&schema);
    let assigned: Vec<(String, String)> = (assignments.iter())
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    zoo_host::params::apply_assignments(&schema, &mut values, &assigned).unwrap();
    let frame = |renderer: &mut Renderer| {
        renderer.set_technique(registration.id, &values).unwrap();
        renderer.render(&View::Final).unwrap();
        assert_eq!(renderer.technique().id, registration.id, "disabled");
        renderer.read_output()
    };
    let (a, b) = (frame(&mut on_gl), frame(&mut on_vulkan));
    let off = differing(&a, &b, 3);
    eprintln!(
        "{} {assignments:?}: {off} of the pixels differ by more than 3/255",
        registration.id
    );
    assert!(
        off <= PARITY,
        "{} {assignments:?}: GL and Vulkan differ in {off}",
        registration.id
    );
    assert!(gl.take_uncaptured_errors().is_empty());
}

/// Frustum-traced's raster path (casters grown in the vertex stage: GL has no conservative
/// rasterisation) renders on GL as on Vulkan, on a scene of masked casters too.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn the_frustum_traced_raster_path_renders_on_gl_as_on_vulkan() {
    let Some(gl) = gl() else { return };
    let registration = zoo_host::find_technique("frustum-traced").unwrap();
    let raster = [("rasteriser", "Raster")];
    let scene = zoo_host::test_support::scene_from_ron("one-point-light.ron", ONE_POINT_LIGHT);
    assert_parity(&gl, &scene, registration, &raster);
    let foliage = Scene::load(&zoo_host::test_support::scene_path("foliage.ron")).unwrap();
    assert_parity(&gl, &foliage, registration, &raster);
}

#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn the_default_render_on_gl_matches_vulkan() {
    let Some(gl) = gl() else { return };
    // The Vulkan sheet is the one the README's check shares.
    let tile = crate::contact_sheet::README_TILE;
    let (a, b) = (
        &crate::contact_sheet::sheet(gl.clone(), tile),
        crate::contact_sheet::readme_sheet(),
    );
    let ids = |s: &contact_sheet::Sheet| s.rows.iter().map(|r| r.id.clone()).collect::<Vec<_>>();
    assert_eq!(ids(a), ids(b));
    for (i, row) in a.rows.iter().enumerate() {
        let off = differing(&a.images[i], &b.images[i], 3);
        assert!(
            off <= PARITY,
            "tile {}: GL and Vulkan differ in {off}",
            row.id
        );
        assert_eq!(
            a.rows[i].summary.is_some(),
            b.rows[i].summary.is_some(),
            "{}",
            row.id
        );
        if let (Some(x), Some(y)) = (a.rows[i].summary, b.rows[i].summary) {
            // The judge sees the same errors: core errors within 0.0005 (a tenth of the
            // techniques' core bounds), mae within 0.001.
            let close = |p: f64, q: f64, tolerance: f64| (p - q).abs() <= tolerance;
            assert!(
                close(x.false_shadow_core, y.false_shadow_core, 5e-4)
                    && close(x.false_lit_core, y.false_lit_core, 5e-4)
                    && close(x.mae, y.mae, 1e-3),
                "{}: GL {x:?} against Vulkan {y:?}",
                row.id
            );
        }
    }
    let layout = Layout::new((tile.x, tile.y), a.images.len());
    assert_eq!(contact_sheet::draw(a).unwrap().dimensions(), layout.size());
}

#[test]
fn techniques_that_need_more_than_gl_offers_are_unavailable_with_the_reason() {
    let Some(gl) = gl() else { return };
    let registration = zoo_host::find_technique("test-needs-view-formats").unwrap();
    let reason = registration.unavailable_reason(&gl).unwrap();
    assert!(
        reason.contains("VIEW_FORMATS") && reason.contains("Gl backend"),
        "{reason}"
    );
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let mut renderer = Renderer::new(gl, scene, UVec2::new(32, 32)).unwrap();
    let err = renderer
        .set_technique("test-needs-view-formats", &ParamValues::new())
        .unwrap_err()
        .to_string();
    assert!(err.contains("VIEW_FORMATS"), "{err}");
    assert_eq!(renderer.technique().id, "unshadowed");
}

/// Frames whose compute passes read what rasterisation wrote the same frame (a G-buffer) come
/// out the same every frame on GL. llvmpipe (Mesa's GL) once ran such a pass before finishing
/// the rasterisation it had queued, and the frustum-traced tile of the GL contact sheet
/// differed from Vulkan's in 0.3 % of its pixels, in one run of some tens.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn compute_passes_see_the_finished_rasterisation_on_gl() {
    const FRAMES: usize = 32;
    let Some(gl) = gl() else { return };
    let scene = shadow_zoo::setup::load_scene(None).unwrap();
    let mut renderer = Renderer::new(gl, scene, crate::contact_sheet::README_TILE).unwrap();
    for id in ["frustum-traced", "per-triangle-volumes", "ssss"] {
        let registration = zoo_host::find_technique(id).unwrap();
        let values = zoo_host::params::defaults(&(registration.params)());
        renderer.set_technique(id, &values).unwrap();
        renderer.render(&View::Final).unwrap();
        let first = renderer.read_output();
        for frame in 1..FRAMES {
            renderer.render(&View::Final).unwrap();
            let off = differing(&renderer.read_output(), &first, 0);
            assert_eq!(off, 0.0, "{id}: frame {frame} differs from the first");
        }
    }
}
