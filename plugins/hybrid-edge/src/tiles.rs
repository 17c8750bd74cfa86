//! The tile restriction: after the band pass, a compute pass lists the screen tiles that hold
//! edge pixels (`shaders/hybrid-edge/tiles.wgsl`), and the volume is drawn once per listed tile
//! and clipped to it with clip distances (`shaders/hybrid-edge/tiled_volumes.wgsl`), so no
//! volume fragment is rasterised outside the edge tiles, on any rasteriser.

use zoo_host::bytemuck;
use zoo_host::glam::UVec2;
use zoo_host::gpu::{GpuType, PassRecorder, gpu_bytes};
use zoo_host::kit::{Stage, StageBindGroup};
use zoo_host::{RenderContext, TechniqueResult, wgpu};
use zoo_shadow_volumes::{band_volume_depth_stencil, volume_stage};

zoo_host::gpu_struct! {
    "hybrid-edge/tile_params.wgsl" =>
    /// The tile grid every tile shader reads (`hybrid-edge/tiles.wgsl`,
    /// `hybrid-edge/tiled_volumes.wgsl`, `hybrid-edge/tile_overlay.wgsl`).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub(crate) struct TileParams {
        /// Tile side in pixels (a multiple of `SCAN_SIDE`).
        tile_size: u32,
        tiles_x: u32,
        tiles_y: u32,
    }
}

/// The tile list and draw arguments for one screen size and tile size.
struct Bound {
    params: TileParams,
    band: wgpu::Texture,
    args: wgpu::Buffer,
    list_group: StageBindGroup,
    draw_group: StageBindGroup,
    /// The overlay's draw: six vertices per listed tile.
    overlay_args: wgpu::Buffer,
    overlay_group: StageBindGroup,
}

/// Stages and buffers of the tile restriction.
pub(crate) struct Tiles {
    /// Lists the tiles that hold band pixels.
    list: Stage,
    /// Draws volumes into the listed tiles.
    volume: Stage,
    params: wgpu::Buffer,
    /// Debug view: the active tiles as squares.
    overlay: Stage,
    bound: Option<Bound>,
}

/// Invocations along each side of the list pass's scan of a tile (`SCAN_SIDE` in the shader,
/// its workgroup's side); tiles are a multiple of it.
const SCAN_SIDE: u32 = 8;

/// Format of the active-tiles view.
pub(crate) const OVERLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

