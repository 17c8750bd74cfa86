//! Accumulation over frames: soft lights' traced visibility averaged, by blending, into a
//! floating-point history laid out like the visibility slots (each light's layer and channel),
//! while nothing moves. The filter pass then resolves the history into the slots.

use zoo_host::prelude::*;

use crate::RtLight;

/// Base name of the accumulation passes.
const PASS: &str = "Accumulate";
/// Format of the history: averages of many frames need more than the slots' eight bits.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The history and its binding.
pub struct History {
    pub texture: wgpu::Texture,
    layer_views: Vec<wgpu::TextureView>,
    /// The history as the filter pass reads it (its group 3).
    pub group: wgpu::BindGroup,
}

impl History {
    /// A history shaped like `ctx`'s visibility slots, bound with `layout` (one unfilterable
    /// 2D array texture at binding 0).
    pub fn new(ctx: &RenderContext<'_>, layout: &wgpu::BindGroupLayout) -> History {
        let device = &ctx.gpu.device;
        let size = ctx.visibility.texture.size();
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("rt-shadows history"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let layer_views = (0..size.depth_or_array_layers)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("rt-shadows history layer {layer}")),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("rt-shadows history view"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let group = kit::bind_group(
            device,
            "rt-shadows history",
            layout,
            &[wgpu::BindingResource::TextureView(&view)],
        );
        History {
            texture,
            layer_views,
            group,
        }
    }

    /// Whether it still has the slots' shape.
    pub fn fits(&self, ctx: &RenderContext<'_>) -> bool {
        self.texture.size() == ctx.visibility.texture.size()
    }
}

/// The accumulation pass: traces a soft light's rays and blends them into its history.
/// The blend does the averaging: the slots' blend (source times the constant, plus the
/// destination times one minus it) with the light's channel of the constant set to the new
/// frame's weight keeps the other channels and gives `traced · (1 − w) + history · w`.
pub struct Accumulation {
    pipeline: wgpu::RenderPipeline,
    uniforms: kit::UniformSlots<RtLight>,
}

impl Accumulation {
    /// The pipeline of fragment `entry` in WGSL `text` (library shader `shader` as composed
    /// for the tracer), after the frame and G-buffer groups: the per-light uniform (2) and the
    /// ray-tracing group (3).
    pub fn new(
        ctx: &RenderContext<'_>,
        shader: &str,
        text: &str,
        entry: &str,
        tracing: &wgpu::BindGroupLayout,
    ) -> TechniqueResult<Accumulation> {
        let module = (ctx.shaders).create_module_from_source(&ctx.gpu.device, shader, text)?;
        let uniforms = kit::UniformSlots::new(
            ctx.gpu,
            "rt-shadows accumulation",
            ctx.lights.len(),
            wgpu::ShaderStages::FRAGMENT,
        );
        let groups = [uniforms.layout(), tracing];
        let layout = kit::pipeline_layout(ctx, "rt-shadows accumulation layout", &groups);
        let target = wgpu::ColorTargetState {
            format: FORMAT,
            ..kit::slot_target()
        };
        let pipeline = zoo_host::gpu::fullscreen_pipeline(
            &ctx.gpu.device,
            "rt-shadows accumulation",
            Some(&layout),
            &module,
            entry,
            target,
        );
        Ok(Accumulation { pipeline, uniforms })
    }

    /// Writes the frame's per-light uniforms (every light's, once per frame).
    pub fn write(&mut self, ctx: &RenderContext<'_>, per_light: impl Fn(usize) -> RtLight) {
        let values: Vec<RtLight> = (0..ctx.lights.len()).map(per_light).collect();
        self.uniforms.write(ctx.gpu, &values);
    }

    /// Records one pass per light in `lights` (named `"Accumulate: light {l}"`) into its layer
    /// and channel of `history`, the new frame weighing `weight` and the history the rest.
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        history: &History,
        tracing: &wgpu::BindGroup,
        lights: &[usize],
        weight: f64,
    ) {
        for &light in lights {
            let (layer, _) = ctx.visibility.slots.slot(light);
            let label = kit::light_pass_name(PASS, light);
            let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
                label: Some(&label),
                color_attachments: &[zoo_host::gpu::color_attachment(
                    &history.layer_views[layer as usize],
                    wgpu::LoadOp::Load,
                )],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let channel = ctx.visibility.light_slot(light).blend_constant;
            pass.set_blend_constant(wgpu::Color {
                r: channel.r * weight,
                g: channel.g * weight,
                b: channel.b * weight,
                a: channel.a * weight,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
            pass.set_bind_group(1, &ctx.gbuffer.bind_group, &[]);
            pass.set_bind_group(
                2,
                self.uniforms.bind_group(),
                &[self.uniforms.offset(light)],
            );
            pass.set_bind_group(zoo_ray_tracing::GROUP, tracing, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}
