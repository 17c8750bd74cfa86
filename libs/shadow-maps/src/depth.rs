//! The depth pass: every caster rendered into each layer of a [`MapArray`] from that layer's
//! camera (`shaders/shadow-maps/depth.wgsl`), optionally with a fragment stage that writes a
//! colour map as well (moments for variance shadow maps, fluxes for reflective ones).

use zoo_host::glam::{Mat4, Vec4};
use zoo_host::gpu::{GpuType, PassRecorder};
use zoo_host::kit::{SharedGroup, Stage, StageBuilder, UniformSlot, UniformSlots};
use zoo_host::render::SceneBuffers;
use zoo_host::{GpuContext, RenderContext, TechniqueError, wgpu};

use crate::atlas_pages::MapTile;
use crate::light_space::{LightFrustum, Projection};
use crate::maps::{MAP_FORMAT, MapArray};
use crate::planning::LightMaps;
use crate::tile_pass::TilePass;

/// Bytes between layer cameras: a uniform dynamic-offset slot, and `LayerCamera` as an array
/// element for lookups that project into any layer.
pub const CAMERA_STRIDE: u64 = 256;

zoo_host::gpu_struct! {
    "shadow-maps/layer_camera.wgsl" =>
    /// One layer's camera (`shadow-maps/layers.wgsl` reads it): the depth pass's uniform, and
    /// an array element of [`CAMERA_STRIDE`]-byte slots for lookups.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct LayerCamera {
        pub view_proj: Mat4,
        /// Perspective layers: the light's position and 1 / far; orthographic layers: w = 0.
        pub eye: Vec4,
        /// Clip space back to world space (to unproject stored depths).
        pub inv_view_proj: Mat4,
        /// Where the layer's map lies in the atlas.
        pub tile: MapTile,
    }
}

// A camera fills at most its slot, a dynamic offset's multiple.
const _: () = assert!(CAMERA_STRIDE.is_multiple_of(256));
const _: () = assert!(LayerCamera::SIZE <= CAMERA_STRIDE as usize);

impl LayerCamera {
    /// The camera of `frustum`, rendering into `tile`.
    pub fn new(frustum: &LightFrustum, tile: MapTile) -> LayerCamera {
        let eye = match frustum.projection {
            Projection::Perspective { far, .. } => {
                frustum.view.inverse().w_axis.truncate().extend(1.0 / far)
            }
            Projection::Orthographic { .. } | Projection::Warped => Vec4::ZERO,
        };
        LayerCamera {
            view_proj: frustum.view_proj,
            eye,
            inv_view_proj: frustum.view_proj.inverse(),
            tile,
        }
    }
}

/// A fragment stage that writes a colour map beside the depth: entry `entry` of shader
/// `shader`, which imports `shadow-maps/depth.wgsl` and takes its `DepthVertex`.
#[derive(Debug, Clone, Copy)]
pub struct ColorOutput<'a> {
    /// The library shader, or the label of `source`.
    pub shader: &'a str,
    /// WGSL to compose instead of the file `shader` (with `#import`s of the library: a moment
    /// method and the pass that calls it, for example).
    pub source: Option<&'a str>,
    pub entry: &'a str,
    /// The entry for alpha-tested casters, which takes `MaskedVertex` from
    /// `shadow-maps/depth_masked.wgsl` (which the shader must import) and discards holes.
    pub masked_entry: &'a str,
    pub format: wgpu::TextureFormat,
    /// What texels no caster covers hold.
    pub clear: wgpu::Color,
}

/// Rasterisation state of the depth pass (the default: no bias, no culling).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DepthState {
    /// Constant depth bias, in units of the depth format's resolution.
    pub constant_bias: i32,
    /// Slope-scaled depth bias.
    pub slope_bias: f32,
    /// Store back faces (cull front faces).
    pub cull_front: bool,
    /// Leave translucent casters out (for techniques that draw them into a transmittance map,
    /// [`crate::TranslucentPass`]); by default they are drawn as opaque.
    pub opaque_only: bool,
}

/// The depth stages and the layer cameras.
pub struct DepthPass {
    opaque_only: bool,
    stage: Stage,
    /// For alpha-tested casters (`shadow-maps/depth_masked.wgsl`), where the scene has any.
    masked_stage: Option<Stage>,
    clear: Option<wgpu::Color>,
    cameras: UniformSlots<LayerCamera>,
    /// Whether the cameras were written.
    written: bool,
}

