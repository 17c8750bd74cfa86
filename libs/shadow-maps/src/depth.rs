//! The depth pass: every caster rendered into each layer of a [`MapArray`] from that layer's
//! camera (`shaders/shadow-maps/depth.wgsl`), optionally with a fragment stage that writes a
//! colour map as well (moments for variance shadow maps, fluxes for reflective ones).

use zoo_host::glam::{Mat4, Vec4};
use zoo_host::gpu::{GpuType, PassRecorder, gpu_bytes_padded};
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

/// The depth pipeline and the layer cameras.
pub struct DepthPass {
    label: String,
    opaque_only: bool,
    pipeline: wgpu::RenderPipeline,
    /// For alpha-tested casters (`shadow-maps/depth_masked.wgsl`), where the scene has any.
    masked_pipeline: Option<wgpu::RenderPipeline>,
    layout: wgpu::BindGroupLayout,
    clear: Option<wgpu::Color>,
    cameras: Option<(wgpu::Buffer, wgpu::BindGroup)>,
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
        let device = &ctx.gpu.device;
        let create = |shader: &str, source: Option<&str>| match source {
            None => ctx.shaders.create_module(device, shader),
            Some(text) => ctx.shaders.create_module_from_source(device, shader, text),
        };
        let module = match color {
            None => create("shadow-maps/depth.wgsl", None)?,
            Some(c) => create(c.shader, c.source)?,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
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
        let stages = |vertex, fragment| DepthStages {
            vertex,
            fragment,
            targets: &targets,
        };
        let pipeline = depth_pipeline(
            device,
            label,
            &[Some(&layout)],
            &module,
            match color {
                None => stages("vs_depth", None),
                Some(c) => stages("vs_depth_world", Some(c.entry)),
            },
            state,
        );
        // Alpha-tested casters get a pipeline of their own, only where the scene has them.
        let casts_masked =
            (ctx.scene.objects.iter()).any(|o| o.casts_shadows && o.alpha_mask.is_some());
        let masked_pipeline = match (casts_masked, color) {
            (false, _) => None,
            (true, None) => {
                let module = create("shadow-maps/depth_masked.wgsl", None)?;
                Some((module, stages("vs_depth_masked", Some("fs_depth_masked"))))
            }
            (true, Some(c)) => Some((
                module.clone(),
                stages("vs_depth_masked", Some(c.masked_entry)),
            )),
        }
        .map(|(module, stages)| {
            let materials = &ctx.scene_buffers.materials.layout;
            let groups = [Some(&layout), Some(materials)];
            depth_pipeline(
                device,
                &format!("{label} masked"),
                &groups,
                &module,
                stages,
                state,
            )
        });
        Ok(DepthPass {
            label: label.to_string(),
            opaque_only: state.opaque_only,
            pipeline,
            masked_pipeline,
            layout,
            clear: color.map(|c| c.clear),
            cameras: None,
        })
    }

    /// Uploads the layer cameras of `lights` (growing the buffer when needed). Returns whether
    /// the buffer was replaced, so bind groups that read [`Self::cameras`] must be rebuilt.
    pub fn write_cameras(&mut self, gpu: &GpuContext, lights: &[LightMaps]) -> bool {
        let mut bytes = Vec::new();
        let layers = lights.iter().flat_map(|l| l.frustums.iter().zip(&l.tiles));
        for (frustum, &tile) in layers {
            let camera = LayerCamera::new(frustum, tile);
            bytes.extend(gpu_bytes_padded(&camera, CAMERA_STRIDE as usize));
        }
        let needed = (bytes.len() as u64).max(CAMERA_STRIDE);
        let replaced = self
            .cameras
            .as_ref()
            .is_none_or(|(buffer, _)| buffer.size() < needed);
        if replaced {
            let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(&format!("{} layer cameras", self.label)),
                size: needed.next_power_of_two().max(CAMERA_STRIDE),
                usage: wgpu::BufferUsages::UNIFORM
                    | wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&format!("{} layer camera bind group", self.label)),
                layout: &self.layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &buffer,
                        offset: 0,
                        size: wgpu::BufferSize::new(LayerCamera::SIZE as u64),
                    }),
                }],
            });
            self.cameras = Some((buffer, bind_group));
        }
        if !bytes.is_empty() {
            let (buffer, _) = self.cameras.as_ref().expect("created above");
            gpu.queue.write_buffer(buffer, 0, &bytes);
        }
        replaced
    }

    /// The layer cameras (`array<LayerCamera>` with a 256-byte stride, for lookups), once
    /// written.
    pub fn cameras(&self) -> Option<&wgpu::Buffer> {
        self.cameras.as_ref().map(|(buffer, _)| buffer)
    }

    /// Records one pass per tile of `passes` (named by [`TilePass::name`] with `base`), into
    /// the depth pages of `depth` and, for a pass with a [`ColorOutput`], the colour pages of
    /// `color` (`depth` is then one scratch page, cleared with each page's first tile). Each
    /// draws the casters `reaches(light, object)` accepts.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        color: Option<&MapArray>,
        depth: &MapArray,
        passes: &[TilePass<'_>],
        base: &str,
        reaches: &dyn Fn(usize, usize) -> bool,
    ) -> Result<(), TechniqueError> {
        let (_, bind_group) = self
            .cameras
            .as_ref()
            .ok_or_else(TechniqueError::not_prepared)?;
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
            pass.set_pipeline(&self.pipeline);
            let offset = tile_pass.layer as u64 * CAMERA_STRIDE;
            pass.set_bind_group(0, bind_group, &[offset as u32]);
            let (opaque_only, light) = (self.opaque_only, tile_pass.maps.light);
            let casts = |i: usize, o: &zoo_host::scene::SceneObject| {
                o.casts_shadows
                    && !(opaque_only && o.transmittance().is_some())
                    && reaches(light, i)
            };
            let buffers = ctx.scene_buffers;
            buffers.draw_objects_masked(&mut pass, ctx.scene, false, casts);
            if let Some(masked) = &self.masked_pipeline {
                pass.set_pipeline(masked);
                pass.set_bind_group(1, &buffers.materials.bind_group, &[]);
                buffers.draw_objects_masked(&mut pass, ctx.scene, true, casts);
            }
        }
        Ok(())
    }
}

/// The entry points and colour targets of a depth pipeline.
struct DepthStages<'a> {
    vertex: &'a str,
    fragment: Option<&'a str>,
    targets: &'a [Option<wgpu::ColorTargetState>],
}

fn depth_pipeline(
    device: &wgpu::Device,
    label: &str,
    groups: &[Option<&wgpu::BindGroupLayout>],
    module: &wgpu::ShaderModule,
    stages: DepthStages<'_>,
    state: DepthState,
) -> wgpu::RenderPipeline {
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(&format!("{label} pipeline layout")),
        bind_group_layouts: groups,
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(&format!("{label} pipeline")),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(stages.vertex),
            compilation_options: Default::default(),
            buffers: &SceneBuffers::VERTEX_LAYOUTS,
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
        fragment: stages.fragment.map(|entry| wgpu::FragmentState {
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets: stages.targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}
