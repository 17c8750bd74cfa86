//! Stencil shadow volumes with z-fail counting (seed 000 section 8; seed 004 sections 2.4, 2.5,
//! 3.5 and 9.2).
//!
//! Per light, a compute pass builds the volumes from the scene's edge adjacency: caps from the
//! triangles facing the light (and, for open or non-manifold meshes, from every triangle
//! oriented toward it), and side quads on edges whose face orientations do not cancel, counted
//! with multiplicity. Vertices are extruded to infinity (w = 0) and drawn with unclipped depth
//! (`DEPTH_CLIP_CONTROL`), so counting is robust with the camera anywhere. One two-sided draw
//! updates the G-buffer's stencil (z-fail: back faces increment and front faces decrement where
//! the depth test fails, with wrap); a full-screen pass then writes visibility 0 where the count
//! is not zero.

use zoo_host::gpu::readback::ReadbackRing;
use zoo_host::params::TechniqueParams;
use zoo_host::render::visibility::VISIBILITY_FORMAT;
use zoo_host::scene::LightKind;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_host::{
    Changes, GpuContext, ParamUpdate, ParamValues, PassInfo, PassRecorder, RenderContext,
    ShadowTechnique, TechniqueError, wgpu,
};

use zoo_shadow_volumes::{
    ARGS_BYTES, VOLUME_VERTEX_LAYOUT, VolumeGenerator, stencil_state, volume_depth_stencil,
    volume_primitive,
};
pub use zoo_shadow_volumes::{Counting, Volumes, silhouette};

zoo_host::technique_params! {
    /// Parameters of stencil shadow volumes.
    pub struct SvParams {
        /// Counting: z-fail (robust, the default) or z-pass (wrong with the camera in a shadow).
        counting: Counting = Counting::ZFail;
        /// Volumes from silhouette edges (default) or one volume per triangle (seed 004's baseline).
        volumes: Volumes = Volumes::Silhouette;
        /// Constant depth bias pushing volume faces back, so a lit surface is never shadowed by
        /// its own near cap (depth-buffer units).
        depth_bias: u32 = 16, range(0, 65536), step(1);
        /// Slope-scaled depth bias of volume faces. It also pushes back the volume's sides,
        /// which a camera sees at grazing angles when the light is low: a slope bias of 1 then
        /// moves shadow edges by about a pixel (judge: core errors 0.012 under a horizontal sun
        /// on planar-room, 0 without), so it is off by default.
        slope_bias: f32 = 0.0, range(0.0, 8.0), step(0.1);
        /// Light whose volumes and stencil counts the debug views show.
        debug_light: u32 = 0, range(0, 1023), step(1);
    }
}

const SLOT: u64 = 256;
const COUNTS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Uint;
const OVERLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Stencil levels the count view distinguishes, shown as ids 1..=10: counts 1..=8, then 255 and
/// 254 (-1 and -2 wrapped); any other non-zero count is id 11.
const COUNT_LEVELS: [u32; 10] = [1, 2, 3, 4, 5, 6, 7, 8, 255, 254];

struct Pipelines {
    generator: VolumeGenerator,
    volume: wgpu::RenderPipeline,
    resolve: wgpu::RenderPipeline,
    overlay: wgpu::RenderPipeline,
    count_equal: wgpu::RenderPipeline,
    count_any: wgpu::RenderPipeline,
    count_layout: wgpu::BindGroupLayout,
}

struct Buffers {
    /// Draw arguments and silhouette counters per light, read back a frame or two late.
    stats: std::sync::Mutex<ReadbackRing>,
    levels_bind_group: wgpu::BindGroup,
}

struct DebugTargets {
    counts: (wgpu::Texture, wgpu::TextureView),
    overlay: (wgpu::Texture, wgpu::TextureView),
}

/// Stencil shadow volumes.
pub struct ShadowVolumes {
    params: SvParams,
    device: wgpu::Device,
    pipelines: Option<Pipelines>,
    buffers: Option<Buffers>,
    debug: Option<DebugTargets>,
    lights: usize,
}