impl DepthPass {
    /// Builds the pipeline (`label` names it and its layouts), with a colour map written by
    /// `color` when given.
    pub fn new(
        ctx: &RenderContext<'_>,
        label: &str,
        state: DepthState,
        color: Option<ColorOutput<'_>>,
    ) -> Result<DepthPass, TechniqueError> {
        let visibility = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let cameras_label = format!("{label} layer cameras");
        let cameras =
            UniformSlots::readable_as_array(ctx.gpu, &cameras_label, 1, visibility, CAMERA_STRIDE);
        let targets: Vec<_> = color
            .map(|c| {
                Some(wgpu::ColorTargetState {
                    format: c.format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })
            })
            .into_iter()
            .collect();
        let camera = cameras.at(0);
        let stage = |shader, text, vertex, fragment: Option<&str>| {
            let mut stage = depth_stage(Stage::render(shader, vertex), state)
                .targets(&targets)
                .shared(&[&camera]);
            if let Some(entry) = fragment {
                stage = stage.fragment(entry);
            }
            if let Some(text) = text {
                stage = stage.text(text);
            }
            stage.build(ctx)
        };
        let main = match color {
            None => stage("shadow-maps/depth.wgsl", None, "vs_depth", None),
            Some(c) => stage(c.shader, c.source, "vs_depth_world", Some(c.entry)),
        }?;
        // Alpha-tested casters get a stage of their own, only where the scene has them.
        let casts_masked =
            (ctx.scene.objects.iter()).any(|o| o.casts_shadows && o.alpha_mask.is_some());
        let masked_stage = match (casts_masked, color) {
            (false, _) => None,
            (true, None) => Some(stage(
                "shadow-maps/depth_masked.wgsl",
                None,
                "vs_depth_masked",
                Some("fs_depth_masked"),
            )?),
            (true, Some(c)) => Some(stage(
                c.shader,
                c.source,
                "vs_depth_masked",
                Some(c.masked_entry),
            )?),
        };
        Ok(DepthPass {
            opaque_only: state.opaque_only,
            stage: main,
            masked_stage,
            clear: color.map(|c| c.clear),
            cameras,
            written: false,
        })
    }

    /// Uploads the layer cameras of `lights` (growing the buffer when needed). Returns whether
    /// the buffer was replaced, so bind groups that read [`Self::cameras`] must be rebuilt.
    pub fn write_cameras(&mut self, gpu: &GpuContext, lights: &[LightMaps]) -> bool {
        let layers = lights.iter().flat_map(|l| l.frustums.iter().zip(&l.tiles));
        let cameras: Vec<LayerCamera> = layers
            .map(|(frustum, &tile)| LayerCamera::new(frustum, tile))
            .collect();
        let replaced = self.cameras.write(gpu, &cameras) || !self.written;
        self.written = true;
        replaced
    }

    /// Layer `layer`'s camera, as the group of stages that read one `LayerCamera`.
    pub fn camera(&self, layer: u32) -> UniformSlot<'_, LayerCamera> {
        self.cameras.at(layer as usize)
    }

    /// The layer cameras (`array<LayerCamera>` with a 256-byte stride, for lookups), once
    /// written.
    pub fn cameras(&self) -> Option<&wgpu::Buffer> {
        self.written.then(|| self.cameras.buffer())
    }

    /// Records one pass per tile of `passes` (named by [`TilePass::name`] with `base`), into
    /// the depth pages of `depth` and, for a pass with a [`ColorOutput`], the colour pages of
    /// `color` (`depth` is then one scratch page, cleared with each page's first tile). Each
    /// draws the casters `casts_into(pass, object)` accepts.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        color: Option<&MapArray>,
        depth: &MapArray,
        passes: &[TilePass<'_>],
        base: &str,
        casts_into: &dyn Fn(&TilePass<'_>, usize) -> bool,
    ) -> Result<(), TechniqueError> {
        if !self.written {
            return Err(TechniqueError::not_prepared());
        }
        if color.is_some() != self.clear.is_some() {
            return Err(TechniqueError::Other(
                "depth pass: colour maps go with a ColorOutput".into(),
            ));
        }
        for tile_pass in passes {
            let page = tile_pass.tile.page as usize;
            let clear = tile_pass.load_op(self.clear.unwrap_or_default());
            let colors: Vec<_> = color
                .map(|c| zoo_host::gpu::color_attachment(&c.layer_views[page], clear))
                .into_iter()
                .collect();
            let depth_page = if color.is_some() { 0 } else { page };
            let depth_view = &depth.layer_views[depth_page];
            let mut pass =
                tile_pass.begin(recorder, base, &colors, depth_view, tile_pass.load_op(1.0));
            let camera = [&self.camera(tile_pass.layer) as &dyn SharedGroup];
            self.stage.set_on(ctx, &mut pass, &[], &camera)?;
            let opaque_only = self.opaque_only;
            let casts = |i: usize, o: &zoo_host::scene::SceneObject| {
                o.casts_shadows
                    && !(opaque_only && o.transmittance().is_some())
                    && casts_into(tile_pass, i)
            };
            let buffers = ctx.scene_buffers;
            buffers.draw_objects_masked(&mut pass, ctx.scene, false, casts);
            if let Some(masked) = &self.masked_stage {
                masked.set_on(ctx, &mut pass, &[], &camera)?;
                buffers.draw_objects_masked(&mut pass, ctx.scene, true, casts);
            }
        }
        Ok(())
    }
}

/// `stage` with the scene's vertices, faces culled and depth written and biased as `state`
/// says.
fn depth_stage(stage: StageBuilder<'_>, state: DepthState) -> StageBuilder<'_> {
    stage
        .vertex_buffers(&SceneBuffers::VERTEX_LAYOUTS)
        .primitive(wgpu::PrimitiveState {
            cull_mode: state.cull_front.then_some(wgpu::Face::Front),
            ..Default::default()
        })
        .depth_stencil(wgpu::DepthStencilState {
            format: MAP_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: Default::default(),
            bias: wgpu::DepthBiasState {
                constant: state.constant_bias,
                slope_scale: state.slope_bias,
                clamp: 0.0,
            },
        })
}
