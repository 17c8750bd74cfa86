//! The tile restriction: after the band pass, a compute pass lists the screen tiles that hold
//! edge pixels (`shaders/hybrid-edge/tiles.wgsl`), and the volume is drawn once per listed tile
//! and clipped to it with clip distances (`shaders/hybrid-edge/tiled_volumes.wgsl`), so no
//! volume fragment is rasterised outside the edge tiles, on any rasteriser.

use zoo_host::bytemuck;
use zoo_host::glam::UVec2;
use zoo_host::gpu::{GpuType, PassRecorder, gpu_bytes};
use zoo_host::kit::{bind_group, bind_group_layout, pipeline_layout, storage, texture, uniform};
use zoo_host::{RenderContext, TechniqueResult, wgpu};
use zoo_shadow_volumes::band_volume_pipeline;

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
    compute_group: wgpu::BindGroup,
    draw_group: wgpu::BindGroup,
    /// The overlay's draw: six vertices per listed tile.
    overlay_args: wgpu::Buffer,
    overlay_group: wgpu::BindGroup,
}

/// Pipelines and buffers of the tile restriction.
pub(crate) struct Tiles {
    compute: wgpu::ComputePipeline,
    compute_layout: wgpu::BindGroupLayout,
    volume: wgpu::RenderPipeline,
    draw_layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    /// Debug view: the active tiles as squares.
    overlay: wgpu::RenderPipeline,
    bound: Option<Bound>,
}

/// Invocations along each side of the list pass's scan of a tile (`SCAN_SIDE` in the shader,
/// its workgroup's side); tiles are a multiple of it.
const SCAN_SIDE: u32 = 8;

/// Format of the active-tiles view.
pub(crate) const OVERLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

impl Tiles {
    /// Builds the pipelines; volume faces are pushed back by `bias`.
    pub(crate) fn new(
        ctx: &RenderContext<'_>,
        bias: wgpu::DepthBiasState,
    ) -> TechniqueResult<Tiles> {
        let device = &ctx.gpu.device;
        let tiles_module = ctx
            .shaders
            .create_module(device, "hybrid-edge/tiles.wgsl")?;
        let draw_module = ctx
            .shaders
            .create_module(device, "hybrid-edge/tiled_volumes.wgsl")?;
        let compute_stage = wgpu::ShaderStages::COMPUTE;
        let compute_layout = bind_group_layout(
            device,
            "hybrid tile list layout",
            &[
                texture(
                    0,
                    compute_stage,
                    wgpu::TextureSampleType::Depth,
                    wgpu::TextureViewDimension::D2,
                ),
                storage(1, compute_stage, false),
                storage(2, compute_stage, false),
                uniform(3, compute_stage),
            ],
        );
        let vertex = wgpu::ShaderStages::VERTEX;
        let draw_layout = bind_group_layout(
            device,
            "hybrid tiled volume layout",
            &[storage(0, vertex, true), uniform(1, vertex)],
        );
        let compute_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("hybrid tile list pipeline layout"),
                bind_group_layouts: &[Some(&compute_layout)],
                immediate_size: 0,
            });
        let compute = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("hybrid tile list pipeline"),
            layout: Some(&compute_pipeline_layout),
            module: &tiles_module,
            entry_point: Some("cs_tiles"),
            compilation_options: Default::default(),
            cache: None,
        });
        // The host's groups first (the shader reads only the frame's), the tiles at group 2.
        let label = "hybrid tiled volume pipeline";
        let volume = band_volume_pipeline(
            ctx,
            label,
            &draw_module,
            "vs_volume_tiled",
            &[&draw_layout],
            bias,
        );
        let overlay_module = ctx
            .shaders
            .create_module(device, "hybrid-edge/tile_overlay.wgsl")?;
        let overlay_layout = pipeline_layout(ctx, "hybrid tile overlay layout", &[&draw_layout]);
        let overlay = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("hybrid tile overlay pipeline"),
            layout: Some(&overlay_layout),
            vertex: wgpu::VertexState {
                module: &overlay_module,
                entry_point: Some("vs_tile"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &overlay_module,
                entry_point: Some("fs_tile"),
                compilation_options: Default::default(),
                targets: &[Some(OVERLAY_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hybrid tile parameters"),
            size: TileParams::SIZE as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Tiles {
            compute,
            compute_layout,
            volume,
            draw_layout,
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
    ) {
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
            return;
        }
        let device = &ctx.gpu.device;
        ctx.gpu
            .queue
            .write_buffer(&self.params, 0, &gpu_bytes(&[params]));
        let list = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hybrid tile list"),
            size: (params.tiles_x * params.tiles_y).max(1) as u64 * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hybrid tiled volume draw arguments"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let depth = band.create_view(&wgpu::TextureViewDescriptor {
            label: Some("hybrid band depth (depth aspect)"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        let compute_group = bind_group(
            device,
            "hybrid tile list",
            &self.compute_layout,
            &[
                wgpu::BindingResource::TextureView(&depth),
                list.as_entire_binding(),
                args.as_entire_binding(),
                self.params.as_entire_binding(),
            ],
        );
        let draw_group = bind_group(
            device,
            "hybrid tiled volumes",
            &self.draw_layout,
            &[list.as_entire_binding(), self.params.as_entire_binding()],
        );
        let overlay_args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hybrid tile overlay draw arguments"),
            size: 16,
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let six_vertices: [u32; 4] = [6, 0, 0, 0];
        ctx.gpu
            .queue
            .write_buffer(&overlay_args, 0, bytemuck::cast_slice(&six_vertices));
        let overlay_group = bind_group(
            device,
            "hybrid tile overlay",
            &self.draw_layout,
            &[list.as_entire_binding(), self.params.as_entire_binding()],
        );
        self.bound = Some(Bound {
            params,
            band: band.clone(),
            args,
            compute_group,
            draw_group,
            overlay_args,
            overlay_group,
        });
    }

    /// Lists the edge tiles of the band depth image in compute pass `name`, once per light
    /// (its volume pieces are all drawn into the listed tiles).
    pub(crate) fn record_list(
        &self,
        recorder: &mut PassRecorder<'_>,
        name: &str,
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        recorder.encoder().clear_buffer(&bound.args, 0, None);
        let mut pass = recorder.compute_pass(name);
        pass.set_pipeline(&self.compute);
        pass.set_bind_group(0, &bound.compute_group, &[]);
        pass.dispatch_workgroups(bound.params.tiles_x, bound.params.tiles_y, 1);
        Ok(())
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
        pass.set_pipeline(&self.overlay);
        pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
        pass.set_bind_group(1, &ctx.gbuffer.bind_group, &[]);
        pass.set_bind_group(2, &bound.overlay_group, &[]);
        pass.draw_indirect(&bound.overlay_args, 0);
        Ok(())
    }

    /// Draws the volume piece into the listed tiles (in a pass with the band attached), with
    /// the vertex count [`Self::take_vertex_count`] took.
    pub(crate) fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        volume: &wgpu::Buffer,
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        pass.set_pipeline(&self.volume);
        pass.set_bind_group(2, &bound.draw_group, &[]);
        pass.set_vertex_buffer(0, volume.slice(..));
        pass.draw_indirect(&bound.args, 0);
        Ok(())
    }
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
