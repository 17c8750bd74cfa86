//! A per-light trace into targets of the technique's choosing: the accumulation of soft lights
//! into the history, the transmittance pass (in scenes with translucent casters, each light's
//! colour fraction that translucent casters let through, into the host's transmittance slot of
//! that light, which the lighting multiplies with its visibility) and the blocker-distance
//! debug view.

use zoo_host::gpu::PassRecorder;
use zoo_host::prelude::*;

use crate::RtLight;

/// The pipeline of one fragment entry of the tracing shader, and its per-light uniforms.
pub struct TracePass {
    label: &'static str,
    pipeline: wgpu::RenderPipeline,
    uniforms: kit::UniformSlots<RtLight>,
}

impl TracePass {
    /// The pipeline of fragment `entry` of the tracing `module` writing `target`, after the
    /// frame and G-buffer groups: the per-light uniform (2) and the ray-tracing group (3).
    /// `label` names it and its passes.
    pub fn new(
        ctx: &RenderContext<'_>,
        label: &'static str,
        (module, entry): (&wgpu::ShaderModule, &str),
        target: wgpu::ColorTargetState,
        tracing: &wgpu::BindGroupLayout,
    ) -> TracePass {
        let uniforms = kit::UniformSlots::new(
            ctx.gpu,
            &format!("rt-shadows {label}"),
            ctx.lights.len(),
            wgpu::ShaderStages::FRAGMENT,
        );
        let groups = [uniforms.layout(), tracing];
        let layout = kit::pipeline_layout(ctx, &format!("rt-shadows {label} layout"), &groups);
        let pipeline = zoo_host::gpu::fullscreen_pipeline(
            &ctx.gpu.device,
            &format!("rt-shadows {label}"),
            Some(&layout),
            module,
            entry,
            target,
        );
        TracePass {
            label,
            pipeline,
            uniforms,
        }
    }

    /// A target state writing `format` as it is (no blend).
    pub fn replace(format: wgpu::TextureFormat) -> wgpu::ColorTargetState {
        wgpu::ColorTargetState {
            format,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        }
    }

    /// Records one pass (named `"{label}: light {l}"`) for each light `target` gives a view
    /// to (loaded or cleared as it says), with the frame's per-light uniforms `per_light` and
    /// the blend constant `blend` gives, if any.
    pub fn record<'t>(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        tracing: &wgpu::BindGroup,
        per_light: impl Fn(usize) -> RtLight,
        target: impl Fn(usize) -> Option<(&'t wgpu::TextureView, wgpu::LoadOp<wgpu::Color>)>,
        blend: impl Fn(usize) -> Option<wgpu::Color>,
    ) {
        let values: Vec<RtLight> = (0..ctx.lights.len()).map(per_light).collect();
        self.uniforms.write(ctx.gpu, &values);
        for light in 0..ctx.lights.len() {
            let Some((view, load)) = target(light) else {
                continue;
            };
            let label = kit::light_pass_name(self.label, light);
            let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
                label: Some(&label),
                color_attachments: &[zoo_host::gpu::color_attachment(view, load)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if let Some(constant) = blend(light) {
                pass.set_blend_constant(constant);
            }
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
