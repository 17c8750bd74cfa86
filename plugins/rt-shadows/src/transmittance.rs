//! The transmittance pass: in scenes with translucent casters, each light's colour fraction
//! that the translucent casters let through, traced into the host's transmittance slot of
//! that light (`fs_transmittance`), which the lighting multiplies with its visibility.

use zoo_host::gpu::PassRecorder;
use zoo_host::prelude::*;
use zoo_host::render::visibility::VISIBILITY_FORMAT;

use crate::RtLight;

/// Base name of the per-light passes.
const PASS: &str = "Transmittance";

/// The pipeline and its per-light uniforms.
pub struct TransmittancePass {
    pipeline: wgpu::RenderPipeline,
    uniforms: kit::UniformSlots<RtLight>,
}

impl TransmittancePass {
    /// The pipeline of fragment `entry` in WGSL `text` (library shader `shader` as composed
    /// for the tracer), after the frame and G-buffer groups: the per-light uniform (2) and the
    /// ray-tracing group (3).
    pub fn new(
        ctx: &RenderContext<'_>,
        shader: &str,
        text: &str,
        entry: &str,
        tracing: &wgpu::BindGroupLayout,
    ) -> TechniqueResult<TransmittancePass> {
        let module = (ctx.shaders).create_module_from_source(&ctx.gpu.device, shader, text)?;
        let uniforms = kit::UniformSlots::new(
            ctx.gpu,
            "rt-shadows transmittance",
            ctx.lights.len(),
            wgpu::ShaderStages::FRAGMENT,
        );
        let groups = [uniforms.layout(), tracing];
        let layout = kit::pipeline_layout(ctx, "rt-shadows transmittance layout", &groups);
        let target = wgpu::ColorTargetState {
            format: VISIBILITY_FORMAT,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        };
        let pipeline = zoo_host::gpu::fullscreen_pipeline(
            &ctx.gpu.device,
            "rt-shadows transmittance",
            Some(&layout),
            &module,
            entry,
            target,
        );
        Ok(TransmittancePass { pipeline, uniforms })
    }

    /// Records one pass per light (named `"Transmittance: light {l}"`) into its transmittance
    /// slot, with the frame's per-light uniforms `per_light`.
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        tracing: &wgpu::BindGroup,
        per_light: impl Fn(usize) -> RtLight,
    ) {
        let values: Vec<RtLight> = (0..ctx.lights.len()).map(per_light).collect();
        self.uniforms.write(ctx.gpu, &values);
        for light in 0..ctx.lights.len() {
            let Some(slot) = ctx.transmittance.slot_view(&ctx.visibility.slots, light) else {
                continue;
            };
            let label = kit::light_pass_name(PASS, light);
            let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
                label: Some(&label),
                color_attachments: &[zoo_host::gpu::color_attachment(slot, wgpu::LoadOp::Load)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
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