impl ShadowVolumes {
    fn create_pipelines(&self, ctx: &RenderContext<'_>) -> Result<Pipelines, TechniqueError> {
        let device = &ctx.gpu.device;
        let stencil_module = ctx.shaders.create_module(device, "sv-zfail/stencil.wgsl")?;
        let generator = VolumeGenerator::new(ctx, "sv-zfail")?;

        let count_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sv-zfail count level layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(4),
                },
                count: None,
            }],
        });
        let frame_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("sv-zfail render pipeline layout"),
            bind_group_layouts: &[Some(&ctx.frame.layout)],
            immediate_size: 0,
        });
        let count_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sv-zfail count pipeline layout"),
                bind_group_layouts: &[Some(&ctx.frame.layout), Some(&count_layout)],
                immediate_size: 0,
            });

        let keep = wgpu::StencilOperation::Keep;
        let face = |compare, pass_op, depth_fail_op| wgpu::StencilFaceState {
            compare,
            fail_op: keep,
            depth_fail_op,
            pass_op,
        };
        let target = |format, write_mask, blend| {
            Some(wgpu::ColorTargetState {
                format,
                blend,
                write_mask,
            })
        };
        let volume_primitive = volume_primitive();
        let bias = wgpu::DepthBiasState {
            constant: self.params.depth_bias as i32,
            slope_scale: self.params.slope_bias,
            clamp: 0.0,
        };
        let volume = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("sv-zfail volume stencil pipeline"),
            layout: Some(&frame_layout),
            vertex: wgpu::VertexState {
                module: &stencil_module,
                entry_point: Some("vs_volume"),
                compilation_options: Default::default(),
                buffers: &[Some(VOLUME_VERTEX_LAYOUT)],
            },
            primitive: volume_primitive,
            depth_stencil: Some(volume_depth_stencil(self.params.counting, bias)),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &stencil_module,
                entry_point: Some("fs_volume"),
                compilation_options: Default::default(),
                targets: &[target(VISIBILITY_FORMAT, wgpu::ColorWrites::empty(), None)],
            }),
            multiview_mask: None,
            cache: None,
        });
        let test = |compare| face(compare, keep, keep);
        let fullscreen = |label: &str,
                          layout: &wgpu::PipelineLayout,
                          entry: &str,
                          compare,
                          targets: &[Option<wgpu::ColorTargetState>]| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &stencil_module,
                    entry_point: Some("fullscreen_vs"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: Some(stencil_state(
                    wgpu::CompareFunction::Always,
                    test(compare),
                    test(compare),
                    Default::default(),
                )),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &stencil_module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let resolve = fullscreen(
            "sv-zfail resolve pipeline",
            &frame_layout,
            "fs_shadowed",
            wgpu::CompareFunction::NotEqual,
            &[Some(zoo_host::kit::slot_target())],
        );
        let debug_targets = |count_writes, overlay_writes, blend| {
            [
                target(COUNTS_FORMAT, count_writes, None),
                target(OVERLAY_FORMAT, overlay_writes, blend),
            ]
        };
        let count_targets = debug_targets(wgpu::ColorWrites::ALL, wgpu::ColorWrites::empty(), None);
        let count_equal = fullscreen(
            "sv-zfail stencil count pipeline (equal)",
            &count_pipeline_layout,
            "fs_count",
            wgpu::CompareFunction::Equal,
            &count_targets,
        );
        let count_any = fullscreen(
            "sv-zfail stencil count pipeline (any)",
            &count_pipeline_layout,
            "fs_count",
            wgpu::CompareFunction::NotEqual,
            &count_targets,
        );
        let additive = wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::REPLACE,
        };
        let overlay = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("sv-zfail volume overlay pipeline"),
            layout: Some(&frame_layout),
            vertex: wgpu::VertexState {
                module: &stencil_module,
                entry_point: Some("vs_volume"),
                compilation_options: Default::default(),
                buffers: &[Some(VOLUME_VERTEX_LAYOUT)],
            },
            primitive: volume_primitive,
            depth_stencil: Some(stencil_state(
                wgpu::CompareFunction::Always,
                test(wgpu::CompareFunction::Always),
                test(wgpu::CompareFunction::Always),
                Default::default(),
            )),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &stencil_module,
                entry_point: Some("fs_volume_debug"),
                compilation_options: Default::default(),
                targets: &debug_targets(
                    wgpu::ColorWrites::empty(),
                    wgpu::ColorWrites::ALL,
                    Some(additive),
                ),
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(Pipelines {
            generator,
            volume,
            resolve,
            overlay,
            count_equal,
            count_any,
            count_layout,
        })
    }

    fn create_buffers(&self, ctx: &RenderContext<'_>) -> Buffers {
        let device = &ctx.gpu.device;
        let pipelines = self.pipelines.as_ref().expect("pipelines exist");
        let stats = std::sync::Mutex::new(ReadbackRing::new(
            device,
            "sv-zfail workload counters",
            ctx.lights.len() as u64 * ARGS_BYTES,
            3,
        ));
        let level_data: Vec<u32> = std::iter::once(11)
            .chain(COUNT_LEVELS.iter().enumerate().map(|(i, _)| i as u32 + 1))
            .flat_map(|value| std::iter::once(value).chain(std::iter::repeat_n(0, 63)))
            .collect();
        let levels = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("sv-zfail count levels"),
                contents: bytemuck::cast_slice(&level_data),
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        let levels_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sv-zfail count levels bind group"),
            layout: &pipelines.count_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &levels,
                    offset: 0,
                    size: wgpu::BufferSize::new(4),
                }),
            }],
        });
        Buffers {
            stats,
            levels_bind_group,
        }
    }

    fn create_debug_targets(device: &wgpu::Device, size: zoo_host::glam::UVec2) -> DebugTargets {
        let make = |label: &str, format| {
            zoo_host::gpu::render_target(device, label, size, format, wgpu::TextureUsages::empty())
        };
        DebugTargets {
            counts: make("sv-zfail stencil counts", COUNTS_FORMAT),
            overlay: make("sv-zfail volumes overlay", OVERLAY_FORMAT),
        }
    }

    /// Silhouette edges and volume triangles per light from the newest frame whose counters
    /// have arrived (empty until one has; never waits for the GPU).
    pub fn workload(&self) -> Vec<(u32, u32)> {
        let Some(buffers) = &self.buffers else {
            return Vec::new();
        };
        let Ok(mut ring) = buffers.stats.lock() else {
            return Vec::new();
        };
        let Some((_, bytes)) = ring.latest(&self.device) else {
            return Vec::new();
        };
        let words: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        (0..self.lights)
            .map(|light| {
                let base = light * (ARGS_BYTES as usize / 4);
                (words[base + 4], words[base] / 3)
            })
            .collect()
    }
}

