//! The stencil-count debug view: the counts the volumes left, as integer ids.

use zoo_host::kit::Stage;
use zoo_host::{PassRecorder, RenderContext, TechniqueResult, wgpu};

use crate::stencil::{STENCIL_READ, stencil_test};

/// Format of the count view.
pub const COUNTS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Uint;

/// Stencil levels the count view distinguishes, shown as ids 1..=10: counts 1..=8, then 255
/// and 254 (-1 and -2 wrapped); any other non-zero count is id [`OTHER_COUNT`].
pub const COUNT_LEVELS: [u32; 10] = [1, 2, 3, 4, 5, 6, 7, 8, 255, 254];

/// The id of a non-zero count that is none of [`COUNT_LEVELS`].
pub const OTHER_COUNT: u32 = COUNT_LEVELS.len() as u32 + 1;

/// Draws a stencil's counts into a [`COUNTS_FORMAT`] view.
pub struct StencilCounts {
    /// Any non-zero count.
    any: Stage,
    /// The count equal to the reference.
    equal: Stage,
}

impl StencilCounts {
    /// Builds the two stages.
    pub fn new(ctx: &RenderContext<'_>) -> TechniqueResult<StencilCounts> {
        Self::reading(ctx, 0xff)
    }

    /// Builds the two stages for counts in the stencil's bits `mask` (below a mark,
    /// [`crate::MARK_BIT`]).
    pub fn reading(ctx: &RenderContext<'_>, mask: u32) -> TechniqueResult<StencilCounts> {
        let stage = |compare| {
            let mut state = stencil_test(compare);
            state.stencil.read_mask = mask;
            Stage::render(STENCIL_READ, "vs_count")
                .fragment("fs_count")
                .targets(&[Some(COUNTS_FORMAT.into())])
                .depth_stencil(state)
                .build(ctx)
        };
        Ok(StencilCounts {
            any: stage(wgpu::CompareFunction::NotEqual)?,
            equal: stage(wgpu::CompareFunction::Equal)?,
        })
    }

    /// Records pass `name`, which clears `target` and writes the id of each pixel's count in
    /// `stencil` (a depth-stencil view, loaded) into it.
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        (stencil, target): (&wgpu::TextureView, &wgpu::TextureView),
        name: &str,
    ) -> TechniqueResult {
        let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
        let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &[zoo_host::gpu::color_attachment(target, clear)],
            depth_stencil_attachment: zoo_host::gpu::stencil_attachment(
                stencil,
                wgpu::LoadOp::Load,
            ),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        // Any non-zero count first, then the exact levels over it.
        self.any.set_on(ctx, &mut pass, &[], &[])?;
        pass.set_stencil_reference(0);
        pass.draw(0..3, OTHER_COUNT..OTHER_COUNT + 1);
        self.equal.set_on(ctx, &mut pass, &[], &[])?;
        for (k, level) in COUNT_LEVELS.iter().enumerate() {
            pass.set_stencil_reference(*level);
            let id = k as u32 + 1;
            pass.draw(0..3, id..id + 1);
        }
        Ok(())
    }
}