impl Tiles {
    /// Builds the stages; volume faces are pushed back by `bias`.
    pub(crate) fn new(
        ctx: &RenderContext<'_>,
        bias: wgpu::DepthBiasState,
    ) -> TechniqueResult<Tiles> {
        let list = Stage::compute("hybrid-edge/tiles.wgsl", "cs_tiles").build(ctx)?;
        let volume = volume_stage(
            "hybrid-edge/tiled_volumes.wgsl",
            "vs_volume_tiled",
            band_volume_depth_stencil(bias),
        )
        .build(ctx)?;
        let overlay = Stage::render("hybrid-edge/tile_overlay.wgsl", "vs_tile")
            .fragment("fs_tile")
            .targets(&[Some(OVERLAY_FORMAT.into())])
            .build(ctx)?;
        let params = ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hybrid tile parameters"),
            size: TileParams::SIZE as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Tiles {
            list,
            volume,
            params,
            overlay,
            bound: None,
        })
    }

    /// Sizes the tile list for `size` pixels in tiles of `tile_size`, over the band depth
    /// image `band` (rebuilt when any of them changed).
    pub(crate) fn prepare(
        &mut self,
        ctx: &RenderContext<'_>,
        band: &wgpu::Texture,
        size: UVec2,
        tile_size: u32,
    ) -> TechniqueResult {
        // The list pass scans a tile with SCAN_SIDE x SCAN_SIDE invocations.
        let tile_size = tile_size.max(SCAN_SIDE).div_ceil(SCAN_SIDE) * SCAN_SIDE;
        let tiles = size.as_vec2() / tile_size as f32;
        let params = TileParams {
            tile_size,
            tiles_x: tiles.x.ceil() as u32,
            tiles_y: tiles.y.ceil() as u32,
        };
        if self
            .bound
            .as_ref()
            .is_some_and(|b| b.params == params && &b.band == band)
        {
            return Ok(());
        }
        ctx.gpu
            .queue
            .write_buffer(&self.params, 0, &gpu_bytes(&[params]));
        let [list, args, overlay_args] = tile_buffers(ctx, &params);
        let depth = band.create_view(&wgpu::TextureViewDescriptor {
            label: Some("hybrid band depth (depth aspect)"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        let list_group = self.list.bind(
            ctx,
            "hybrid tile list",
            &[
                ("band_depth", wgpu::BindingResource::TextureView(&depth)),
                ("tile_list", list.as_entire_binding()),
                ("draw_args", args.as_entire_binding()),
                ("params", self.params.as_entire_binding()),
            ],
        )?;
        let draw_group = self.volume.bind(
            ctx,
            "hybrid tiled volumes",
            &[
                ("tile_list", list.as_entire_binding()),
                ("params", self.params.as_entire_binding()),
            ],
        )?;
        let overlay_group = self.overlay.bind(
            ctx,
            "hybrid tile overlay",
            &[
                ("active_tiles", list.as_entire_binding()),
                ("overlay_params", self.params.as_entire_binding()),
            ],
        )?;
        self.bound = Some(Bound {
            params,
            band: band.clone(),
            args,
            list_group,
            draw_group,
            overlay_args,
            overlay_group,
        });
        Ok(())
    }

    /// Lists the edge tiles of the band depth image in compute pass `name`, once per light
    /// (its volume pieces are all drawn into the listed tiles).
    pub(crate) fn record_list(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        name: &str,
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        recorder.encoder().clear_buffer(&bound.args, 0, None);
        // One workgroup (SCAN_SIDE x SCAN_SIDE invocations) scans one tile.
        let (x, y) = (bound.params.tiles_x, bound.params.tiles_y);
        let extent = [x * SCAN_SIDE, y * SCAN_SIDE, 1];
        (self.list).dispatch(ctx, recorder, name, &[&bound.list_group], &[], extent)
    }

    /// Takes the vertex count of the volume piece just generated from `volume_args` (the
    /// generator's draw arguments) for the next [`Self::draw`].
    pub(crate) fn take_vertex_count(
        &self,
        recorder: &mut PassRecorder<'_>,
        volume_args: &wgpu::Buffer,
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        (recorder.encoder()).copy_buffer_to_buffer(volume_args, 0, &bound.args, 0, 4);
        Ok(())
    }

    /// Draws the listed tiles into `target` (the `active tiles` view), in pass `name`.
    pub(crate) fn record_overlay(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        target: &wgpu::TextureView,
        name: &str,
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        // The instance count the list pass wrote.
        (recorder.encoder()).copy_buffer_to_buffer(&bound.args, 4, &bound.overlay_args, 4, 4);
        let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &[zoo_host::gpu::color_attachment(
                target,
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            )],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        (self.overlay).set_on(ctx, &mut pass, &[&bound.overlay_group], &[])?;
        pass.draw_indirect(&bound.overlay_args, 0);
        Ok(())
    }

    /// Draws the volume piece into the listed tiles (in a pass with the band attached), with
    /// the vertex count [`Self::take_vertex_count`] took.
    pub(crate) fn draw(
        &self,
        ctx: &RenderContext<'_>,
        pass: &mut wgpu::RenderPass<'_>,
        volume: &wgpu::Buffer,
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        (self.volume).set_on(ctx, pass, &[&bound.draw_group], &[])?;
        pass.set_vertex_buffer(0, volume.slice(..));
        pass.draw_indirect(&bound.args, 0);
        Ok(())
    }
}

/// The tile list for `params`' grid, the tiled volume draw's arguments (the list pass counts
/// the instances) and the overlay's (six vertices per listed tile).
fn tile_buffers(ctx: &RenderContext<'_>, params: &TileParams) -> [wgpu::Buffer; 3] {
    let buffer = |label, size, usage| {
        ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    let tiles = u64::from(params.tiles_x * params.tiles_y).max(1);
    let list = buffer("hybrid tile list", tiles * 4, wgpu::BufferUsages::STORAGE);
    let args = buffer(
        "hybrid tiled volume draw arguments",
        16,
        wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::INDIRECT
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
    );
    let overlay_args = buffer(
        "hybrid tile overlay draw arguments",
        16,
        wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
    );
    let six_vertices: [u32; 4] = [6, 0, 0, 0];
    ctx.gpu
        .queue
        .write_buffer(&overlay_args, 0, bytemuck::cast_slice(&six_vertices));
    [list, args, overlay_args]
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn the_scan_side_is_the_shader_s() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose("hybrid-edge/tiles.wgsl")
            .unwrap()
            .source;
        let side = zoo_host::gpu::layout::wgsl_integer_constant(&source, "SCAN_SIDE");
        assert_eq!(side, Ok(i64::from(SCAN_SIDE)));
        let size = zoo_host::gpu::layout::wgsl_workgroup_size(&source, "cs_tiles");
        assert_eq!(size, Ok([SCAN_SIDE, SCAN_SIDE, 1]));
    }
}