fn volume_pass_name(light: usize) -> String {
    format!("Shadow volumes: light {light}")
}

fn generation_pass_name(light: usize) -> String {
    format!("Volume generation: light {light}")
}

fn debug_pass_name(light: usize) -> String {
    format!("Volume debug: light {light}")
}

impl ShadowTechnique for ShadowVolumes {
    fn passes(&self) -> Vec<PassInfo> {
        let mut out = Vec::new();
        for light in 0..self.lights {
            out.push(PassInfo::compute(generation_pass_name(light)));
            out.push(PassInfo::render(volume_pass_name(light)));
            // The debug pass is recorded only while a debug view is shown.
        }
        out
    }

    fn resources(&self) -> Vec<ResourceInfo> {
        let mut out = self
            .pipelines
            .as_ref()
            .map(|p| p.generator.resources())
            .unwrap_or_default();
        if let Some(d) = &self.debug {
            out.push(ResourceInfo::texture("stencil counts", &d.counts.0, true));
            out.push(ResourceInfo::texture("volumes", &d.overlay.0, true));
        }
        out
    }

    fn packs_visibility_slots(&self) -> bool {
        // Volumes are infinite: a light's shadow is written wherever it falls.
        false
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> Result<(), TechniqueError> {
        if self.pipelines.is_none() {
            self.pipelines = Some(self.create_pipelines(ctx)?);
        }
        // Volume buffers and the counter ring depend on the scene and the number of lights,
        // not on where the lights are (moving one keeps its counters coming).
        let count_changed = ctx.lights.len() != self.lights;
        if changes.scene || count_changed || self.buffers.is_none() {
            self.lights = ctx.lights.len();
            let generator = &mut self.pipelines.as_mut().expect("created above").generator;
            generator.prepare(ctx, self.params.volumes);
            self.buffers = Some(self.create_buffers(ctx));
        }
        if changes.resolution || self.debug.is_none() {
            self.debug = Some(Self::create_debug_targets(&ctx.gpu.device, ctx.size));
        }
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> Result<(), TechniqueError> {
        let (Some(p), Some(b), Some(debug)) = (&self.pipelines, &self.buffers, &self.debug) else {
            return Err(TechniqueError::Other(
                "sv-zfail: record before prepare".into(),
            ));
        };
        let (Some(volume), Some(args)) = (p.generator.volume(), p.generator.args()) else {
            return Err(TechniqueError::not_prepared());
        };
        let stats = b
            .stats
            .lock()
            .ok()
            .and_then(|mut ring| ring.target().cloned());
        for light in 0..self.lights {
            p.generator
                .record(ctx, recorder, light, &generation_pass_name(light))?;
            {
                let name = volume_pass_name(light);
                let stencil = zoo_host::gpu::stencil_attachment(
                    &ctx.gbuffer.depth_view,
                    wgpu::LoadOp::Clear(0),
                );
                let mut pass = ctx.light_pass(recorder, &name, light, stencil);
                pass.set_pipeline(&p.volume);
                pass.set_vertex_buffer(0, volume.slice(..));
                pass.draw_indirect(args, 0);
                pass.set_pipeline(&p.resolve);
                pass.set_stencil_reference(0);
                pass.draw(0..3, 0..1);
            }
            if let Some(stats) = &stats {
                recorder.encoder().copy_buffer_to_buffer(
                    args,
                    0,
                    stats,
                    light as u64 * ARGS_BYTES,
                    ARGS_BYTES,
                );
            }
            let showing_debug = matches!(ctx.debug_view, Some("stencil counts" | "volumes"));
            if showing_debug && light as u32 == self.params.debug_light {
                let name = debug_pass_name(light);
                let clear = |view| {
                    zoo_host::gpu::color_attachment(view, wgpu::LoadOp::Clear(wgpu::Color::BLACK))
                };
                let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(&name),
                    color_attachments: &[clear(&debug.counts.1), clear(&debug.overlay.1)],
                    depth_stencil_attachment: zoo_host::gpu::stencil_attachment(
                        &ctx.gbuffer.depth_view,
                        wgpu::LoadOp::Load,
                    ),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
                // Any non-zero count first (level 9), then the exact levels.
                pass.set_pipeline(&p.count_any);
                pass.set_stencil_reference(0);
                pass.set_bind_group(1, &b.levels_bind_group, &[0]);
                pass.draw(0..3, 0..1);
                pass.set_pipeline(&p.count_equal);
                for (k, level) in COUNT_LEVELS.iter().enumerate() {
                    pass.set_stencil_reference(*level);
                    pass.set_bind_group(1, &b.levels_bind_group, &[((k as u64 + 1) * SLOT) as u32]);
                    pass.draw(0..3, 0..1);
                }
                pass.set_pipeline(&p.overlay);
                pass.set_vertex_buffer(0, volume.slice(..));
                pass.draw_indirect(args, 0);
            }
        }
        Ok(())
    }

    fn update_params(&mut self, values: &ParamValues) -> Result<ParamUpdate, TechniqueError> {
        let next = SvParams::from_values(values)?;
        // Only the debug light is read at record time; the rest shapes pipelines and buffers.
        let same_build = SvParams {
            debug_light: self.params.debug_light,
            ..next.clone()
        } == self.params;
        if !same_build {
            return Ok(ParamUpdate::Rebuild);
        }
        self.params = next;
        Ok(ParamUpdate::Applied)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let debug = self.debug.as_ref()?;
        match resource {
            "stencil counts" => Some(DebugImage {
                view: &debug.counts.1,
                mapping: ViewMapping::Integer,
            }),
            "volumes" => Some(DebugImage {
                view: &debug.overlay.1,
                mapping: ViewMapping::Color { min: 0.0, max: 1.0 },
            }),
            _ => None,
        }
    }

    fn counters(&self) -> Vec<(String, f64)> {
        self.workload()
            .into_iter()
            .enumerate()
            .flat_map(|(light, (silhouettes, triangles))| {
                [
                    (
                        format!("light {light} silhouette edges"),
                        silhouettes as f64,
                    ),
                    (format!("light {light} volume triangles"), triangles as f64),
                ]
            })
            .collect()
    }
}

fn create(
    gpu: &GpuContext,
    values: &ParamValues,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    Ok(Box::new(ShadowVolumes {
        params: SvParams::from_values(values)?,
        device: gpu.device.clone(),
        pipelines: None,
        buffers: None,
        debug: None,
        lights: 0,
    }))
}

zoo_host::register_technique! {
    id: "sv-zfail",
    name: "Stencil shadow volumes (z-fail)",
    description: "Silhouette volumes built on the GPU, extruded to infinity, counted with two-sided z-fail stencil",
    source: "seed 000 section 8; seed 004 sections 2.4-3.5 and 9.2 (Crow 1977; Carmack, Everitt & Kilgard 2002)",
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    required_features: || wgpu::Features::DEPTH_CLIP_CONTROL,
    optional_features: wgpu::Features::empty,
    required_limits: || wgpu::Limits {
        max_storage_buffers_per_shader_stage: 8,
        ..wgpu::Limits::downlevel_defaults()
    },
    // Volumes are generated by compute shaders into storage buffers and drawn indirectly.
    required_downlevel: || {
        wgpu::DownlevelFlags::COMPUTE_SHADERS | wgpu::DownlevelFlags::INDIRECT_EXECUTION
    },
    params: SvParams::schema,
    create: create,
}
