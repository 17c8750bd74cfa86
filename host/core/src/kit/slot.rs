//! Writing one light's visibility slot.
//!
//! Lights' visibility lives in the channels of an `Rgba8Unorm` array (see
//! [`VisibilityTargets`]). A pass that writes light `l` returns its visibility in every
//! channel; the pipeline blends with `src * constant + dst * (1 - constant)` and the blend
//! constant is the one-hot mask of the light's channel, so one pipeline serves every channel and
//! the other lights' values stay exactly as they were.

use crate::gpu::{PassRecorder, RecordedRenderPass};
use crate::render::VisibilityTargets;
use crate::render::visibility::VISIBILITY_FORMAT;
use crate::technique::RenderContext;

/// The colour target of a pipeline that writes visibility slots.
pub fn slot_target() -> wgpu::ColorTargetState {
    let select = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Constant,
        dst_factor: wgpu::BlendFactor::OneMinusConstant,
        operation: wgpu::BlendOperation::Add,
    };
    wgpu::ColorTargetState {
        format: VISIBILITY_FORMAT,
        blend: Some(wgpu::BlendState {
            color: select,
            alpha: select,
        }),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// Where one light's visibility goes.
#[derive(Debug, Clone, Copy)]
pub struct LightSlot<'a> {
    /// The array layer to attach.
    pub view: &'a wgpu::TextureView,
    /// The blend constant that selects the light's channel.
    pub blend_constant: wgpu::Color,
}

impl VisibilityTargets {
    /// The layer and channel selector of light `light`.
    pub fn light_slot(&self, light: usize) -> LightSlot<'_> {
        let (layer, channel) = self.slots.slot(light);
        let on = |c: u32| if c == channel { 1.0 } else { 0.0 };
        LightSlot {
            view: &self.layer_views[layer as usize],
            blend_constant: wgpu::Color {
                r: on(0),
                g: on(1),
                b: on(2),
                a: on(3),
            },
        }
    }
}

impl RenderContext<'_> {
    /// Opens render pass `label` on light `light`'s visibility slot (loaded, not cleared) with
    /// the blend constant set for [`slot_target`] pipelines and the frame (group 0) and G-buffer
    /// (group 1) bind groups bound. `depth_stencil` attaches, for example, the G-buffer's
    /// depth-stencil for stencil techniques.
    pub fn light_pass<'r>(
        &self,
        recorder: &'r mut PassRecorder<'_>,
        label: &str,
        light: usize,
        depth_stencil: Option<wgpu::RenderPassDepthStencilAttachment<'_>>,
    ) -> RecordedRenderPass<'r> {
        self.light_pass_with(recorder, label, light, &[], depth_stencil)
    }

    /// As [`Self::light_pass`], with more colour attachments after the slot (locations 1, 2,
    /// ...; pipelines that do not blend them are not affected by the blend constant).
    pub fn light_pass_with<'r>(
        &self,
        recorder: &'r mut PassRecorder<'_>,
        label: &str,
        light: usize,
        more_colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
        depth_stencil: Option<wgpu::RenderPassDepthStencilAttachment<'_>>,
    ) -> RecordedRenderPass<'r> {
        let slot = self.visibility.light_slot(light);
        let mut attachments = vec![crate::gpu::color_attachment(slot.view, wgpu::LoadOp::Load)];
        attachments.extend_from_slice(more_colors);
        let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &attachments,
            depth_stencil_attachment: depth_stencil,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_blend_constant(slot.blend_constant);
        pass.set_bind_group(0, &self.frame.bind_group, &[]);
        pass.set_bind_group(1, &self.gbuffer.bind_group, &[]);
        pass
    }
}
