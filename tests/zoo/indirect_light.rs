//! The contract for techniques that add light: the indirect target (irradiance over π) is
//! written and read back, lighting adds albedo × indirect in place of the scene's ambient as
//! the CPU mirror does, the judge scores it against the one-bounce reference, and 3D
//! resources show as slices.

use glam::{UVec2, Vec3};
use zoo_host::judging::{SceneReference, judge_technique, shade_on_cpu};
use zoo_host::params::ParamValues;
use zoo_host::test_support::{gpu, scene_path};
use zoo_host::{
    Changes, DebugVolume, GpuContext, LightKind, PassRecorder, RenderContext, Renderer, Scene,
    ShadowTechnique, TechniqueResult, View, ViewMapping, VolumeAxis, VolumeSlice,
};

const INDIRECT: [f64; 3] = [0.3, 0.2, 0.1];

/// Adds a constant indirect light everywhere.
struct ConstantIndirect;

impl ShadowTechnique for ConstantIndirect {
    fn prepare(&mut self, _: &RenderContext<'_>, _: Changes) -> TechniqueResult {
        Ok(())
    }
    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let [r, g, b] = INDIRECT;
        let clear = zoo_host::wgpu::LoadOp::Clear(zoo_host::wgpu::Color { r, g, b, a: 1.0 });
        let attachments = [zoo_host::gpu::color_attachment(&ctx.indirect.view, clear)];
        drop(recorder.render_pass(&zoo_host::gpu::color_pass(
            "Constant indirect",
            &attachments,
        )));
        Ok(())
    }
}

/// Owns a 4 x 3 x 2 volume whose texels hold their own coordinates, shown across z.
struct Volume {
    view: Option<zoo_host::wgpu::TextureView>,
}

impl ShadowTechnique for Volume {
    fn prepare(&mut self, ctx: &RenderContext<'_>, _: Changes) -> TechniqueResult {
        use zoo_host::wgpu;
        let size = wgpu::Extent3d {
            width: 4,
            height: 3,
            depth_or_array_layers: 2,
        };
        let texture = ctx.gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("test volume"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let mut texels = Vec::new();
        for z in 0..2u32 {
            for y in 0..3u32 {
                for x in 0..4u32 {
                    texels.extend([x * 80, y * 120, z * 255, 255].map(|v| v as u8));
                }
            }
        }
        ctx.gpu.queue.write_texture(
            texture.as_image_copy(),
            &texels,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(16),
                rows_per_image: Some(3),
            },
            size,
        );
        self.view = Some(texture.create_view(&Default::default()));
        Ok(())
    }
    fn record(&mut self, _: &RenderContext<'_>, _: &mut PassRecorder<'_>) -> TechniqueResult {
        Ok(())
    }
    fn debug_volume(&self, resource: &str) -> Option<DebugVolume<'_>> {
        if resource != "volume" {
            return None;
        }
        Some(DebugVolume {
            view: self.view.as_ref()?,
            mapping: ViewMapping::Color { min: 0.0, max: 1.0 },
            slice: VolumeSlice {
                axis: VolumeAxis::Z,
                index: 1,
            },
        })
    }
}

zoo_host::register_technique! {
    id: "test-indirect",
    name: "Test: constant indirect light",
    description: "Adds (0.3, 0.2, 0.1) of indirect light everywhere (test only)",
    source: "test",
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    adds_light: true,
    create: |_: &GpuContext, _: &ParamValues| {
        Ok(Box::new(ConstantIndirect) as Box<dyn ShadowTechnique>)
    },
}

zoo_host::register_technique! {
    id: "test-volume",
    name: "Test: a 3D debug volume",
    description: "Shows a slice of a small volume (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    create: |_: &GpuContext, _: &ParamValues| {
        Ok(Box::new(Volume { view: None }) as Box<dyn ShadowTechnique>)
    },
}

#[test]
fn added_light_replaces_the_ambient_and_matches_the_cpu_mirror() {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let mut renderer = Renderer::new(gpu(), scene.clone(), UVec2::new(96, 72)).unwrap();
    assert_eq!(renderer.ambient(), scene.ambient);
    renderer
        .set_technique("test-indirect", &ParamValues::new())
        .unwrap();
    assert_eq!(
        renderer.ambient(),
        Vec3::ZERO,
        "the technique's light replaces the ambient"
    );
    renderer.render(&View::Final).unwrap();
    let indirect = renderer.read_indirect();
    let expected = Vec3::new(0.3, 0.2, 0.1);
    assert!(
        indirect
            .iter()
            .all(|c| (*c - expected).abs().max_element() < 1e-3)
    );
    // The GPU frame against the CPU mirror with every light visible.
    let gbuffer = renderer.read_gbuffer();
    let lit = vec![1.0f32; indirect.len()];
    let visibility: Vec<&[f32]> = (0..scene.lights.len()).map(|_| lit.as_slice()).collect();
    let image = renderer.read_output();
    let mirror = shade_on_cpu(&renderer, &gbuffer, &visibility, Some(&indirect), &image);
    let off = image
        .as_raw()
        .iter()
        .zip(mirror.as_raw())
        .filter(|(a, b)| (**a as i32 - **b as i32).abs() > 2)
        .count();
    assert!(
        off < image.as_raw().len() / 200,
        "{off} channels differ from the CPU mirror"
    );
}

#[test]
fn the_judge_scores_added_light_against_the_one_bounce_reference() {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let mut renderer = Renderer::new(gpu(), scene.clone(), UVec2::new(48, 36)).unwrap();
    let mut reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
    let judged = judge_technique(
        &mut renderer,
        &reference,
        "test-indirect",
        &ParamValues::new(),
    )
    .unwrap();
    let rmse = judged
        .indirect_rmse(&mut reference, &scene, &scene.lights, 16)
        .expect("the technique adds light");
    // A constant is a poor one-bounce estimate, but a finite one.
    assert!(rmse.is_finite() && rmse > 0.05, "{rmse}");
    let bounce = reference.indirect(&scene, &scene.lights, 16);
    let mean = bounce.iter().map(|c| c.x as f64).sum::<f64>() / bounce.len() as f64;
    assert!(mean > 0.0, "planar-room's walls and floor reflect light");
    // Techniques that add no light are not scored.
    let plain =
        judge_technique(&mut renderer, &reference, "unshadowed", &ParamValues::new()).unwrap();
    assert!(
        plain
            .indirect_rmse(&mut reference, &scene, &scene.lights, 16)
            .is_none()
    );
}

#[test]
fn three_dimensional_resources_show_as_slices() {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let size = UVec2::new(8, 6);
    let mut renderer = Renderer::new(gpu(), scene, size).unwrap();
    renderer
        .set_technique("test-volume", &ParamValues::new())
        .unwrap();
    renderer.render(&View::Final).unwrap();
    renderer.render(&View::Resource("volume".into())).unwrap();
    let image = renderer.read_output();
    // Across z at texel 1: x across the screen (2 pixels a texel), y up (2 pixels a texel).
    let pixel = |x: u32, y: u32| image.get_pixel(x, y).0;
    assert_eq!(pixel(0, 0), [0, 240, 255, 255], "top left: x 0, y 2");
    assert_eq!(pixel(7, 5), [240, 0, 255, 255], "bottom right: x 3, y 0");
    assert_eq!(pixel(3, 2), [80, 120, 255, 255], "x 1, y 1");
}
