//! Translucent casters in light space: a colour map per layer of a [`ShadowMapSet`] holding
//! the smallest transmittance colour and the nearest depth of the translucent surfaces in
//! front of that layer's opaque depth (`shaders/shadow-maps/translucent.wgsl`). Build the set
//! with [`DepthState::opaque_only`](crate::DepthState::opaque_only) so the depth maps hold
//! opaque casters alone.
//!
//! A min blend keeps one colour per texel: a shadow ray through several translucent objects
//! gets the darkest one's colour in each channel, not their product (exact for one object,
//! however many of its surfaces the ray crosses).

use zoo_host::gpu::PassRecorder;
use zoo_host::kit::{SharedGroup, Stage};
use zoo_host::render::SceneBuffers;
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};

use crate::maps::{MAP_FORMAT, MapArray};
use crate::set::ShadowMapSet;

/// Format of the translucency maps: rgb transmittance, a depth (as the depth map stores it).
pub const TRANSLUCENT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The translucency maps of a shadow-map set and the pass that draws them.
pub struct TranslucentPass {
    label: String,
    stage: Stage,
    maps: Option<MapArray>,
}

impl TranslucentPass {
    /// Builds the stage (`label` names it and its maps), drawing into the layers of `set`.
    pub fn new(
        ctx: &RenderContext<'_>,
        label: &str,
        set: &ShadowMapSet,
    ) -> TechniqueResult<TranslucentPass> {
        let min = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Min,
        };
        let stage = Stage::render("shadow-maps/translucent.wgsl", "vs_translucent")
            .fragment("fs_translucent")
            .vertex_buffers(&SceneBuffers::VERTEX_LAYOUTS)
            // Behind the opaque depth nothing can be lit through them: test, never write.
            .depth_stencil(wgpu::DepthStencilState {
                format: MAP_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            })
            .targets(&[Some(wgpu::ColorTargetState {
                format: TRANSLUCENT_FORMAT,
                blend: Some(wgpu::BlendState {
                    color: min,
                    alpha: min,
                }),
                write_mask: wgpu::ColorWrites::ALL,
            })])
            .shared(&[&set.layer_camera(0)])
            .build(ctx)?;
        Ok(TranslucentPass {
            label: label.to_string(),
            stage,
            maps: None,
        })
    }

    /// Matches the maps to `set`'s depth maps; call after the set's `prepare`.
    pub fn prepare(&mut self, ctx: &RenderContext<'_>, set: &ShadowMapSet) {
        let Some(depth) = set.depth_maps() else {
            return;
        };
        let shape = (depth.resolution, depth.layers);
        if self.maps.as_ref().map(|m| (m.resolution, m.layers)) != Some(shape) {
            self.maps = Some(MapArray::with_format(
                ctx.gpu,
                &format!("{} maps", self.label),
                shape.0,
                shape.1,
                TRANSLUCENT_FORMAT,
            ));
        }
    }

    /// The maps (once prepared): one layer per depth-map layer.
    pub fn maps(&self) -> Option<&MapArray> {
        self.maps.as_ref()
    }

    /// Draws the translucent casters into every layer `set` renders (after the set's depth
    /// passes), one pass each named by [`layer_pass_name`] with `base`, as
    /// `set.pass_names(base)` lists them.
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        set: &ShadowMapSet,
        base: &str,
    ) -> TechniqueResult {
        let (Some(maps), Some(depth)) = (&self.maps, set.depth_maps()) else {
            return Err(TechniqueError::not_prepared());
        };
        for tile_pass in set.tile_passes() {
            let page = tile_pass.tile.page as usize;
            let colors = [zoo_host::gpu::color_attachment(
                &maps.layer_views[page],
                tile_pass.load_op(wgpu::Color::WHITE),
            )];
            let depth_view = &depth.layer_views[page];
            let mut pass = tile_pass.begin(recorder, base, &colors, depth_view, wgpu::LoadOp::Load);
            let camera = [&set.layer_camera(tile_pass.layer) as &dyn SharedGroup];
            self.stage.set_on(ctx, &mut pass, &[], &camera)?;
            ctx.scene_buffers
                .draw_objects_where(&mut pass, ctx.scene, |_, o| o.transmittance().is_some());
        }
        Ok(())
    }
}
