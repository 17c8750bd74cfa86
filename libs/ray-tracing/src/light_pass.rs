//! A per-light full-screen trace into targets of the technique's choosing, with a per-light
//! uniform `T`: rt-shadows' accumulation of soft lights into its history and its
//! blocker-distance view, and the transmittance pass of rt-shadows and ddgi (in scenes with
//! translucent casters, each light's colour fraction that translucent casters let through,
//! into the host's transmittance slot of that light, which the lighting multiplies with its
//! visibility: [`transmittance_slot`]).

use zoo_host::gpu::PassRecorder;
use zoo_host::kit::UniformValue;
use zoo_host::prelude::*;

/// The stage of one fragment entry of a tracing shader, and its per-light uniforms.
pub struct TracePass<T: UniformValue> {
    label: &'static str,
    stage: kit::Stage,
    uniforms: kit::UniformSlots<T>,
}

/// A fragment entry of a tracing shader: the shader's name, its text for the chosen tracer
/// and the entry.
pub type TraceEntry<'a> = (&'a str, &'a str, &'a str);

impl<T: UniformValue> TracePass<T> {
    /// The stage of fragment `entry` of the tracing shader writing `target`, reading the
    /// per-light uniform and the ray-tracing group `tracing`. `label` names it and its passes.
    pub fn new(
        ctx: &RenderContext<'_>,
        label: &'static str,
        (shader, text, entry): TraceEntry<'_>,
        target: wgpu::ColorTargetState,
        tracing: &dyn kit::SharedGroup,
    ) -> TechniqueResult<TracePass<T>> {
        let uniforms = kit::UniformSlots::new(
            ctx.gpu,
            &format!("{label} per light"),
            ctx.lights.len(),
            wgpu::ShaderStages::FRAGMENT,
        );
        let stage = kit::Stage::render(shader, "fullscreen_vs")
            .text(text)
            .fragment(entry)
            .targets(&[Some(target)])
            .shared(&[&uniforms.at(0), tracing])
            .build(ctx)?;
        Ok(TracePass {
            label,
            stage,
            uniforms,
        })
    }

    /// Records one pass (named `"{label}: light {l}"`) for each light `target` gives a view
    /// to (loaded or cleared as it says), with the frame's per-light uniforms `per_light` and
    /// the blend constant `blend` gives, if any.
    pub fn record<'t>(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        tracing: &dyn kit::SharedGroup,
        per_light: impl Fn(usize) -> T,
        target: impl Fn(usize) -> Option<(&'t wgpu::TextureView, wgpu::LoadOp<wgpu::Color>)>,
        blend: impl Fn(usize) -> Option<wgpu::Color>,
    ) -> TechniqueResult {
        let values: Vec<T> = (0..ctx.lights.len()).map(per_light).collect();
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
            let shared = [&self.uniforms.at(light) as &dyn kit::SharedGroup, tracing];
            self.stage.set_on(ctx, &mut pass, &[], &shared)?;
            pass.draw(0..3, 0..1);
        }
        Ok(())
    }
}

/// A target state writing `format` as it is (no blend).
pub fn replace_target(format: wgpu::TextureFormat) -> wgpu::ColorTargetState {
    wgpu::ColorTargetState {
        format,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// The target of light `light`'s pass into its transmittance slot, kept as it is
/// elsewhere (white until written), for [`TracePass::record`]; `None` where the frame has no
/// transmittance slots.
pub fn transmittance_slot<'c>(
    ctx: &'c RenderContext<'_>,
    light: usize,
) -> Option<(&'c wgpu::TextureView, wgpu::LoadOp<wgpu::Color>)> {
    let view = ctx.transmittance.slot_view(&ctx.visibility.slots, light);
    view.map(|view| (view, wgpu::LoadOp::Load))
}
