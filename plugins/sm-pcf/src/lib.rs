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

use bytemuck::{Pod, Zeroable};
use zoo_host::glam::UVec2;
use zoo_host::gpu::layout::ChoiceCodes;
use zoo_host::params::TechniqueParams;
use zoo_host::scene::LightKind;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_host::{
    Changes, GpuContext, ParamUpdate, ParamValues, PassInfo, PassRecorder, RenderContext,
    ShadowTechnique, TechniqueError, wgpu,
};

use zoo_shadow_maps::{DepthState, ShadowMapSet, light_size};

zoo_host::param_choice! {
    /// How shadow-map comparisons are filtered.
    pub enum Filter { None, Hardware2x2, Pcf3x3, Pcf5x5, Pcf7x7, Pcf9x9, Poisson, Pcss }
}

zoo_host::technique_params! {
    /// Parameters of shadow maps with PCF.
    pub struct SmParams {
        /// Shadow-map resolution in texels per side (clamped to the device and memory budget).
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
    search_texels: f32,
    position: [f32; 3],
    _pad0: f32,
    direction: [f32; 3],
    _pad1: f32,
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
const LOOKUP_SHADER: &str = "sm-pcf/lookup.wgsl";
const DIAGNOSTICS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
struct Pipelines {
    /// Without and with diagnostics output; each writes the light's slot (`kit::slot_target`).
    lookup: Vec<wgpu::RenderPipeline>,
    lookup_layout: wgpu::BindGroupLayout,
    /// The lookup's value of each `Filter` (its `FILTER_*` constants).
    filter_codes: ChoiceCodes,
}

struct Buffers {
    lights: wgpu::Buffer,
    current: wgpu::Buffer,
    lookup_bind_group: wgpu::BindGroup,
}

/// Shadow maps with PCF.
pub struct ShadowMaps {
    params: SmParams,
    pipelines: Option<Pipelines>,
    /// The lights' depth maps, their frusta and the depth pass.
    maps: Option<ShadowMapSet>,
    buffers: Option<Buffers>,
    diagnostics: Option<(wgpu::Texture, wgpu::TextureView)>,
    samplers: Option<(wgpu::Sampler, wgpu::Sampler)>,
}

impl ShadowMaps {
    fn create_pipelines(&self, ctx: &RenderContext<'_>) -> Result<Pipelines, TechniqueError> {
        let device = &ctx.gpu.device;
        let lookup_module = ctx.shaders.create_module(device, LOOKUP_SHADER)?;
        let lookup_source = ctx.shaders.compose(LOOKUP_SHADER)?.source;
        let filter_codes = ChoiceCodes::read(&lookup_source, "FILTER", Filter::NAMES)
            .map_err(|e| TechniqueError::Other(format!("{LOOKUP_SHADER}: {e}")))?;

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
            lookup,
            lookup_layout,
            filter_codes,
        })
    }

    /// Uploads every light's lookup parameters (after the maps were refitted or a parameter
    /// changed).
    fn upload(&mut self, ctx: &RenderContext<'_>) {
        let pipelines = self.pipelines.as_ref().expect("pipelines exist");
        let maps = self.maps.as_ref().expect("maps exist");
        let resolution = maps.resolution();
        let filter_mode = pipelines.filter_codes.code(self.params.filter.index());
        let shadow_lights: Vec<ShadowLight> = maps
            .lights()
            .iter()
            .map(|maps| {
                let light = &ctx.lights[maps.light];
                let scale = maps.scale(resolution);
                ShadowLight {
                    first_layer: maps.first_layer,
                    layer_count: maps.frustums.len() as u32,
                    filter_mode,
                    light: maps.light as u32,
                    texel_scale: scale.texel_scale,
                    perspective: u32::from(scale.perspective),
                    near: scale.near,
                    far: scale.far,
                    normal_offset: self.params.normal_offset,
                    kernel_texels: self.params.kernel_radius,
                    light_size: light_size(light),
                    search_texels: self.params.pcss_max_texels,
                    position: light.position.to_array(),
                    _pad0: 0.0,
                    direction: light.direction.to_array(),
                    _pad1: 0.0,
                }
            })
            .collect();
        let currents: Vec<Current> = (0..maps.lights().len())
            .map(|i| Current {
                index: i as u32,
                debug: u32::from(i as u32 == self.params.debug_light),
                _pad: [0; 62],
            })
            .collect();

        let queue = &ctx.gpu.queue;
        let fits = |buffer: &wgpu::Buffer, bytes: usize| buffer.size() >= bytes.max(16) as u64;
        let light_bytes = size_of_val(shadow_lights.as_slice());
        let current_bytes = size_of_val(currents.as_slice());
        if !self
            .buffers
            .as_ref()
            .is_some_and(|b| fits(&b.lights, light_bytes) && fits(&b.current, current_bytes))
        {
            self.buffers = Some(self.create_buffers(ctx, light_bytes, current_bytes));
        }
        let buffers = self.buffers.as_ref().expect("created above");
        if !shadow_lights.is_empty() {
            queue.write_buffer(&buffers.lights, 0, bytemuck::cast_slice(&shadow_lights));
            queue.write_buffer(&buffers.current, 0, bytemuck::cast_slice(&currents));
        }
    }

    fn create_buffers(
        &self,
        ctx: &RenderContext<'_>,
        light_bytes: usize,
        current_bytes: usize,
    ) -> Buffers {
        let device = &ctx.gpu.device;
        let pipelines = self.pipelines.as_ref().expect("pipelines exist");
        let set = self.maps.as_ref().expect("maps exist");
        let maps = set.maps().expect("maps prepared");
        let (linear, nearest) = self.samplers.as_ref().expect("samplers exist");
        let buffer = |label: &str, bytes: usize, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (bytes.max(SLOT as usize) as u64).next_multiple_of(SLOT),
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let cameras = set.cameras().expect("cameras written");
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
                    resource: cameras.as_entire_binding(),
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
            lights,
            current,
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

/// Base name of the depth passes (see `zoo_shadow_maps::layer_pass_name`).
const DEPTH_PASS: &str = "Shadow map";

fn lookup_pass_name(light: usize) -> String {
    format!("Shadow lookup: light {light}")
}

impl ShadowTechnique for ShadowMaps {
    fn passes(&self) -> Vec<PassInfo> {
        let Some(maps) = &self.maps else {
            return Vec::new();
        };
        let lookups = maps.lights().iter().map(|l| lookup_pass_name(l.light));
        (maps.pass_names(DEPTH_PASS).into_iter())
            .chain(lookups)
            .map(PassInfo::render)
            .collect()
    }

    fn resources(&self) -> Vec<ResourceInfo> {
        let mut out = Vec::new();
        if let Some(maps) = self.maps.as_ref().and_then(|m| m.maps()) {
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
        if let Some(cameras) = self.maps.as_ref().and_then(|m| m.cameras()) {
            out.push(ResourceInfo::buffer(
                "layer cameras",
                cameras,
                "LayerCamera in 256-byte slots",
            ));
        }
        if let Some(b) = &self.buffers {
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
            let state = DepthState {
                constant_bias: self.params.constant_bias as i32,
                slope_bias: self.params.slope_bias,
                cull_front: self.params.cull_front,
            };
            self.maps = Some(ShadowMapSet::new(ctx, "sm-pcf shadow maps", state, None)?);
        }
        if changes.resolution || self.diagnostics.is_none() {
            self.diagnostics = Some(Self::diagnostics_texture(&ctx.gpu.device, ctx.size));
        }
        // Directional maps follow the camera; spot and point maps follow their lights.
        let maps = self.maps.as_mut().expect("created above");
        let p = &self.params;
        if maps.prepare(ctx, changes, p.map_size, p.stable_fit) {
            self.buffers = None;
        }
        if changes != Changes::default() || self.buffers.is_none() {
            self.upload(ctx);
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
            return Err(TechniqueError::not_prepared());
        };
        maps.record(ctx, recorder, DEPTH_PASS)?;
        for (k, light_maps) in maps.lights().iter().enumerate() {
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
        // Depth biases and culling live in the depth pipeline; the map size is applied by
        // the map set at the next `prepare`, the rest reaches the shader through the per-light
        // buffers `upload` rewrites.
        let built = |p: &SmParams| (p.constant_bias, p.slope_bias.to_bits(), p.cull_front);
        if built(&next) != built(&self.params) {
            return Ok(ParamUpdate::Rebuild);
        }
        self.params = next;
        Ok(ParamUpdate::Applied)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        match resource {
            "shadow maps" => {
                let set = self.maps.as_ref()?;
                let light =
                    (set.lights().iter()).find(|l| l.light as u32 == self.params.debug_light)?;
                Some(DebugImage {
                    view: &set.maps()?.layer_views[light.first_layer as usize],
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
        let Some(maps) = &self.maps else {
            return Vec::new();
        };
        let layers: usize = maps.lights().iter().map(|l| l.frustums.len()).sum();
        let resolution = maps.resolution();
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
    use zoo_host::gpu::layout::{SizeRule, check_mirror, wgsl_struct};

    #[test]
    fn every_filter_has_a_distinct_shader_constant() {
        let codes = ChoiceCodes::read(&shader(LOOKUP_SHADER), "FILTER", Filter::NAMES).unwrap();
        let mut values: Vec<u32> = (0..Filter::NAMES.len()).map(|i| codes.code(i)).collect();
        values.sort();
        values.dedup();
        assert_eq!(values.len(), Filter::NAMES.len());
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
            search_texels,
            position,
            direction
        });
        check_mirror(&lookup, "ShadowLight", size, &fields, SizeRule::Equal).unwrap();
        // The layer cameras come from the shadow-map library's depth pass, 256 bytes apart.
        let slot = wgsl_struct(&lookup, "Slot").unwrap();
        assert_eq!(slot.size as u64, zoo_shadow_maps::CAMERA_STRIDE);
        assert_eq!(slot.members[0], ("camera".to_string(), 0));
        // Uniforms at 256-byte dynamic offsets: the Rust struct fills the slot.
        let (size, fields) = zoo_host::mirror_fields!(Current { index, debug });
        check_mirror(&lookup, "Current", size, &fields, SizeRule::AtLeast).unwrap();
    }
}
