//! Triangle-id maps: each shadow-map layer rendered once more from its camera with vertices
//! pulled from the scene's storage buffers, writing depth and the index of the front-most
//! caster triangle per texel (`shaders/hybrid-edge/ids.wgsl`). They replace the shadow-map
//! library's depth pass, so the depth maps and the ids come from one rasterisation.

use zoo_host::gpu::PassRecorder;
use zoo_host::kit::{bind_group, bind_group_layout, texture};
use zoo_host::{RenderContext, TechniqueResult, wgpu};
use zoo_shadow_maps::{DepthState, MAP_FORMAT, MapArray, TilePass};

use crate::NO_TRIANGLE;
use crate::casters::{caster_group, caster_layout, draw_casters};
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
    pipeline: wgpu::RenderPipeline,
    camera_layout: wgpu::BindGroupLayout,
    /// Group 4 of `fs_band_ids`: the coverage maps' ids, the scene's vertices and indices, and
    /// the triangle ids.
    pub(crate) lookup_layout: wgpu::BindGroupLayout,
    bound: Option<Bound>,
}

impl IdMaps {
    /// Builds the pipeline with the depth maps' rasterisation `state`.
    pub(crate) fn new(ctx: &RenderContext<'_>, state: DepthState) -> TechniqueResult<IdMaps> {
        let device = &ctx.gpu.device;
        let module = ctx.shaders.create_module(device, "hybrid-edge/ids.wgsl")?;
        let camera_layout = caster_layout(device, "hybrid id map camera layout");
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
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("hybrid id map pipeline layout"),
            bind_group_layouts: &[Some(&ctx.frame.layout), Some(&camera_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("hybrid id map pipeline"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_ids"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: state.cull_front.then_some(wgpu::Face::Front),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: MAP_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: Default::default(),
                bias: wgpu::DepthBiasState {
                    constant: state.constant_bias,
                    slope_scale: state.slope_bias,
                    clamp: 0.0,
                },
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_ids"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::TextureFormat::R32Uint.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(IdMaps {
            pipeline,
            camera_layout,
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
        let camera_group = caster_group(ctx, "hybrid id map cameras", &self.camera_layout, cameras);
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

    /// The band pass's group 4, once prepared.
    pub(crate) fn lookup_group(&self) -> Option<&wgpu::BindGroup> {
        self.bound.as_ref().map(|b| &b.lookup_group)
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
        let none = NO_TRIANGLE as f64;
        let clear = wgpu::Color {
            r: none,
            g: none,
            b: none,
            a: none,
        };
        for tile_pass in passes {
            let page = tile_pass.tile.page as usize;
            let colors = [zoo_host::gpu::color_attachment(
                &bound.ids.layer_views[page],
                tile_pass.load_op(clear),
            )];
            let depth_view = &depth.layer_views[page];
            let mut pass =
                tile_pass.begin(recorder, base, &colors, depth_view, tile_pass.load_op(1.0));
            draw_casters(
                ctx,
                &mut pass,
                &self.pipeline,
                &bound.camera_group,
                tile_pass,
                reaches,
            );
        }
        Ok(())
    }
}
