//! Caster id maps: each shadow-map layer rendered once more from its camera, every caster
//! triangle's id written per texel, with the vertices pulled from the scene's storage buffers
//! (`shaders/hybrid-edge/casters.wgsl`). Two kinds:
//! - triangle-id maps (`shaders/hybrid-edge/ids.wgsl`): depth and the index of the front-most
//!   caster triangle per texel, rendered into the map set's depth maps in place of the
//!   library's depth pass, so the depth maps and the ids come from one rasterisation;
//! - coverage maps (`shaders/hybrid-edge/coverage.wgsl`): rendered conservatively into depth
//!   maps of their own, so every texel a caster touches holds the id of a triangle touching
//!   it, the one nearest the light at the texel's centre. The band pass tests a pixel's own
//!   light ray against that triangle's plane: where the depth map's samples say lit but a
//!   caster thinner than a texel may cross the ray, the pixel joins the edge band and the
//!   exact pass decides.

use zoo_host::gpu::{PassRecorder, gpu_bytes};
use zoo_host::kit::{SharedGroup, Stage, StageBindGroup};
use zoo_host::render::drawn_runs;
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};
use zoo_shadow_maps::{DepthState, MAP_FORMAT, MapArray, ShadowMapSet, TilePass};

use crate::NO_TRIANGLE;
use crate::closed::{ClosedCaster, closed_casters};

/// What a kind of caster id map is drawn with.
pub(crate) struct CasterIds<'a> {
    /// Names the maps and passes.
    pub(crate) label: &'a str,
    /// The library shader and its vertex and fragment entries.
    pub(crate) shader: &'a str,
    pub(crate) entries: (&'a str, &'a str),
    /// Culling and bias of the rasterisation.
    pub(crate) state: DepthState,
    /// Whether the maps have depth maps of their own (coverage), or render into the set's.
    pub(crate) own_depth: bool,
    /// Whether the shader culls the faces of closed casters turned from the light
    /// ([`crate::closed`]): it binds their boxes and orientations.
    pub(crate) closed_casters: bool,
}

/// The maps made for one set of depth maps and scene.
struct Bound {
    /// The depth maps and scene vertices these were made for.
    made_for: (wgpu::Texture, wgpu::Buffer),
    ids: MapArray,
    depth: Option<MapArray>,
    scene: StageBindGroup,
    /// The scene objects' [`ClosedCaster`]s, where the shader reads them.
    _closed: Option<wgpu::Buffer>,
}

/// A kind of caster id map: its stage and, once prepared, its maps.
pub(crate) struct CasterIdMaps {
    label: String,
    own_depth: bool,
    closed_casters: bool,
    stage: Stage,
    bound: Option<Bound>,
}

impl CasterIdMaps {
    /// Builds the stage of `ids`, reading `set`'s layer cameras.
    pub(crate) fn new(
        ctx: &RenderContext<'_>,
        set: &ShadowMapSet,
        ids: CasterIds<'_>,
    ) -> TechniqueResult<CasterIdMaps> {
        let (vertex, fragment) = ids.entries;
        let state = ids.state;
        let stage = Stage::render(ids.shader, vertex)
            .fragment(fragment)
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
            .targets(&[Some(wgpu::TextureFormat::R32Uint.into())])
            .shared(&[&set.layer_camera(0)])
            .build(ctx)?;
        Ok(CasterIdMaps {
            label: ids.label.to_string(),
            own_depth: ids.own_depth,
            closed_casters: ids.closed_casters,
            stage,
            bound: None,
        })
    }

    /// Makes maps like `depth` (the set's depth maps) when those or the scene changed;
    /// returns whether it did.
    pub(crate) fn prepare(
        &mut self,
        ctx: &RenderContext<'_>,
        depth: &MapArray,
    ) -> TechniqueResult<bool> {
        let vertices = &ctx.scene_buffers.vertices;
        let current = (self.bound.as_ref())
            .is_some_and(|b| b.made_for.0 == depth.texture && &b.made_for.1 == vertices);
        if current {
            return Ok(false);
        }
        let label = &self.label;
        let (resolution, layers) = (depth.resolution, depth.layers);
        let own_depth = (self.own_depth)
            .then(|| MapArray::new(ctx.gpu, &format!("{label} depth"), resolution, layers));
        let ids = MapArray::with_format(
            ctx.gpu,
            &format!("{label} maps"),
            resolution,
            layers,
            wgpu::TextureFormat::R32Uint,
        );
        let closed = (self.closed_casters).then(|| {
            // At least one element: a scene without objects binds a buffer too.
            let mut casters = closed_casters(ctx.scene);
            casters.resize(casters.len().max(1), ClosedCaster::default());
            let device = &ctx.gpu.device;
            wgpu::util::DeviceExt::create_buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("{label} closed casters")),
                    contents: &gpu_bytes(&casters),
                    usage: wgpu::BufferUsages::STORAGE,
                },
            )
        });
        let mut entries = vec![
            ("scene_vertices", vertices.as_entire_binding()),
            (
                "scene_indices",
                ctx.scene_buffers.indices.as_entire_binding(),
            ),
        ];
        if let Some(closed) = &closed {
            entries.push(("closed_casters", closed.as_entire_binding()));
        }
        let scene = (self.stage).bind(ctx, &format!("{label} scene triangles"), &entries)?;
        self.bound = Some(Bound {
            made_for: (depth.texture.clone(), vertices.clone()),
            ids,
            depth: own_depth,
            scene,
            _closed: closed,
        });
        Ok(true)
    }

    /// The id maps, once prepared.
    pub(crate) fn maps(&self) -> Option<&MapArray> {
        self.bound.as_ref().map(|b| &b.ids)
    }

    /// Renders the tile of each of `passes` into the id maps and the depth maps (their own,
    /// or `set`'s), one pass each named by [`TilePass::name`] with `base`, drawing the casters
    /// that can reach the tile ([`ShadowMapSet::casts_into`]).
    pub(crate) fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        set: &ShadowMapSet,
        (passes, base): (&[TilePass<'_>], &str),
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(TechniqueError::not_prepared)?;
        let depth = (bound.depth.as_ref())
            .or(set.maps())
            .ok_or_else(TechniqueError::not_prepared)?;
        let none = wgpu::Color {
            r: NO_TRIANGLE as f64,
            ..wgpu::Color::TRANSPARENT
        };
        for tile_pass in passes {
            let page = tile_pass.tile.page as usize;
            let colors = [zoo_host::gpu::color_attachment(
                &bound.ids.layer_views[page],
                tile_pass.load_op(none),
            )];
            let depth_view = &depth.layer_views[page];
            let load = tile_pass.load_op(1.0);
            let mut pass = tile_pass.begin(recorder, base, &colors, depth_view, load);
            let camera = [&set.layer_camera(tile_pass.layer) as &dyn SharedGroup];
            self.stage
                .set_on(ctx, &mut pass, &[&bound.scene], &camera)?;
            let light = &ctx.lights[tile_pass.maps.light];
            let drawn = |i, o: &zoo_host::scene::SceneObject| {
                o.casts_shadows && set.casts_into(light, tile_pass, i)
            };
            for (indices, objects) in drawn_runs(ctx.scene, drawn) {
                pass.draw(indices, objects);
            }
        }
        Ok(())
    }
}
