//! A separable Gaussian blur of colour map layers (moment maps, for example), tile by tile
//! through a one-page scratch texture, every tile of a page in one pass a direction
//! (`shaders/shadow-maps/blur.wgsl`).

use zoo_host::gpu::PassRecorder;
use zoo_host::kit::{UniformSlots, bind_group, bind_group_layout, texture};
use zoo_host::{GpuContext, RenderContext, TechniqueError, wgpu};

use crate::atlas_pages::MapTile;
use crate::maps::MapArray;
use crate::tile_pass::TilePass;

zoo_host::gpu_struct! {
    "shadow-maps/blur_params.wgsl" =>
    /// One blur step's uniform (`shadow-maps/blur.wgsl`).
    #[derive(Debug, Clone, Copy)]
    struct BlurParams {
        /// The tile read (its page of `source`).
        tile: MapTile,
        /// Taps on each side of the centre; the kernel has 2 * radius + 1.
        radius: u32,
        /// Standard deviation in texels.
        sigma: f32,
        /// 1 for the vertical pass, 0 for the horizontal one.
        vertical: u32,
    }
}

/// The scratch layer and the source bind groups for one map array.
struct Bound {
    maps: wgpu::Texture,
    scratch: MapArray,
    maps_group: wgpu::BindGroup,
    scratch_group: wgpu::BindGroup,
}

/// The blur's pipeline, its per-pass parameters and its bindings to one map array. Blurring
/// is per layer: on cube maps, kernels wider than the guard band ([`crate::CUBE_GUARD`]) do
/// not reach across face edges.
pub struct LayerBlur {
    label: String,
    format: wgpu::TextureFormat,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: UniformSlots<BlurParams>,
    bound: Option<Bound>,
}

impl LayerBlur {
    /// Builds the pipeline for maps of `format` (`label` names it).
    pub fn new(
        ctx: &RenderContext<'_>,
        label: &str,
        format: wgpu::TextureFormat,
    ) -> Result<LayerBlur, TechniqueError> {
        let device = &ctx.gpu.device;
        let module = ctx.shaders.create_module(device, "shadow-maps/blur.wgsl")?;
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let unfiltered = wgpu::TextureSampleType::Uint;
        let layout = bind_group_layout(
            device,
            &format!("{label} source layout"),
            &[texture(
                0,
                fragment,
                unfiltered,
                wgpu::TextureViewDimension::D2Array,
            )],
        );
        let params = UniformSlots::new(ctx.gpu, &format!("{label} parameters"), 2, fragment);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label} pipeline layout")),
            bind_group_layouts: &[Some(&layout), Some(params.layout())],
            immediate_size: 0,
        });
        let pipeline = zoo_host::gpu::fullscreen_pipeline(
            device,
            &format!("{label} pipeline"),
            Some(&pipeline_layout),
            &module,
            "fs_blur",
            wgpu::ColorTargetState::from(format),
        );
        Ok(LayerBlur {
            label: label.to_string(),
            format,
            pipeline,
            layout,
            params,
            bound: None,
        })
    }

    /// Blurs the tile of each of `passes` in `maps` with a Gaussian of `radius` texels on each
    /// side (standard deviation radius / 2; taps past the tile's edge repeat it); nothing for
    /// radius 0. Once per frame.
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        maps: &MapArray,
        passes: &[TilePass<'_>],
        radius: u32,
        base: &str,
    ) {
        if radius == 0 {
            // Nothing to blur: let go of the scratch (and any replaced maps it still holds).
            self.bound = None;
            return;
        }
        if self.bound.as_ref().is_none_or(|b| b.maps != maps.texture) {
            self.bound = Some(self.bind(ctx.gpu, maps));
        }
        let bound = self.bound.as_ref().expect("bound above");
        // A tile's horizontal step reads it from its page into the same texels of the scratch
        // page; its vertical step reads those back into the page.
        let step = |tile, vertical| BlurParams {
            tile,
            radius,
            sigma: radius as f32 * 0.5,
            vertical: u32::from(vertical),
        };
        let params: Vec<BlurParams> = (passes.iter())
            .flat_map(|p| {
                [
                    step(p.tile, false),
                    step(MapTile { page: 0, ..p.tile }, true),
                ]
            })
            .collect();
        self.params.write(ctx.gpu, &params);
        // One pass a page and direction, drawing every tile on the page: render passes, not
        // draws, are what a tile costs (1024 lights blurred in 128 passes instead of 2048).
        let mut pages: Vec<u32> = passes.iter().map(|p| p.tile.page).collect();
        pages.sort_unstable();
        pages.dedup();
        for page in pages {
            let on_page = || (passes.iter().enumerate()).filter(|(_, p)| p.tile.page == page);
            let steps = [
                (
                    "horizontal",
                    &bound.maps_group,
                    &bound.scratch.layer_views[0],
                ),
                (
                    "vertical",
                    &bound.scratch_group,
                    &maps.layer_views[page as usize],
                ),
            ];
            for (k, (direction, source, target)) in steps.into_iter().enumerate() {
                let label = format!("{base}: page {page} ({direction})");
                let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(&label),
                    color_attachments: &[zoo_host::gpu::color_attachment(
                        target,
                        wgpu::LoadOp::Load,
                    )],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, source, &[]);
                for (i, tile_pass) in on_page() {
                    tile_pass.tile.restrict(&mut pass);
                    let offset = self.params.offset(2 * i + k);
                    pass.set_bind_group(1, self.params.bind_group(), &[offset]);
                    pass.draw(0..3, 0..1);
                }
            }
        }
    }

    fn bind(&self, gpu: &GpuContext, maps: &MapArray) -> Bound {
        let label = &self.label;
        let scratch = MapArray::with_format(
            gpu,
            &format!("{label} scratch"),
            maps.resolution,
            1,
            self.format,
        );
        let group = |name: String, view: &wgpu::TextureView| {
            bind_group(
                &gpu.device,
                &name,
                &self.layout,
                &[wgpu::BindingResource::TextureView(view)],
            )
        };
        Bound {
            maps: maps.texture.clone(),
            maps_group: group(format!("{label} maps"), &maps.array_view),
            scratch_group: group(format!("{label} scratch"), &scratch.array_view),
            scratch,
        }
    }
}
