//! Translucent casters in light space: a colour map per layer of a [`ShadowMapSet`] holding
//! the smallest transmittance colour and the nearest depth of the translucent surfaces in
//! front of that layer's opaque depth (`shaders/shadow-maps/translucent.wgsl`). Build the set
//! with [`DepthState::opaque_only`](crate::DepthState::opaque_only) so the depth maps hold
//! opaque casters alone.
//!
//! A min blend keeps one colour per texel: a shadow ray through several translucent objects
//! gets the darkest one's colour in each channel, not their product (exact for one object,
//! however many of its surfaces the ray crosses).

use zoo_host::gpu::{GpuType, PassRecorder};
use zoo_host::render::SceneBuffers;
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};

use crate::depth::{CAMERA_STRIDE, LayerCamera};
use crate::maps::{MAP_FORMAT, MapArray};
use crate::set::ShadowMapSet;

/// Format of the translucency maps: rgb transmittance, a depth (as the depth map stores it).
pub const TRANSLUCENT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The translucency maps of a shadow-map set and the pass that draws them.
pub struct TranslucentPass {
    label: String,
    pipeline: wgpu::RenderPipeline,
    camera_layout: wgpu::BindGroupLayout,
    camera_group: Option<wgpu::BindGroup>,
    maps: Option<MapArray>,
}

impl TranslucentPass {
    /// Builds the pipeline (`label` names it and its maps).
    pub fn new(ctx: &RenderContext<'_>, label: &str) -> TechniqueResult<TranslucentPass> {
        let device = &ctx.gpu.device;
        let module = ctx
            .shaders
            .create_module(device, "shadow-maps/translucent.wgsl")?;
        let camera_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(&format!("{label} layer camera layout")),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(LayerCamera::SIZE as u64),
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label} pipeline layout")),
            bind_group_layouts: &[Some(&ctx.frame.layout), Some(&camera_layout)],
            immediate_size: 0,
        });
        let min = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Min,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(&format!("{label} pipeline")),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_translucent"),
                compilation_options: Default::default(),
                buffers: &SceneBuffers::VERTEX_LAYOUTS,
            },
            primitive: wgpu::PrimitiveState::default(),
            // Behind the opaque depth nothing can be lit through them: test, never write.
            depth_stencil: Some(wgpu::DepthStencilState {
                format: MAP_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_translucent"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: TRANSLUCENT_FORMAT,
                    blend: Some(wgpu::BlendState {
                        color: min,
                        alpha: min,
                    }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(TranslucentPass {
            label: label.to_string(),
            pipeline,
            camera_layout,
            camera_group: None,
            maps: None,
        })
    }

    /// Matches the maps to `set`'s depth maps and binds its layer cameras; call after the
    /// set's `prepare`, with what it returned (`replaced`).
    pub fn prepare(&mut self, ctx: &RenderContext<'_>, set: &ShadowMapSet, replaced: bool) {
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
        if let Some(cameras) = set.cameras()
            && (replaced || self.camera_group.is_none())
        {
            let group = ctx
                .gpu
                .device
                .create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("{} layer camera bind group", self.label)),
                    layout: &self.camera_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: cameras,
                            offset: 0,
                            size: wgpu::BufferSize::new(LayerCamera::SIZE as u64),
                        }),
                    }],
                });
            self.camera_group = Some(group);
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
        let (Some(maps), Some(group), Some(depth)) =
            (&self.maps, &self.camera_group, set.depth_maps())
        else {
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
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
            let offset = tile_pass.layer as u64 * CAMERA_STRIDE;
            pass.set_bind_group(1, group, &[offset as u32]);
            ctx.scene_buffers
                .draw_objects_where(&mut pass, ctx.scene, |_, o| o.transmittance().is_some());
        }
        Ok(())
    }
}
