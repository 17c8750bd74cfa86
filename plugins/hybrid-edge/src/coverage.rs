//! Coverage maps: each shadow-map layer rendered once more, conservatively, so every texel a
//! caster touches holds the id of a triangle touching it, the one nearest the light at the
//! texel's centre (`shaders/hybrid-edge/coverage.wgsl`). The band pass tests a pixel's own
//! light ray against that triangle's plane: where the depth map's samples say lit but a caster
//! thinner than a texel may cross the ray, the pixel joins the edge band and the exact pass
//! decides.

use zoo_host::gpu::PassRecorder;
use zoo_host::kit::{bind_group, bind_group_layout, storage, texture};
use zoo_host::{RenderContext, TechniqueResult, wgpu};
use zoo_shadow_maps::{DepthState, MapArray, TilePass};

use crate::casters::CasterIdPass;

/// The coverage maps of one set of depth maps.
struct Bound {
    /// The depth maps, layer cameras and scene vertices these were made for.
    depth: wgpu::Texture,
    cameras: wgpu::Buffer,
    vertices: wgpu::Buffer,
    depth_maps: MapArray,
    ids: MapArray,
    camera_group: wgpu::BindGroup,
    lookup_group: wgpu::BindGroup,
}

/// The coverage pass's pipeline, its maps and the band pass's group over them.
pub(crate) struct CoverageMaps {
    pass: CasterIdPass,
    /// Group 4 of `fs_band`: the coverage maps' ids, the scene's vertices and indices.
    pub(crate) lookup_layout: wgpu::BindGroupLayout,
    bound: Option<Bound>,
}

/// The band shaders' bindings 0 to 2 of group 4: the coverage maps' ids, the scene's vertices
/// and indices.
pub(crate) fn coverage_entries() -> [wgpu::BindGroupLayoutEntry; 3] {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    [
        texture(
            0,
            fragment,
            wgpu::TextureSampleType::Uint,
            wgpu::TextureViewDimension::D2Array,
        ),
        storage(1, fragment, true),
        storage(2, fragment, true),
    ]
}

/// Bindings 0 to 2 of group 4 over the coverage ids `ids` and the context's scene.
pub(crate) fn coverage_resources<'a>(
    ctx: &'a RenderContext<'_>,
    ids: &'a MapArray,
) -> [wgpu::BindingResource<'a>; 3] {
    [
        wgpu::BindingResource::TextureView(&ids.array_view),
        ctx.scene_buffers.vertices.as_entire_binding(),
        ctx.scene_buffers.indices.as_entire_binding(),
    ]
}

impl CoverageMaps {
    pub(crate) fn new(ctx: &RenderContext<'_>) -> TechniqueResult<CoverageMaps> {
        let stages = ("vs_coverage", "fs_coverage");
        let shader = "hybrid-edge/coverage.wgsl";
        // Both faces, no bias: a caster's every triangle counts, whichever way it faces.
        let state = DepthState::default();
        let pass = CasterIdPass::new(ctx, "hybrid coverage", shader, stages, state)?;
        let lookup_layout = bind_group_layout(
            &ctx.gpu.device,
            "hybrid coverage lookup layout",
            &coverage_entries(),
        );
        Ok(CoverageMaps {
            pass,
            lookup_layout,
            bound: None,
        })
    }

    /// Makes coverage maps like `depth` (the depth maps, with layer cameras `cameras`) when
    /// those changed.
    pub(crate) fn prepare(
        &mut self,
        ctx: &RenderContext<'_>,
        depth: &MapArray,
        cameras: &wgpu::Buffer,
    ) {
        let current = self.bound.as_ref().is_some_and(|b| {
            b.depth == depth.texture
                && &b.cameras == cameras
                && b.vertices == ctx.scene_buffers.vertices
        });
        if current {
            return;
        }
        let depth_maps = MapArray::new(
            ctx.gpu,
            "hybrid coverage depth",
            depth.resolution,
            depth.layers,
        );
        let ids = MapArray::with_format(
            ctx.gpu,
            "hybrid coverage maps",
            depth.resolution,
            depth.layers,
            wgpu::TextureFormat::R32Uint,
        );
        let camera_group = (self.pass).camera_group(ctx, "hybrid coverage cameras", cameras);
        let lookup_group = bind_group(
            &ctx.gpu.device,
            "hybrid coverage lookup",
            &self.lookup_layout,
            &coverage_resources(ctx, &ids),
        );
        self.bound = Some(Bound {
            depth: depth.texture.clone(),
            cameras: cameras.clone(),
            vertices: ctx.scene_buffers.vertices.clone(),
            depth_maps,
            ids,
            camera_group,
            lookup_group,
        });
    }

    /// The maps' triangle ids, once prepared.
    pub(crate) fn maps(&self) -> Option<&MapArray> {
        self.bound.as_ref().map(|b| &b.ids)
    }

    /// The band pass's group over the maps and the scene's triangles (bound once prepared).
    pub(crate) fn lookup(&self) -> zoo_host::kit::NamedGroup<'_> {
        zoo_host::kit::NamedGroup {
            names: &["coverage_ids", "scene_vertices", "scene_indices"],
            layout: &self.lookup_layout,
            group: self.bound.as_ref().map(|b| &b.lookup_group),
        }
    }

    /// Renders the tile of each of `passes` into the coverage maps, one pass each named by
    /// [`TilePass::name`] with `base`, drawing the casters `reaches(light, object)` accepts.
    pub(crate) fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        passes: &[TilePass<'_>],
        base: &str,
        reaches: &dyn Fn(usize, usize) -> bool,
    ) -> TechniqueResult {
        let bound = self
            .bound
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        let maps = (&bound.ids, &bound.depth_maps);
        let cameras = &bound.camera_group;
        (self.pass).record(ctx, recorder, maps, cameras, passes, base, reaches);
        Ok(())
    }
}
