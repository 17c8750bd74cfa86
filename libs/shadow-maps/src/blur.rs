//! A separable Gaussian blur of colour map layers (moment maps, for example), tile by tile
//! through a one-page scratch texture, every tile of a page in one pass a direction
//! (`shaders/shadow-maps/blur.wgsl`).

use zoo_host::gpu::PassRecorder;
use zoo_host::kit::{SharedGroup, Stage, StageBindGroup, UniformSlots};
use zoo_host::{RenderContext, TechniqueError, wgpu};

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
    maps_group: StageBindGroup,
    scratch_group: StageBindGroup,
}

/// The blur's stage, its per-pass parameters and its bindings to one map array. Blurring
/// is per layer: on cube maps, kernels wider than the guard band ([`crate::CUBE_GUARD`]) do
/// not reach across face edges.
pub struct LayerBlur {
    label: String,
    format: wgpu::TextureFormat,
    stage: Stage,
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
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let params = UniformSlots::new(ctx.gpu, &format!("{label} parameters"), 2, fragment);
        let stage = Stage::render("shadow-maps/blur.wgsl", "fullscreen_vs")
            .fragment("fs_blur")
            .targets(&[Some(wgpu::ColorTargetState::from(format))])
            .shared(&[&params.at(0)])
            .build(ctx)?;
        Ok(LayerBlur {
            label: label.to_string(),
            format,
            stage,
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
    ) -> Result<(), TechniqueError> {
        if radius == 0 {
            // Nothing to blur: let go of the scratch (and any replaced maps it still holds).
            self.bound = None;
            return Ok(());
        }
        if self.bound.as_ref().is_none_or(|b| b.maps != maps.texture) {
            self.bound = Some(self.bind(ctx, maps)?);
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
                for (i, tile_pass) in on_page() {
                    tile_pass.tile.restrict(&mut pass);
                    let step = [&self.params.at(2 * i + k) as &dyn SharedGroup];
                    self.stage.set_on(ctx, &mut pass, &[source], &step)?;
                    pass.draw(0..3, 0..1);
                }
            }
        }
        Ok(())
    }

    fn bind(&self, ctx: &RenderContext<'_>, maps: &MapArray) -> Result<Bound, TechniqueError> {
        let label = &self.label;
        let scratch = MapArray::with_format(
            ctx.gpu,
            &format!("{label} scratch"),
            maps.resolution,
            1,
            self.format,
        );
        let group = |name: String, view: &wgpu::TextureView| {
            let source = ("source", wgpu::BindingResource::TextureView(view));
            self.stage.bind(ctx, &name, &[source])
        };
        Ok(Bound {
            maps: maps.texture.clone(),
            maps_group: group(format!("{label} maps"), &maps.array_view)?,
            scratch_group: group(format!("{label} scratch"), &scratch.array_view)?,
            scratch,
        })
    }
}
