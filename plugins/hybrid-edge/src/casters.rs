//! Passes that render every caster triangle's id from one shadow-map layer with the vertices
//! pulled from the scene's storage buffers (`shaders/hybrid-edge/casters.wgsl`): the
//! triangle-id maps and the coverage maps. Group 1 holds the layer camera (a dynamic offset
//! into the map set's camera buffer) and the scene's vertices and indices.

use zoo_host::gpu::{GpuType, PassRecorder};
use zoo_host::kit::{bind_group, bind_group_layout, storage};
use zoo_host::render::drawn_runs;
use zoo_host::{RenderContext, TechniqueResult, wgpu};
use zoo_shadow_maps::{CAMERA_STRIDE, DepthState, LayerCamera, MAP_FORMAT, MapArray, TilePass};

use crate::NO_TRIANGLE;

/// A pipeline that writes, per texel of each tile it renders, depth and the id of a caster
/// triangle (`R32Uint`), from the layer's camera.
pub(crate) struct CasterIdPass {
    pipeline: wgpu::RenderPipeline,
    camera_layout: wgpu::BindGroupLayout,
}

impl CasterIdPass {
    /// The pipeline of `shader`'s `vertex` and `fragment` entry points, rasterised with
    /// `state`'s culling and bias; `label` names its objects.
    pub(crate) fn new(
        ctx: &RenderContext<'_>,
        label: &str,
        shader: &str,
        (vertex, fragment): (&str, &str),
        state: DepthState,
    ) -> TechniqueResult<CasterIdPass> {
        let device = &ctx.gpu.device;
        let module = ctx.shaders.create_module(device, shader)?;
        let camera_layout = caster_layout(device, &format!("{label} camera layout"));
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label} pipeline layout")),
            bind_group_layouts: &[Some(&ctx.frame.layout), Some(&camera_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(&format!("{label} pipeline")),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vertex),
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
                entry_point: Some(fragment),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::TextureFormat::R32Uint.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(CasterIdPass {
            pipeline,
            camera_layout,
        })
    }

    /// Group 1 over the layer cameras `cameras`.
    pub(crate) fn camera_group(
        &self,
        ctx: &RenderContext<'_>,
        label: &str,
        cameras: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        caster_group(ctx, label, &self.camera_layout, cameras)
    }

    /// Renders the tile of each of `passes` into the pages of `ids` and `depth` (group 1
    /// `cameras`, from [`Self::camera_group`]), one pass each named by [`TilePass::name`] with
    /// `base`, drawing the casters `reaches(light, object)` accepts.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        (ids, depth): (&MapArray, &MapArray),
        cameras: &wgpu::BindGroup,
        passes: &[TilePass<'_>],
        base: &str,
        reaches: &dyn Fn(usize, usize) -> bool,
    ) {
        let none = wgpu::Color {
            r: NO_TRIANGLE as f64,
            ..wgpu::Color::TRANSPARENT
        };
        for tile_pass in passes {
            let page = tile_pass.tile.page as usize;
            let colors = [zoo_host::gpu::color_attachment(
                &ids.layer_views[page],
                tile_pass.load_op(none),
            )];
            let depth_view = &depth.layer_views[page];
            let mut pass =
                tile_pass.begin(recorder, base, &colors, depth_view, tile_pass.load_op(1.0));
            draw_casters(ctx, &mut pass, &self.pipeline, cameras, tile_pass, reaches);
        }
    }
}

/// Group 1 of a caster pass.
fn caster_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    let vertex = wgpu::ShaderStages::VERTEX;
    bind_group_layout(
        device,
        label,
        &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: vertex,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(LayerCamera::SIZE as u64),
                },
                count: None,
            },
            storage(1, vertex, true),
            storage(2, vertex, true),
        ],
    )
}

/// Group 1 of a caster pass over the layer cameras `cameras` and the context's scene.
fn caster_group(
    ctx: &RenderContext<'_>,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    cameras: &wgpu::Buffer,
) -> wgpu::BindGroup {
    let buffers = ctx.scene_buffers;
    bind_group(
        &ctx.gpu.device,
        label,
        layout,
        &[
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: cameras,
                offset: 0,
                size: wgpu::BufferSize::new(LayerCamera::SIZE as u64),
            }),
            buffers.vertices.as_entire_binding(),
            buffers.indices.as_entire_binding(),
        ],
    )
}

/// Draws every caster triangle `reaches(light, object)` accepts with `pipeline` from the
/// camera of `tile_pass`'s layer, each object's stored index range with the object as the
/// instance.
fn draw_casters(
    ctx: &RenderContext<'_>,
    pass: &mut wgpu::RenderPass<'_>,
    pipeline: &wgpu::RenderPipeline,
    group: &wgpu::BindGroup,
    tile_pass: &TilePass<'_>,
    reaches: &dyn Fn(usize, usize) -> bool,
) {
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
    let offset = (tile_pass.layer as u64 * CAMERA_STRIDE) as u32;
    pass.set_bind_group(1, group, &[offset]);
    let light = tile_pass.maps.light;
    for (indices, objects) in drawn_runs(ctx.scene, |i, o| o.casts_shadows && reaches(light, i)) {
        pass.draw(indices, objects);
    }
}
