//! Triangle-id maps: each shadow-map layer rendered once more from its camera with vertices
//! pulled from the scene's storage buffers, writing depth and the index of the front-most
//! caster triangle per texel (`shaders/hybrid-edge/ids.wgsl`). They replace the shadow-map
//! library's depth pass, so the depth maps and the ids come from one rasterisation.

use zoo_host::gpu::PassRecorder;
use zoo_host::kit::{bind_group, bind_group_layout, texture};
use zoo_host::{RenderContext, TechniqueResult, wgpu};
use zoo_shadow_maps::{DepthState, MapArray, TilePass};

use crate::casters::CasterIdPass;
use crate::coverage::{coverage_entries, coverage_resources};

/// The id maps of one set of depth maps, and the bind groups over them.
struct Bound {
    /// The depth maps, layer cameras, scene vertices and coverage maps these were made for.
    depth: wgpu::Texture,
    cameras: wgpu::Buffer,
    vertices: wgpu::Buffer,
    coverage: wgpu::Texture,
    ids: MapArray,
    camera_group: wgpu::BindGroup,
    lookup_group: wgpu::BindGroup,
}

/// The id pass's pipeline and its bindings.
pub(crate) struct IdMaps {
    pass: CasterIdPass,
    /// Group 4 of `fs_band_ids`: the coverage maps' ids, the scene's vertices and indices, and
    /// the triangle ids.
    pub(crate) lookup_layout: wgpu::BindGroupLayout,
    bound: Option<Bound>,
}

impl IdMaps {
    /// Builds the pipeline with the depth maps' rasterisation `state`.
    pub(crate) fn new(ctx: &RenderContext<'_>, state: DepthState) -> TechniqueResult<IdMaps> {
        let device = &ctx.gpu.device;
        let stages = ("vs_ids", "fs_ids");
        let pass = CasterIdPass::new(ctx, "hybrid id map", "hybrid-edge/ids.wgsl", stages, state)?;
        let [coverage_ids, vertices, indices] = coverage_entries();
        let ids = texture(
            3,
            wgpu::ShaderStages::FRAGMENT,
            wgpu::TextureSampleType::Uint,
            wgpu::TextureViewDimension::D2Array,
        );
        let lookup_layout = bind_group_layout(
            device,
            "hybrid id lookup layout",
            &[coverage_ids, vertices, indices, ids],
        );
        Ok(IdMaps {
            pass,
            lookup_layout,
            bound: None,
        })
    }

    /// Makes id maps and bind groups for `depth` (the depth maps), `cameras` (their layer
    /// cameras) and `coverage` (their coverage maps) when they changed.
    pub(crate) fn prepare(
        &mut self,
        ctx: &RenderContext<'_>,
        depth: &MapArray,
        cameras: &wgpu::Buffer,
        coverage: &MapArray,
    ) {
        let current = self.bound.as_ref().is_some_and(|b| {
            b.depth == depth.texture
                && &b.cameras == cameras
                && b.vertices == ctx.scene_buffers.vertices
                && b.coverage == coverage.texture
        });
        if current {
            return;
        }
        let device = &ctx.gpu.device;
        let ids = MapArray::with_format(
            ctx.gpu,
            "hybrid triangle ids",
            depth.resolution,
            depth.layers,
            wgpu::TextureFormat::R32Uint,
        );
        let buffers = ctx.scene_buffers;
        let camera_group = (self.pass).camera_group(ctx, "hybrid id map cameras", cameras);
        let lookup_group = bind_group(
            device,
            "hybrid id lookup",
            &self.lookup_layout,
            &[
                coverage_resources(ctx, coverage).as_slice(),
                &[wgpu::BindingResource::TextureView(&ids.array_view)],
            ]
            .concat(),
        );
        self.bound = Some(Bound {
            depth: depth.texture.clone(),
            cameras: cameras.clone(),
            vertices: buffers.vertices.clone(),
            coverage: coverage.texture.clone(),
            ids,
            camera_group,
            lookup_group,
        });
    }

    /// The band pass's group over the maps and the scene's triangles (bound once prepared).
    pub(crate) fn lookup(&self) -> zoo_host::kit::NamedGroup<'_> {
        zoo_host::kit::NamedGroup {
            names: &[
                "coverage_ids",
                "scene_vertices",
                "scene_indices",
                "triangle_ids",
            ],
            layout: &self.lookup_layout,
            group: self.bound.as_ref().map(|b| &b.lookup_group),
        }
    }

    /// The id maps, once prepared.
    pub(crate) fn maps(&self) -> Option<&MapArray> {
        self.bound.as_ref().map(|b| &b.ids)
    }

    /// Renders the tile of each of `passes` into `depth` and the id maps, one pass each named
    /// by [`TilePass::name`] with `base`, drawing the casters `reaches(light, object)` accepts.
    pub(crate) fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        depth: &MapArray,
        passes: &[TilePass<'_>],
        base: &str,
        reaches: &dyn Fn(usize, usize) -> bool,
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        let maps = (&bound.ids, depth);
        let cameras = &bound.camera_group;
        (self.pass).record(ctx, recorder, maps, cameras, passes, base, reaches);
        Ok(())
    }
}
