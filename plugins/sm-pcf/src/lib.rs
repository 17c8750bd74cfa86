//! Shadow maps with percentage-closer filtering (seed 000 section 7, seed 004 sections 3.4 and
//! 9.1), with PCSS as the soft research variant.
//!
//! Each light renders its casters into depth layers of one `Depth32Float` array: spot lights
//! through a perspective frustum fitted to the cone, directional lights through an orthographic
//! box fitted to what the camera sees and the casters that can shadow it, point lights into six
//! cube faces widened by a guard band. A full-screen pass per light then compares each pixel's
//! light-space depth with the map and writes the light's visibility. Points outside a map are
//! lit. Bias: constant and slope-scaled pipeline depth bias, normal offset in texels, and
//! optional front-face culling in the depth pass.

pub mod light_space;

use bytemuck::{Pod, Zeroable};
use zoo_host::glam::{UVec2, Vec3};
use zoo_host::params::TechniqueParams;
use zoo_host::render::Vertex;
use zoo_host::scene::{Light, LightKind, Scene};
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_host::{
    Changes, GpuContext, ParamUpdate, ParamValues, PassInfo, PassRecorder, RenderContext,
    ShadowTechnique, TechniqueError, wgpu,
};

use crate::light_space::{
    Aabb, LightFrustum, Projection, cube_frustums, directional_frustum, spot_frustum,
};

zoo_host::param_choice! {
    /// How shadow-map comparisons are filtered.
    pub enum Filter { None, Hardware2x2, Pcf3x3, Pcf5x5, Pcf7x7, Pcf9x9, Poisson, Pcss }
}

zoo_host::technique_params! {
    /// Parameters of shadow maps with PCF.
    pub struct SmParams {
        /// Shadow-map resolution in texels per side (clamped to the device limit).
        map_size: u32 = 2048, range(256, 8192), step(256);
        /// Filter: none, hardware 2x2, N x N grid PCF, rotated Poisson disc, or PCSS.
        filter: Filter = Filter::Pcf3x3;
        /// Constant depth bias of the depth pass, in units of the depth format's resolution.
        constant_bias: u32 = 0, range(0, 100000), step(100);
        /// Slope-scaled depth bias of the depth pass (times the polygon's depth slope).
        slope_bias: f32 = 1.5, range(0.0, 10.0), step(0.1);
        /// Normal offset: lookups move off the surface by this many shadow-map texels.
        normal_offset: f32 = 1.5, range(0.0, 8.0), step(0.1);
        /// Cull front faces in the depth pass (stores back faces).
        cull_front: bool = false;
        /// Keep directional maps stable as the camera moves (extent on a geometric ladder, centre
        /// snapped to whole texels), so shadow edges do not shimmer.
        stable_fit: bool = true;
        /// Poisson disc radius in texels.
        kernel_radius: f32 = 2.0, range(0.5, 16.0), step(0.5);
        /// Largest PCSS blocker search and penumbra radius, in texels.
        pcss_max_texels: f32 = 24.0, range(2.0, 64.0), step(1.0);
        /// Light whose maps and diagnostics the debug views show.
        debug_light: u32 = 0, range(0, 1023), step(1);
    }
}

impl Filter {
    fn code(self) -> u32 {
        Filter::NAMES
            .iter()
            .position(|n| *n == self.name())
            .expect("every variant is named") as u32
    }
}

/// `Slot` in `sm-pcf/lookup.wgsl` and `LayerCamera` in `depth.wgsl`: 256 bytes.
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
#[repr(C)]
struct Slot {
    view_proj: [[f32; 4]; 4],
    _pad: [[f32; 4]; 12],
}

/// `ShadowLight` in `sm-pcf/lookup.wgsl`.
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
#[repr(C)]
struct ShadowLight {
    first_layer: u32,
    layer_count: u32,
    filter_mode: u32,
    light: u32,
    texel_scale: f32,
    perspective: u32,
    near: f32,
    far: f32,
    normal_offset: f32,
    kernel_texels: f32,
    light_size: f32,
    map_size: f32,
    position: [f32; 3],
    search_texels: f32,
    direction: [f32; 3],
    _pad: f32,
}

