//! The technique's stages and the render passes of one light: a piece of its volumes counted
//! into the stencil (and, after the last, the resolve), and the debug views' overlay and
//! stencil counts.

use zoo_host::kit::{NamedTextures, Stage, TextureSpec};
use zoo_host::technique::ViewMapping;
use zoo_host::{PassRecorder, RenderContext, TechniqueError, TechniqueResult, wgpu};
use zoo_shadow_volumes::{
    COUNTS_FORMAT, Counting, StencilCounts, VolumeGenerator, resolve_stage, stencil_test,
    volume_depth_stencil, volume_stage,
};

use crate::SvParams;

/// The count view's name.
pub(crate) const COUNTS_VIEW: &str = "stencil counts";
/// The overlay view's name.
pub(crate) const OVERLAY_VIEW: &str = "volumes";

/// The debug views' textures.
pub(crate) fn debug_targets() -> NamedTextures {
    NamedTextures::new(
        "sv-zfail",
        [
            TextureSpec::screen_target(COUNTS_VIEW, COUNTS_FORMAT, Some(ViewMapping::Integer)),
            TextureSpec::screen_target(
                OVERLAY_VIEW,
                wgpu::TextureFormat::Rgba8Unorm,
                Some(ViewMapping::Color { min: 0.0, max: 1.0 }),
            ),
        ],
    )
}

/// The volume generator and every stage of the technique.
pub(crate) struct Passes {
    pub(crate) generator: VolumeGenerator,
    /// Counts a piece of volumes into the G-buffer's stencil: by z-fail, then z-pass (where
    /// the counting is `Auto`, both, chosen per light).
    volumes: Vec<(Counting, Stage)>,
    /// Shadows the pixels with a non-zero count.
    resolve: Stage,
    /// Adds volumes to the overlay view.
    overlay: Stage,
    counts: StencilCounts,
}

impl Passes {
    /// Builds every stage; the volume pass takes its biases and counting from `params`.
    pub(crate) fn new(ctx: &RenderContext<'_>, params: &SvParams) -> TechniqueResult<Passes> {
        let bias = wgpu::DepthBiasState {
            constant: params.depth_bias as i32,
            slope_scale: params.slope_bias,
            clamp: 0.0,
        };
        let countings = match params.counting {
            Counting::Auto => vec![Counting::ZFail, Counting::ZPass],
            one => vec![one],
        };
        let volumes = (countings.into_iter())
            .map(|counting| {
                let state = volume_depth_stencil(counting, bias);
                let stage = volume_stage("shadow-volumes/draw.wgsl", "vs_volume", state);
                Ok((counting, stage.build(ctx)?))
            })
            .collect::<TechniqueResult<_>>()?;
        let additive = wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::REPLACE,
        };
        let overlay = Stage::render("sv-zfail/overlay.wgsl", "vs_volume")
            .vertex_buffers(zoo_shadow_volumes::VOLUME_BUFFERS)
            .primitive(zoo_shadow_volumes::volume_primitive())
            .depth_stencil(stencil_test(wgpu::CompareFunction::Always))
            .fragment("fs_volume_debug")
            .targets(&[Some(wgpu::ColorTargetState {
                format: wgpu::TextureFormat::Rgba8Unorm,
                blend: Some(additive),
                write_mask: wgpu::ColorWrites::ALL,
            })]);
        Ok(Passes {
            generator: VolumeGenerator::new(ctx, "sv-zfail")?,
            volumes,
            resolve: resolve_stage(ctx)?,
            overlay: overlay.build(ctx)?,
            counts: StencilCounts::new(ctx)?,
        })
    }

    /// Counts the volume piece just generated into the G-buffer's stencil for `light` by
    /// `counting` (z-fail or z-pass; cleared by piece 0); after the `last` piece, writes the
    /// light's visibility 0 where the count is not 0.
    pub(crate) fn record_volume(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        (light, piece, last, counting): (usize, usize, bool, Counting),
        name: &str,
    ) -> TechniqueResult {
        let stage = (self.volumes.iter())
            .find(|(c, _)| *c == counting)
            .map(|(_, stage)| stage)
            .ok_or_else(TechniqueError::not_prepared)?;
        let (Some(volume), Some(args)) = (self.generator.volume(), self.generator.args()) else {
            return Err(TechniqueError::not_prepared());
        };
        let load = match piece {
            0 => wgpu::LoadOp::Clear(0),
            _ => wgpu::LoadOp::Load,
        };
        let stencil = zoo_host::gpu::stencil_attachment(&ctx.gbuffer.depth_view, load);
        let mut pass = ctx.light_pass(recorder, name, light, stencil);
        stage.set_on(ctx, &mut pass, &[], &[])?;
        pass.set_vertex_buffer(0, volume.slice(..));
        pass.draw_indirect(args, 0);
        if last {
            self.resolve.set_on(ctx, &mut pass, &[], &[])?;
            pass.set_stencil_reference(0);
            pass.draw(0..3, 0..1);
        }
        Ok(())
    }

    /// Adds the volume piece just generated to the overlay view (cleared by piece 0).
    pub(crate) fn record_overlay(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        (targets, piece): (&NamedTextures, usize),
        name: &str,
    ) -> TechniqueResult {
        let (Some(volume), Some(args), Some(overlay)) = (
            self.generator.volume(),
            self.generator.args(),
            targets.view(OVERLAY_VIEW),
        ) else {
            return Err(TechniqueError::not_prepared());
        };
        let load = match piece {
            0 => wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            _ => wgpu::LoadOp::Load,
        };
        let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &[zoo_host::gpu::color_attachment(overlay, load)],
            depth_stencil_attachment: zoo_host::gpu::stencil_attachment(
                &ctx.gbuffer.depth_view,
                wgpu::LoadOp::Load,
            ),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.overlay.set_on(ctx, &mut pass, &[], &[])?;
        pass.set_vertex_buffer(0, volume.slice(..));
        pass.draw_indirect(args, 0);
        Ok(())
    }

    /// Draws the light's stencil counts, after its last piece, into the count view.
    pub(crate) fn record_counts(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        targets: &NamedTextures,
        name: &str,
    ) -> TechniqueResult {
        let counts = targets
            .view(COUNTS_VIEW)
            .ok_or_else(TechniqueError::not_prepared)?;
        let stencil = &ctx.gbuffer.depth_view;
        self.counts.record(ctx, recorder, (stencil, counts), name)
    }
}
