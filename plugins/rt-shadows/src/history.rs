//! Accumulation over frames: soft lights' traced visibility averaged into a floating-point
//! history laid out like the visibility slots (each light's layer and channel), while nothing
//! moves. The filter pass then resolves the history into the slots.

use zoo_host::prelude::*;

use crate::RtLight;

/// Base name of the accumulation passes.
const PASS: &str = "Accumulate";
/// Format of the history: averages of many frames need more than the slots' eight bits.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The history, the previous frame's copy the accumulation reads, and their bindings.
pub struct History {
    history: wgpu::Texture,
    layer_views: Vec<wgpu::TextureView>,
    previous: wgpu::Texture,
    /// The previous frame's history (the accumulation pass's group 4).
    pub previous_group: wgpu::BindGroup,
    /// The current history (the filter pass's group 3).
    pub current_group: wgpu::BindGroup,
}

impl History {
    /// A history shaped like `ctx`'s visibility slots, both groups made with `layout` (one
    /// unfilterable 2D array texture at binding 0).
    pub fn new(ctx: &RenderContext<'_>, layout: &wgpu::BindGroupLayout) -> History {
        let device = &ctx.gpu.device;
        let size = ctx.visibility.texture.size();
        let texture = |label: &str, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: FORMAT,
                usage,
                view_formats: &[],
            })
        };
        let history = texture(
            "rt-shadows history",
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let previous = texture(
            "rt-shadows previous history",
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        let array_view = |texture: &wgpu::Texture, label: &str| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let group = |label: &str, view: &wgpu::TextureView| {
            kit::bind_group(
                device,
                label,
                layout,
                &[wgpu::BindingResource::TextureView(view)],
            )
        };
        let layer_views = (0..size.depth_or_array_layers)
            .map(|layer| {
                history.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("rt-shadows history layer {layer}")),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let previous_group = group(
            "rt-shadows previous history",
            &array_view(&previous, "rt-shadows previous history view"),
        );
        let current_group = group(
            "rt-shadows history",
            &array_view(&history, "rt-shadows history view"),
        );
        History {
            history,
            layer_views,
            previous,
            previous_group,
            current_group,
        }
    }

    /// Whether it still has the slots' shape.
    pub fn fits(&self, ctx: &RenderContext<'_>) -> bool {
        self.history.size() == ctx.visibility.texture.size()
    }
}

/// The accumulation pass: traces a soft light's rays and blends them into its history.
pub struct Accumulation {
    pipeline: wgpu::RenderPipeline,
    uniforms: kit::UniformSlots<RtLight>,
}

impl Accumulation {
    /// The pipeline of fragment `entry` in `shader`, after the frame and G-buffer groups: the
    /// per-light uniform (2), the ray-tracing group (3) and the previous history (4).
    pub fn new(
        ctx: &RenderContext<'_>,
        shader: &str,
        entry: &str,
        tracing: &wgpu::BindGroupLayout,
        history: &wgpu::BindGroupLayout,
    ) -> TechniqueResult<Accumulation> {
        let module = ctx.shaders.create_module(&ctx.gpu.device, shader)?;
        let uniforms = kit::UniformSlots::new(
            ctx.gpu,
            "rt-shadows accumulation",
            ctx.lights.len(),
            wgpu::ShaderStages::FRAGMENT,
        );
        let groups = [uniforms.layout(), tracing, history];
        let layout = kit::pipeline_layout(ctx, "rt-shadows accumulation layout", &groups);
        // The slots' blend: the pass's constant keeps only the light's channel.
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

    /// Copies the history aside, then records one pass per light in `lights` (named
    /// `"Accumulate: light {l}"`) into its layer and channel of the history.
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        history: &History,
        tracing: &wgpu::BindGroup,
        lights: &[usize],
        per_light: impl Fn(usize) -> RtLight,
    ) {
        recorder.encoder().copy_texture_to_texture(
            history.history.as_image_copy(),
            history.previous.as_image_copy(),
            history.history.size(),
        );
        let values: Vec<RtLight> = (0..ctx.lights.len()).map(per_light).collect();
        self.uniforms.write(ctx.gpu, &values);
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
            pass.set_blend_constant(ctx.visibility.light_slot(light).blend_constant);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
            pass.set_bind_group(1, &ctx.gbuffer.bind_group, &[]);
            pass.set_bind_group(
                2,
                self.uniforms.bind_group(),
                &[self.uniforms.offset(light)],
            );
            pass.set_bind_group(zoo_ray_tracing::GROUP, tracing, &[]);
            pass.set_bind_group(4, &history.previous_group, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}