/// `Current` in `sm-pcf/lookup.wgsl`, in a 256-byte slot.
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
#[repr(C)]
struct Current {
    index: u32,
    debug: u32,
    _pad: [u32; 62],
}

const SLOT: u64 = 256;
const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const DIAGNOSTICS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Texels of guard band around each cube face (covers bilinear taps across face edges).
const CUBE_GUARD: u32 = 2;
/// Shadow maps are kept under this many bytes; the resolution drops to fit.
const MEMORY_BUDGET: u64 = 1 << 30;

/// One light's layers.
#[derive(Debug, Clone)]
struct LightMaps {
    light: usize,
    first_layer: u32,
    frustums: Vec<LightFrustum>,
    /// Screen rectangle (x, y, width, height) its lookup pass can touch.
    scissor: [u32; 4],
}

/// The screen rectangle covering `light`'s range sphere (the whole screen for directional
/// lights or when the sphere reaches behind the camera); width 0 when it is off screen.
pub fn light_scissor(light: &Light, view_proj: zoo_host::glam::Mat4, size: UVec2) -> [u32; 4] {
    let full = [0, 0, size.x, size.y];
    if light.kind == LightKind::Directional {
        return full;
    }
    let (mut lo, mut hi) = (
        zoo_host::glam::Vec2::splat(f32::INFINITY),
        zoo_host::glam::Vec2::splat(f32::NEG_INFINITY),
    );
    for i in 0..8 {
        let corner = light.position
            + light.range
                * Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                );
        let clip = view_proj * corner.extend(1.0);
        if clip.w <= 1e-4 {
            return full;
        }
        let ndc = clip.truncate().truncate() / clip.w;
        let pixel = zoo_host::glam::Vec2::new(
            (ndc.x * 0.5 + 0.5) * size.x as f32,
            (0.5 - ndc.y * 0.5) * size.y as f32,
        );
        lo = lo.min(pixel);
        hi = hi.max(pixel);
    }
    let x0 = lo.x.floor().clamp(0.0, size.x as f32) as u32;
    let y0 = lo.y.floor().clamp(0.0, size.y as f32) as u32;
    let x1 = hi.x.ceil().clamp(0.0, size.x as f32) as u32;
    let y1 = hi.y.ceil().clamp(0.0, size.y as f32) as u32;
    [x0, y0, x1.saturating_sub(x0), y1.saturating_sub(y0)]
}

struct Pipelines {
    depth: wgpu::RenderPipeline,
    depth_layout: wgpu::BindGroupLayout,
    /// Without and with diagnostics output; each writes the light's slot (`kit::slot_target`).
    lookup: Vec<wgpu::RenderPipeline>,
    lookup_layout: wgpu::BindGroupLayout,
}

struct Maps {
    resolution: u32,
    /// Layers in use (the texture may hold a spare one, see `zoo_host::gpu::array_layers`).
    layers: u32,
    texture: wgpu::Texture,
    layer_views: Vec<wgpu::TextureView>,
    array_view: wgpu::TextureView,
}

struct Buffers {
    slots: wgpu::Buffer,
    lights: wgpu::Buffer,
    current: wgpu::Buffer,
    depth_bind_group: wgpu::BindGroup,
    lookup_bind_group: wgpu::BindGroup,
}

/// Shadow maps with PCF.
pub struct ShadowMaps {
    params: SmParams,
    pipelines: Option<Pipelines>,
    maps: Option<Maps>,
    buffers: Option<Buffers>,
    diagnostics: Option<(wgpu::Texture, wgpu::TextureView)>,
    samplers: Option<(wgpu::Sampler, wgpu::Sampler)>,
    lights: Vec<LightMaps>,
    /// World bounds of every object and of each caster, for fitting directional maps.
    object_bounds: Vec<Aabb>,
    caster_bounds: Vec<Aabb>,
}

/// World-space bounds of the objects (only shadow casters when `casters_only`).
fn object_bounds(scene: &Scene, casters_only: bool) -> Vec<Aabb> {
    scene
        .objects
        .iter()
        .filter(|o| o.casts_shadows || !casters_only)
        .filter_map(|o| {
            let points: Vec<Vec3> = scene.mesh.indices[o.indices.clone()]
                .iter()
                .map(|&i| scene.mesh.positions[i as usize])
                .collect();
            zoo_host::scene::mesh::bounds(&points)
        })
        .collect()
}

