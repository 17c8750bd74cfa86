//! The slot contract: a technique chooses which visibility slot each light writes (asked again
//! on camera moves when it says so), a refused assignment disables it with its message, and a
//! technique may write a transmittance colour per light that lighting multiplies in.

use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{UVec2, Vec3};
use zoo_host::params::ParamValues;
use zoo_host::render::{SlotAssignment, SlotRequest};
use zoo_host::test_support::{gpu, scene_from_ron};
use zoo_host::{
    Changes, GpuContext, LightKind, PassRecorder, RenderContext, Renderer, Scene, ShadowTechnique,
    TechniqueError, TechniqueResult, View, render::RenderError,
};

static ASKED: AtomicUsize = AtomicUsize::new(0);

/// Gives the lights their slots in reverse order, and refuses while the camera is at x > 0.
struct ByCamera;

impl ShadowTechnique for ByCamera {
    fn assign_slots(&self, request: &SlotRequest<'_>) -> TechniqueResult<SlotAssignment> {
        ASKED.fetch_add(1, Ordering::SeqCst);
        if request.camera.position.x > 0.0 {
            return Err(TechniqueError::Other(
                "test-slots: lights 0, 1 need a layer over the cap".into(),
            ));
        }
        let n = request.lights.len() as u32;
        Ok(SlotAssignment::from_slots((0..n).rev().collect()))
    }
    fn slots_follow_camera(&self) -> bool {
        true
    }
    fn prepare(&mut self, _: &RenderContext<'_>, _: Changes) -> TechniqueResult {
        Ok(())
    }
    fn record(&mut self, _: &RenderContext<'_>, _: &mut PassRecorder<'_>) -> TechniqueResult {
        Ok(())
    }
}

/// Tints light 0 red through its transmittance slot.
struct RedFilter;

impl ShadowTechnique for RedFilter {
    fn writes_transmittance(&self, _: &Scene) -> bool {
        true
    }
    fn prepare(&mut self, _: &RenderContext<'_>, _: Changes) -> TechniqueResult {
        Ok(())
    }
    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let (layer, channel) = ctx.visibility.slots.slot(0);
        let view = &ctx.transmittance.slot_views[(layer * 4 + channel) as usize];
        let red = zoo_host::wgpu::Color {
            r: 1.0,
            g: 0.0,
            b: 0.0,
            a: 1.0,
        };
        let attachments = [zoo_host::gpu::color_attachment(
            view,
            zoo_host::wgpu::LoadOp::Clear(red),
        )];
        drop(recorder.render_pass(&zoo_host::gpu::color_pass("Red filter", &attachments)));
        Ok(())
    }
}

zoo_host::register_technique! {
    id: "test-slots",
    name: "Test: slots by camera",
    description: "Reverse slot order; refuses at x > 0 (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    create: |_: &GpuContext, _: &ParamValues| Ok(Box::new(ByCamera) as Box<dyn ShadowTechnique>),
}

zoo_host::register_technique! {
    id: "test-red-filter",
    name: "Test: red transmittance",
    description: "Light 0 keeps only red (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    create: |_: &GpuContext, _: &ParamValues| Ok(Box::new(RedFilter) as Box<dyn ShadowTechnique>),
}

fn two_lights() -> Scene {
    scene_from_ron(
        "two-lights.ron",
        "(camera: (position: (-1, 4, 6), target: (0, 0, 0)),
          lights: [Point(position: (-1, 3, 0), intensity: 10, range: 20),
                   Point(position: (1, 3, 0), intensity: 10, range: 20)],
          objects: [(mesh: Plane(size: 10), color: (0.8, 0.8, 0.8))])",
    )
}

#[test]
fn techniques_choose_slots_follow_the_camera_and_report_refusals() {
    let scene = two_lights();
    let mut camera = scene.camera;
    let mut renderer = Renderer::new(gpu(), scene, UVec2::new(32, 32)).unwrap();
    renderer
        .set_technique("test-slots", &ParamValues::new())
        .unwrap();
    renderer.render(&View::Final).unwrap();
    assert_eq!(renderer.slots().slot(0), (0, 1));
    assert_eq!(renderer.slots().slot(1), (0, 0));
    let before = ASKED.load(Ordering::SeqCst);
    camera.position.z += 1.0;
    renderer.set_camera(camera);
    assert!(
        ASKED.load(Ordering::SeqCst) > before,
        "asked again on a camera move"
    );
    renderer.render(&View::Final).unwrap();
    // A refused assignment disables the technique with its message.
    camera.position.x = 2.0;
    renderer.set_camera(camera);
    let err = renderer.render(&View::Final).unwrap_err();
    assert!(
        matches!(&err, RenderError::Technique(e) if e.to_string().contains("lights 0, 1 need a layer")),
        "{err}"
    );
    assert_eq!(renderer.technique().id, "unshadowed");
    renderer.render(&View::Final).unwrap();
    // Refused at the start, the switch itself fails and names the lights.
    let err = renderer
        .set_technique("test-slots", &ParamValues::new())
        .unwrap_err();
    assert!(err.to_string().contains("over the cap"), "{err}");
}

#[test]
fn lighting_multiplies_each_light_by_its_transmittance() {
    let mut renderer = Renderer::new(gpu(), two_lights(), UVec2::new(32, 32)).unwrap();
    renderer.render(&View::Final).unwrap();
    let white = renderer.read_output();
    assert!(
        renderer
            .read_transmittance(0)
            .iter()
            .all(|c| *c == Vec3::ONE)
    );
    renderer
        .set_technique("test-red-filter", &ParamValues::new())
        .unwrap();
    renderer.render(&View::Final).unwrap();
    let tinted = renderer.read_output();
    assert!(renderer.read_transmittance(0).iter().all(|c| *c == Vec3::X));
    assert!(
        renderer
            .read_transmittance(1)
            .iter()
            .all(|c| *c == Vec3::ONE)
    );
    // Light 0's green and blue are gone, its red stays: the image turns red.
    let centre = (16 * 32 + 16) * 4;
    let (w, t) = (
        &white.as_raw()[centre..centre + 3],
        &tinted.as_raw()[centre..centre + 3],
    );
    assert_eq!(w[0], t[0], "red is untouched");
    assert!(t[1] < w[1] && t[2] < w[2], "{w:?} -> {t:?}");
}
