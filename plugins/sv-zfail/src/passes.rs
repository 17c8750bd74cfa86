//! The render passes of one light: a piece of its volumes counted into the stencil (and, after
//! the last, the resolve), and the debug views' overlay and stencil counts.

use zoo_host::{PassRecorder, RenderContext, TechniqueResult, wgpu};

use crate::pipelines::{Buffers, COUNT_LEVELS, DebugTargets, Pipelines, SLOT};

/// Counts the volume piece just generated into the G-buffer's stencil for `light` (cleared by
/// piece 0); after the `last` piece, writes the light's visibility 0 where the count is not 0.
pub(crate) fn record_volume(
    ctx: &RenderContext<'_>,
    recorder: &mut PassRecorder<'_>,
    p: &Pipelines,
    (light, piece, last): (usize, usize, bool),
    name: &str,
) -> TechniqueResult {
    let (Some(volume), Some(args)) = (p.generator.volume(), p.generator.args()) else {
        return Err(zoo_host::TechniqueError::not_prepared());
    };
    let load = match piece {
        0 => wgpu::LoadOp::Clear(0),
        _ => wgpu::LoadOp::Load,
    };
    let stencil = zoo_host::gpu::stencil_attachment(&ctx.gbuffer.depth_view, load);
    let mut pass = ctx.light_pass(recorder, name, light, stencil);
    pass.set_pipeline(&p.volume);
    pass.set_vertex_buffer(0, volume.slice(..));
    pass.draw_indirect(args, 0);
    if last {
        pass.set_pipeline(&p.resolve);
        pass.set_stencil_reference(0);
        pass.draw(0..3, 0..1);
    }
    Ok(())
}

/// A debug pass named `name` with the count and overlay views attached (`clear`ed or
/// loaded) and the G-buffer's stencil loaded.
fn debug_pass<'r>(
    recorder: &'r mut PassRecorder<'_>,
    ctx: &RenderContext<'_>,
    debug: &DebugTargets,
    [counts, overlay]: [bool; 2],
    name: &str,
) -> zoo_host::gpu::RecordedRenderPass<'r> {
    let attach = |view, clear: bool| {
        let load = match clear {
            true => wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            false => wgpu::LoadOp::Load,
        };
        zoo_host::gpu::color_attachment(view, load)
    };
    let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
        label: Some(name),
        color_attachments: &[
            attach(&debug.counts.1, counts),
            attach(&debug.overlay.1, overlay),
        ],
        depth_stencil_attachment: zoo_host::gpu::stencil_attachment(
            &ctx.gbuffer.depth_view,
            wgpu::LoadOp::Load,
        ),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
    pass
}

/// Adds the volume piece just generated to the overlay view (cleared by piece 0).
pub(crate) fn record_overlay(
    ctx: &RenderContext<'_>,
    recorder: &mut PassRecorder<'_>,
    p: &Pipelines,
    debug: &DebugTargets,
    piece: usize,
    name: &str,
) -> TechniqueResult {
    let (Some(volume), Some(args)) = (p.generator.volume(), p.generator.args()) else {
        return Err(zoo_host::TechniqueError::not_prepared());
    };
    let mut pass = debug_pass(recorder, ctx, debug, [false, piece == 0], name);
    pass.set_pipeline(&p.overlay);
    pass.set_vertex_buffer(0, volume.slice(..));
    pass.draw_indirect(args, 0);
    Ok(())
}

/// Draws the light's stencil counts, after its last piece, into the count view.
pub(crate) fn record_counts(
    ctx: &RenderContext<'_>,
    recorder: &mut PassRecorder<'_>,
    p: &Pipelines,
    b: &Buffers,
    debug: &DebugTargets,
    name: &str,
) {
    let mut pass = debug_pass(recorder, ctx, debug, [true, false], name);
    // Any non-zero count first (level 9), then the exact levels.
    pass.set_pipeline(&p.count_any);
    pass.set_stencil_reference(0);
    pass.set_bind_group(1, &b.levels_bind_group, &[0]);
    pass.draw(0..3, 0..1);
    pass.set_pipeline(&p.count_equal);
    for (k, level) in COUNT_LEVELS.iter().enumerate() {
        pass.set_stencil_reference(*level);
        pass.set_bind_group(1, &b.levels_bind_group, &[((k as u64 + 1) * SLOT) as u32]);
        pass.draw(0..3, 0..1);
    }
}