/// The resolution to use: the requested one clamped to the device and the memory budget.
pub fn effective_resolution(requested: u32, device_max: u32, layers: u32) -> (u32, Option<String>) {
    let mut resolution = requested.min(device_max);
    let mut note = (resolution < requested).then(|| {
        format!("sm-pcf: map_size {requested} exceeds the device limit; using {resolution}")
    });
    while resolution > 256 && layers as u64 * (resolution as u64).pow(2) * 4 > MEMORY_BUDGET {
        resolution /= 2;
        note = Some(format!(
            "sm-pcf: {layers} map layers at {requested} texels exceed {} MiB; using {resolution}",
            MEMORY_BUDGET >> 20
        ));
    }
    (resolution, note)
}

fn light_size(light: &Light) -> f32 {
    match light.kind {
        LightKind::Directional => light.radius.tan(),
        _ => light.radius,
    }
}

impl ShadowMaps {
    fn create_pipelines(&self, ctx: &RenderContext<'_>) -> Result<Pipelines, TechniqueError> {
        let device = &ctx.gpu.device;
        let depth_module = ctx.shaders.create_module(device, "sm-pcf/depth.wgsl")?;
        let lookup_module = ctx.shaders.create_module(device, "sm-pcf/lookup.wgsl")?;
        let depth_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sm-pcf depth layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(64),
                },
                count: None,
            }],
        });
        let depth_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sm-pcf depth pipeline layout"),
                bind_group_layouts: &[Some(&depth_layout)],
                immediate_size: 0,
            });
        let depth = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("sm-pcf depth pipeline"),
            layout: Some(&depth_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &depth_module,
                entry_point: Some("vs_depth"),
                compilation_options: Default::default(),
                buffers: &[Some(Vertex::LAYOUT)],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: self.params.cull_front.then_some(wgpu::Face::Front),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: MAP_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: Default::default(),
                bias: wgpu::DepthBiasState {
                    constant: self.params.constant_bias as i32,
                    slope_scale: self.params.slope_bias,
                    clamp: 0.0,
                },
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });

        let texture_entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty,
            count: None,
        };
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let lookup_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sm-pcf lookup layout"),
            entries: &[
                texture_entry(
                    0,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                ),
                texture_entry(
                    1,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                ),
                texture_entry(
                    2,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                ),
                texture_entry(3, storage),
                texture_entry(4, storage),
                texture_entry(
                    5,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(16),
                    },
                ),
                // The same maps as plain floats, for reading stored depths (GLSL cannot fetch
                // texels of depth textures).
                texture_entry(
                    6,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                ),
                // And once more for the nearest comparison sampler (GLSL pairs each texture
                // with one sampler).
                texture_entry(
                    7,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                ),
            ],
        });
        let lookup_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sm-pcf lookup pipeline layout"),
                bind_group_layouts: &[
                    Some(&ctx.frame.layout),
                    Some(&ctx.gbuffer.layout),
                    Some(&lookup_layout),
                ],
                immediate_size: 0,
            });
        let lookup = [false, true]
            .into_iter()
            .map(|diagnostics| {
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(if diagnostics {
                        "sm-pcf lookup pipeline (diagnostics)"
                    } else {
                        "sm-pcf lookup pipeline"
                    }),
                    layout: Some(&lookup_pipeline_layout),
                    vertex: wgpu::VertexState {
                        module: &lookup_module,
                        entry_point: Some("fullscreen_vs"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: Default::default(),
                    depth_stencil: None,
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &lookup_module,
                        entry_point: Some("fs_lookup"),
                        compilation_options: Default::default(),
                        targets: &[
                            Some(zoo_host::kit::slot_target()),
                            Some(wgpu::ColorTargetState {
                                format: DIAGNOSTICS_FORMAT,
                                blend: None,
                                write_mask: if diagnostics {
                                    wgpu::ColorWrites::ALL
                                } else {
                                    wgpu::ColorWrites::empty()
                                },
                            }),
                        ],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            })
            .collect();
        Ok(Pipelines {
            depth,
            depth_layout,
            lookup,
            lookup_layout,
        })
    }

    /// Plans layers for every light and (re)creates the map array when its size changes.
    fn plan_maps(&mut self, ctx: &RenderContext<'_>) {
        let layers_needed: u32 = ctx
            .lights
            .iter()
            .map(|l| if l.kind == LightKind::Point { 6 } else { 1 })
            .sum::<u32>()
            .max(1);
        let device_max = ctx.gpu.device.limits().max_texture_dimension_2d;
        let (resolution, note) =
            effective_resolution(self.params.map_size, device_max, layers_needed);
        if let Some(note) = note {
            zoo_host::log::warn!("{note}");
        }
        let layers_allocated =
            zoo_host::gpu::array_layers(ctx.gpu, resolution, resolution, layers_needed);
        let reuse = self
            .maps
            .as_ref()
            .is_some_and(|m| m.resolution == resolution && m.layers == layers_needed);
        if !reuse {
            let texture = ctx.gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("sm-pcf shadow maps"),
                size: wgpu::Extent3d {
                    width: resolution,
                    height: resolution,
                    depth_or_array_layers: layers_allocated,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: MAP_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            let layer_views = (0..layers_needed)
                .map(|layer| {
                    texture.create_view(&wgpu::TextureViewDescriptor {
                        label: Some(&format!("sm-pcf shadow map layer {layer}")),
                        dimension: Some(wgpu::TextureViewDimension::D2),
                        base_array_layer: layer,
                        array_layer_count: Some(1),
                        ..Default::default()
                    })
                })
                .collect();
            let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some("sm-pcf shadow maps (array)"),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                array_layer_count: Some(layers_needed),
                ..Default::default()
            });
            self.maps = Some(Maps {
                resolution,
                layers: layers_needed,
                texture,
                layer_views,
                array_view,
            });
            self.buffers = None;
        }
    }

    /// Fits every light's frustums to the current lights and camera and uploads them.
    fn fit(&mut self, ctx: &RenderContext<'_>) {
        let resolution = self.maps.as_ref().expect("maps planned").resolution;
        let aspect = ctx.size.x as f32 / ctx.size.y.max(1) as f32;
        let mut next_layer = 0;
        self.lights = ctx
            .lights
            .iter()
            .enumerate()
            .map(|(i, light)| {
                let frustums = match light.kind {
                    LightKind::Spot => vec![spot_frustum(light)],
                    LightKind::Point => cube_frustums(light, resolution, CUBE_GUARD).to_vec(),
                    LightKind::Directional => vec![directional_frustum(
                        light.direction,
                        ctx.camera,
                        aspect,
                        &self.object_bounds,
                        &self.caster_bounds,
                        self.params.stable_fit.then_some(resolution),
                    )],
                };
                let maps = LightMaps {
                    light: i,
                    first_layer: next_layer,
                    frustums,
                    scissor: light_scissor(light, ctx.frame.matrices.view_proj, ctx.size),
                };
                next_layer += maps.frustums.len() as u32;
                maps
            })
            .collect();

        let slots: Vec<Slot> = self
            .lights
            .iter()
            .flat_map(|l| &l.frustums)
            .map(|f| Slot {
                view_proj: f.view_proj.to_cols_array_2d(),
                _pad: [[0.0; 4]; 12],
            })
            .collect();
        let shadow_lights: Vec<ShadowLight> = self
            .lights
            .iter()
            .map(|maps| {
                let light = &ctx.lights[maps.light];
                let (texel_scale, perspective, near, far) = match maps.frustums[0].projection {
                    Projection::Perspective {
                        tan_half_fov,
                        near,
                        far,
                    } => (2.0 * tan_half_fov / resolution as f32, 1, near, far),
                    Projection::Orthographic { extent, near, far } => {
                        (extent / resolution as f32, 0, near, far)
                    }
                };
                ShadowLight {
                    first_layer: maps.first_layer,
                    layer_count: maps.frustums.len() as u32,
                    filter_mode: self.params.filter.code(),
                    light: maps.light as u32,
                    texel_scale,
                    perspective,
                    near,
                    far,
                    normal_offset: self.params.normal_offset,
                    kernel_texels: self.params.kernel_radius,
                    light_size: light_size(light),
                    map_size: resolution as f32,
                    position: light.position.to_array(),
                    search_texels: self.params.pcss_max_texels,
                    direction: light.direction.to_array(),
                    _pad: 0.0,
                }
            })
            .collect();
        let currents: Vec<Current> = (0..self.lights.len())
            .map(|i| Current {
                index: i as u32,
                debug: u32::from(i as u32 == self.params.debug_light),
                _pad: [0; 62],
            })
            .collect();

        let queue = &ctx.gpu.queue;
        let fits = |buffer: &wgpu::Buffer, bytes: usize| buffer.size() >= bytes.max(16) as u64;
        let slot_bytes = size_of_val(slots.as_slice());
        let light_bytes = size_of_val(shadow_lights.as_slice());
        let current_bytes = size_of_val(currents.as_slice());
        if !self.buffers.as_ref().is_some_and(|b| {
            fits(&b.slots, slot_bytes)
                && fits(&b.lights, light_bytes)
                && fits(&b.current, current_bytes)
        }) {
            self.buffers = Some(self.create_buffers(ctx, slot_bytes, light_bytes, current_bytes));
        }
        let buffers = self.buffers.as_ref().expect("created above");
        if !slots.is_empty() {
            queue.write_buffer(&buffers.slots, 0, bytemuck::cast_slice(&slots));
            queue.write_buffer(&buffers.lights, 0, bytemuck::cast_slice(&shadow_lights));
            queue.write_buffer(&buffers.current, 0, bytemuck::cast_slice(&currents));
        }
    }

    fn create_buffers(
        &self,
        ctx: &RenderContext<'_>,
        slot_bytes: usize,
        light_bytes: usize,
        current_bytes: usize,
    ) -> Buffers {
        let device = &ctx.gpu.device;
        let pipelines = self.pipelines.as_ref().expect("pipelines exist");
        let maps = self.maps.as_ref().expect("maps exist");
        let (linear, nearest) = self.samplers.as_ref().expect("samplers exist");
        let buffer = |label: &str, bytes: usize, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (bytes.max(SLOT as usize) as u64).next_multiple_of(SLOT),
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let slots = buffer(
            "sm-pcf layer cameras",
            slot_bytes,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::STORAGE,
        );
        let lights = buffer(
            "sm-pcf shadow lights",
            light_bytes,
            wgpu::BufferUsages::STORAGE,
        );
        let current = buffer(
            "sm-pcf current light",
            current_bytes,
            wgpu::BufferUsages::UNIFORM,
        );
        let depth_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sm-pcf depth bind group"),
            layout: &pipelines.depth_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &slots,
                    offset: 0,
                    size: wgpu::BufferSize::new(64),
                }),
            }],
        });
        let lookup_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sm-pcf lookup bind group"),
            layout: &pipelines.lookup_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&maps.array_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(linear),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(nearest),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: slots.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: lights.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &current,
                        offset: 0,
                        size: wgpu::BufferSize::new(16),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::TextureView(&maps.array_view),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: wgpu::BindingResource::TextureView(&maps.array_view),
                },
            ],
        });
        Buffers {
            slots,
            lights,
            current,
            depth_bind_group,
            lookup_bind_group,
        }
    }

    fn create_samplers(device: &wgpu::Device) -> (wgpu::Sampler, wgpu::Sampler) {
        let sampler = |label, filter| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                address_mode_u: wgpu::AddressMode::ClampToEdge,
                address_mode_v: wgpu::AddressMode::ClampToEdge,
                mag_filter: filter,
                min_filter: filter,
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..Default::default()
            })
        };
        (
            sampler("sm-pcf compare sampler (linear)", wgpu::FilterMode::Linear),
            sampler(
                "sm-pcf compare sampler (nearest)",
                wgpu::FilterMode::Nearest,
            ),
        )
    }

    fn diagnostics_texture(
        device: &wgpu::Device,
        size: UVec2,
    ) -> (wgpu::Texture, wgpu::TextureView) {
        zoo_host::gpu::render_target(
            device,
            "sm-pcf diagnostics",
            size,
            DIAGNOSTICS_FORMAT,
            wgpu::TextureUsages::empty(),
        )
    }
}

fn depth_pass_name(light: usize, face: Option<usize>) -> String {
    match face {
        Some(f) => format!("Shadow map: light {light} face {f}"),
        None => format!("Shadow map: light {light}"),
    }
}

fn lookup_pass_name(light: usize) -> String {
    format!("Shadow lookup: light {light}")
}

impl ShadowTechnique for ShadowMaps {
    fn passes(&self) -> Vec<PassInfo> {
        let mut out = Vec::new();
        for maps in &self.lights {
            let cube = maps.frustums.len() == 6;
            for face in 0..maps.frustums.len() {
                out.push(PassInfo::render(depth_pass_name(
                    maps.light,
                    cube.then_some(face),
                )));
            }
        }
        for maps in &self.lights {
            out.push(PassInfo::render(lookup_pass_name(maps.light)));
        }
        out
    }

    fn resources(&self) -> Vec<ResourceInfo> {
        let mut out = Vec::new();
        if let Some(maps) = &self.maps {
            out.push(ResourceInfo::texture("shadow maps", &maps.texture, true));
        }
        if let Some((texture, _)) = &self.diagnostics {
            out.push(ResourceInfo::texture("diagnostics", texture, false));
            // Two views of the diagnostics texture (no memory of their own).
            for view in ["coverage", "depth difference"] {
                out.push(ResourceInfo {
                    bytes: 0,
                    ..ResourceInfo::texture(view, texture, true)
                });
            }
        }
        if let Some(b) = &self.buffers {
            out.push(ResourceInfo::buffer(
                "layer cameras",
                &b.slots,
                "mat4 in 256-byte slots",
            ));
            out.push(ResourceInfo::buffer(
                "shadow lights",
                &b.lights,
                "ShadowLight",
            ));
        }
        out
    }

    fn packs_visibility_slots(&self) -> bool {
        // The lookup writes only inside each light's range and cone.
        true
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> Result<(), TechniqueError> {
        if self.pipelines.is_none() {
            self.pipelines = Some(self.create_pipelines(ctx)?);
            self.samplers = Some(Self::create_samplers(&ctx.gpu.device));
        }
        if changes.scene {
            self.object_bounds = object_bounds(ctx.scene, false);
            self.caster_bounds = object_bounds(ctx.scene, true);
        }
        if changes.resolution || self.diagnostics.is_none() {
            self.diagnostics = Some(Self::diagnostics_texture(&ctx.gpu.device, ctx.size));
        }
        if changes.scene || changes.lights || self.maps.is_none() {
            self.plan_maps(ctx);
        }
        // Directional maps follow the camera; spot and point maps follow their lights.
        if changes != Changes::default() || self.buffers.is_none() {
            self.fit(ctx);
        }
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> Result<(), TechniqueError> {
        let (Some(pipelines), Some(maps), Some(buffers), Some((_, diagnostics))) = (
            &self.pipelines,
            &self.maps,
            &self.buffers,
            &self.diagnostics,
        ) else {
            return Err(TechniqueError::Other(
                "sm-pcf: record before prepare".into(),
            ));
        };
        for light_maps in &self.lights {
            let cube = light_maps.frustums.len() == 6;
            for face in 0..light_maps.frustums.len() {
                let layer = light_maps.first_layer + face as u32;
                let name = depth_pass_name(light_maps.light, cube.then_some(face));
                let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(&name),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &maps.layer_views[layer as usize],
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&pipelines.depth);
                pass.set_bind_group(
                    0,
                    &buffers.depth_bind_group,
                    &[(layer as u64 * SLOT) as u32],
                );
                ctx.scene_buffers.draw_objects(&mut pass, ctx.scene, true);
            }
        }
        for (k, light_maps) in self.lights.iter().enumerate() {
            let debug = light_maps.light as u32 == self.params.debug_light;
            let name = lookup_pass_name(light_maps.light);
            let diagnostics = zoo_host::gpu::color_attachment(
                diagnostics,
                zoo_host::gpu::clear_first(k == 0, wgpu::Color::TRANSPARENT),
            );
            let mut pass =
                ctx.light_pass_with(recorder, &name, light_maps.light, &[diagnostics], None);
            pass.set_pipeline(&pipelines.lookup[usize::from(debug)]);
            pass.set_bind_group(2, &buffers.lookup_bind_group, &[(k as u64 * SLOT) as u32]);
            let [x, y, width, height] = light_maps.scissor;
            if width > 0 && height > 0 {
                pass.set_scissor_rect(x, y, width, height);
                pass.draw(0..3, 0..1);
            }
        }
        Ok(())
    }

    fn update_params(&mut self, values: &ParamValues) -> Result<ParamUpdate, TechniqueError> {
        let next = SmParams::from_values(values)?;
        // Map size, depth biases and culling live in the maps and the depth pipeline; the
        // rest reaches the shader through the per-light buffers `fit` rewrites.
        let built = |p: &SmParams| {
            (
                p.map_size,
                p.constant_bias,
                p.slope_bias.to_bits(),
                p.cull_front,
            )
        };
        if built(&next) != built(&self.params) {
            return Ok(ParamUpdate::Rebuild);
        }
        self.params = next;
        Ok(ParamUpdate::Applied)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        match resource {
            "shadow maps" => {
                let maps = self.maps.as_ref()?;
                let light = self
                    .lights
                    .iter()
                    .find(|l| l.light as u32 == self.params.debug_light)?;
                Some(DebugImage {
                    view: &maps.layer_views[light.first_layer as usize],
                    mapping: ViewMapping::Depth { min: 0.0, max: 1.0 },
                })
            }
            "coverage" => Some(DebugImage {
                view: &self.diagnostics.as_ref()?.1,
                mapping: ViewMapping::Channel {
                    channel: 0,
                    min: 0.0,
                    max: 1.0,
                },
            }),
            "depth difference" => Some(DebugImage {
                view: &self.diagnostics.as_ref()?.1,
                mapping: ViewMapping::Channel {
                    channel: 1,
                    min: -2.0,
                    max: 2.0,
                },
            }),
            _ => None,
        }
    }

    fn counters(&self) -> Vec<(String, f64)> {
        let layers: usize = self.lights.iter().map(|l| l.frustums.len()).sum();
        let resolution = self.maps.as_ref().map_or(0, |m| m.resolution);
        vec![
            ("map layers".into(), layers as f64),
            ("map resolution".into(), resolution as f64),
        ]
    }
}

fn create(
    _: &GpuContext,
    values: &ParamValues,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    Ok(Box::new(ShadowMaps {
        params: SmParams::from_values(values)?,
        pipelines: None,
        maps: None,
        buffers: None,
        diagnostics: None,
        samplers: None,
        lights: Vec::new(),
        object_bounds: Vec::new(),
        caster_bounds: Vec::new(),
    }))
}

zoo_host::register_technique! {
    id: "sm-pcf",
    name: "Shadow maps + PCF",
    description: "Depth maps from each light (spot frustum, fitted directional box, point cube) with PCF or PCSS",
    source: "seed 000 section 7; seed 004 sections 3.4 and 9.1 (Williams 1978; Reeves 1987; Fernando 2005)",
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    required_features: wgpu::Features::empty,
    optional_features: wgpu::Features::empty,
    required_limits: wgpu::Limits::downlevel_defaults,
    params: SmParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::layout::{SizeRule, check_mirror, wgsl_integer_constant};

    #[test]
    fn resolution_is_clamped_to_device_and_memory() {
        assert_eq!(effective_resolution(2048, 16384, 3), (2048, None));
        let (r, note) = effective_resolution(8192, 4096, 1);
        assert_eq!(r, 4096);
        assert!(note.unwrap().contains("device limit"));
        // 224 layers at 2048 would need 3.5 GiB.
        let (r, note) = effective_resolution(2048, 16384, 224);
        assert!(224 * (r as u64).pow(2) * 4 <= MEMORY_BUDGET);
        assert!(note.unwrap().contains("exceed"));
    }

    #[test]
    fn scissor_covers_the_light_sphere_on_screen() {
        let camera = zoo_host::scene::Camera {
            position: Vec3::new(0.0, 5.0, 10.0),
            target: Vec3::ZERO,
            fov_y: 1.0,
            near: 0.1,
            far: 100.0,
        };
        let size = UVec2::new(200, 100);
        let view_proj = camera.projection(2.0) * camera.view();
        let mut light = Light {
            kind: LightKind::Point,
            position: Vec3::ZERO,
            direction: Vec3::NEG_Y,
            radiance: Vec3::ONE,
            range: 1.0,
            spot_angle: 0.0,
            spot_softness: 0.0,
            radius: 0.0,
        };
        let [x, y, w, h] = light_scissor(&light, view_proj, size);
        assert!(w > 0 && h > 0 && w < 200 && h < 100, "{x} {y} {w} {h}");
        // Every point of the sphere projects inside the rectangle.
        for k in 0..200 {
            let t = k as f32;
            let p = Vec3::new((t * 1.7).sin(), (t * 0.9).cos(), (t * 2.3).sin()).normalize() * 0.99;
            let ndc = view_proj.project_point3(p);
            let px = (ndc.x * 0.5 + 0.5) * 200.0;
            let py = (0.5 - ndc.y * 0.5) * 100.0;
            assert!(
                px >= x as f32 && px <= (x + w) as f32 && py >= y as f32 && py <= (y + h) as f32
            );
        }
        // A sphere reaching behind the camera, or a directional light, covers the screen.
        light.range = 20.0;
        assert_eq!(light_scissor(&light, view_proj, size), [0, 0, 200, 100]);
        light.kind = LightKind::Directional;
        assert_eq!(light_scissor(&light, view_proj, size), [0, 0, 200, 100]);
    }

    #[test]
    fn filter_codes_match_the_shader() {
        let source = shader("sm-pcf/lookup.wgsl");
        for (filter, constant) in [
            (Filter::None, "FILTER_NONE"),
            (Filter::Hardware2x2, "FILTER_HARDWARE_2X2"),
            (Filter::Pcf3x3, "FILTER_PCF_3X3"),
            (Filter::Pcf5x5, "FILTER_PCF_5X5"),
            (Filter::Pcf7x7, "FILTER_PCF_7X7"),
            (Filter::Pcf9x9, "FILTER_PCF_9X9"),
            (Filter::Poisson, "FILTER_POISSON"),
            (Filter::Pcss, "FILTER_PCSS"),
        ] {
            assert_eq!(
                Ok(i64::from(filter.code())),
                wgsl_integer_constant(&source, constant),
                "{filter:?}"
            );
        }
    }

    fn shader(name: &str) -> String {
        zoo_host::ShaderLibrary::embedded()
            .compose(name)
            .unwrap()
            .source
    }

    #[test]
    fn gpu_structs_mirror_the_shaders() {
        let lookup = shader("sm-pcf/lookup.wgsl");
        let (size, fields) = zoo_host::mirror_fields!(ShadowLight {
            first_layer,
            layer_count,
            filter_mode,
            light,
            texel_scale,
            perspective,
            near,
            far,
            normal_offset,
            kernel_texels,
            light_size,
            map_size,
            position,
            search_texels,
            direction,
            _pad
        });
        check_mirror(&lookup, "ShadowLight", size, &fields, SizeRule::Equal).unwrap();
        let (size, fields) = zoo_host::mirror_fields!(Slot { view_proj, _pad });
        check_mirror(&lookup, "Slot", size, &fields, SizeRule::Equal).unwrap();
        // Uniforms at 256-byte dynamic offsets: the Rust struct fills the slot.
        let (size, fields) = zoo_host::mirror_fields!(Current { index, debug });
        check_mirror(&lookup, "Current", size, &fields, SizeRule::AtLeast).unwrap();
        let depth = shader("sm-pcf/depth.wgsl");
        let (size, fields) = zoo_host::mirror_fields!(Slot { view_proj });
        check_mirror(&depth, "LayerCamera", size, &fields, SizeRule::AtLeast).unwrap();
    }
}
