//! Planar projected shadows (seed 000, sections 5 and 14): every caster is flattened onto each
//! receiver plane with Blinn's matrix `M = (P . L) I - L P^T` and drawn into the light's
//! visibility slot, only on pixels the stencil marks as that plane.
//!
//! Correct by construction: a pixel is written once with a fixed value however many casters
//! overlap (no double darkening); the stencil keeps shadows inside the plane's extent; caster
//! parts beyond the light (anti-shadows) or below the plane (false shadows) are discarded per
//! fragment; a light behind a plane casts nothing onto it; and the shadow is not depth-tested
//! against the receiver, so it cannot z-fight with it. It is a planar-only technique: no
//! self-shadowing, nothing on curved receivers.

pub mod matrix;

use zoo_host::glam::{Mat4, Vec4};
use zoo_host::gpu::{GpuType, gpu_bytes};
use zoo_host::params::TechniqueParams;
use zoo_host::render::SceneBuffers;
use zoo_host::render::gbuffer::DEPTH_FORMAT;
use zoo_host::render::visibility::VISIBILITY_FORMAT;
use zoo_host::scene::LightKind;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_host::{
    Changes, GpuContext, ParamUpdate, ParamValues, PassRecorder, RenderContext, ShadowTechnique,
    TechniqueError, wgpu,
};

use crate::matrix::shadow_matrix;

zoo_host::technique_params! {
    /// Parameters of planar projected shadows.
    pub struct PlanarParams {
        /// Receiver planes that get shadows: bit i enables the scene's i-th receiver plane.
        receivers: u32 = u32::MAX, range(0, u32::MAX), step(1);
        /// Shadow opacity: the fraction of the light a shadow removes (1 is physically right).
        opacity: f32 = 1.0, range(0.0, 1.0), step(0.05);
        /// Depth bias (depth-buffer units, toward the camera) of the plane-marking draw, so the
        /// plane wins the depth test against its own G-buffer depth.
        depth_offset: u32 = 16, range(0, 4096), step(1), flags(rebuild);
    }
}

zoo_host::gpu_struct! {
    "planar/projection_uniform.wgsl" =>
    /// Uniform data of one (light, plane) pair (`planar/projection.wgsl`).
    #[derive(Debug, Clone, Copy)]
    struct Projection {
        shadow_matrix: Mat4,
        /// Receiver plane (n, d): n . x + d = 0, n pointing to the lit side.
        plane: Vec4,
        /// Homogeneous light: (position, 1) or (direction toward the light, 0).
        light: Vec4,
        /// x: visibility written in shadow, y: plane id, z: distance tolerance for plane pixels.
        params: Vec4,
    }
}

/// Uniform slots are this far apart (the dynamic-offset alignment).
const SLOT: u64 = 256;
const PLANE_IDS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Uint;

/// One receiver plane to draw for one light.
struct PlaneDraw {
    /// Index into the scene's receivers (stencil id = index + 1).
    receiver: usize,
    /// Byte offset of its [`Projection`] in the uniform buffer.
    offset: u32,
}

/// The passes of one light.
struct LightPass {
    light: usize,
    planes: Vec<PlaneDraw>,
}

struct Gpu {
    mark: wgpu::RenderPipeline,
    /// Writes shadows into the light's slot (`kit::slot_target`).
    shadow: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

/// The planar technique.
pub struct Planar {
    params: PlanarParams,
    gpu: Option<Gpu>,
    uniforms: Option<(wgpu::Buffer, wgpu::BindGroup)>,
    plane_ids: Option<(wgpu::Texture, wgpu::TextureView)>,
    lights: Vec<LightPass>,
}

impl Planar {
    fn create_pipelines(&self, ctx: &RenderContext<'_>) -> Result<Gpu, TechniqueError> {
        let device = &ctx.gpu.device;
        let mark_module = ctx.shaders.create_module(device, "planar/mark.wgsl")?;
        let shadow_module = ctx.shaders.create_module(device, "planar/shadow.wgsl")?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("planar projection layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(Projection::SIZE as u64),
                },
                count: None,
            }],
        });
        // Marking reads the G-buffer; the shadow pass reads the casters' materials instead.
        let pipeline_layout = |label, group_1| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(&ctx.frame.layout), Some(group_1), Some(&layout)],
                immediate_size: 0,
            })
        };
        let mark_layout = pipeline_layout("planar mark pipeline layout", &ctx.gbuffer.layout);
        let shadow_layout = pipeline_layout(
            "planar shadow pipeline layout",
            &ctx.scene_buffers.materials.layout,
        );
        let stencil_face = |compare, pass_op| wgpu::StencilFaceState {
            compare,
            fail_op: wgpu::StencilOperation::Keep,
            depth_fail_op: wgpu::StencilOperation::Keep,
            pass_op,
        };
        let pipeline = |label: &str,
                        (module, pipeline_layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
                        vertex: &str,
                        fragment: &str,
                        visibility: wgpu::ColorTargetState,
                        plane_ids: wgpu::ColorWrites,
                        depth_compare,
                        stencil: wgpu::StencilFaceState,
                        bias: wgpu::DepthBiasState| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(pipeline_layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some(vertex),
                    compilation_options: Default::default(),
                    buffers: &SceneBuffers::VERTEX_LAYOUTS,
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(false),
                    depth_compare: Some(depth_compare),
                    stencil: wgpu::StencilState {
                        front: stencil,
                        back: stencil,
                        read_mask: 0xff,
                        write_mask: 0xff,
                    },
                    bias,
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some(fragment),
                    compilation_options: Default::default(),
                    targets: &[
                        Some(visibility),
                        Some(wgpu::ColorTargetState {
                            format: PLANE_IDS_FORMAT,
                            blend: None,
                            write_mask: plane_ids,
                        }),
                    ],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let mark = pipeline(
            "planar mark plane pipeline",
            (&mark_module, &mark_layout),
            "vs_mark",
            "fs_mark",
            wgpu::ColorTargetState {
                format: VISIBILITY_FORMAT,
                blend: None,
                write_mask: wgpu::ColorWrites::empty(),
            },
            wgpu::ColorWrites::RED,
            wgpu::CompareFunction::LessEqual,
            stencil_face(
                wgpu::CompareFunction::Always,
                wgpu::StencilOperation::Replace,
            ),
            wgpu::DepthBiasState {
                constant: -(self.params.depth_offset as i32),
                slope_scale: if self.params.depth_offset > 0 {
                    -2.0
                } else {
                    0.0
                },
                clamp: 0.0,
            },
        );
        let shadow = pipeline(
            "planar shadow pipeline",
            (&shadow_module, &shadow_layout),
            "vs_shadow",
            "fs_shadow",
            zoo_host::kit::slot_target(),
            wgpu::ColorWrites::empty(),
            wgpu::CompareFunction::Always,
            // Zero after the first write: each pixel is shadowed once per plane.
            stencil_face(wgpu::CompareFunction::Equal, wgpu::StencilOperation::Zero),
            Default::default(),
        );
        Ok(Gpu {
            mark,
            shadow,
            layout,
        })
    }

    /// Plans the (light, plane) draws and fills the uniform buffer.
    fn plan(&mut self, ctx: &RenderContext<'_>) -> Result<(), TechniqueError> {
        let scene = ctx.scene;
        let (lo, hi) = scene.bounds();
        let tolerance = (lo.distance(hi) * 1e-4).max(1e-5);
        let mut data = Vec::new();
        self.lights.clear();
        for (light_index, light) in ctx.lights.iter().enumerate() {
            let l = light.homogeneous();
            let mut planes = Vec::new();
            for (r, receiver) in scene.receivers.iter().enumerate() {
                let enabled = r < 32 && self.params.receivers & (1 << r) != 0;
                // A light behind (or in) the plane casts nothing onto its front.
                if !enabled || receiver.plane.dot(l) <= 0.0 {
                    continue;
                }
                planes.push(PlaneDraw {
                    receiver: r,
                    offset: (data.len() as u64 * SLOT) as u32,
                });
                data.push(Projection {
                    shadow_matrix: shadow_matrix(receiver.plane, l),
                    plane: receiver.plane,
                    light: l,
                    params: Vec4::new(1.0 - self.params.opacity, (r + 1) as f32, tolerance, 0.0),
                });
            }
            if !planes.is_empty() {
                self.lights.push(LightPass {
                    light: light_index,
                    planes,
                });
            }
        }
        if scene.receivers.len() > 255 {
            return Err(TechniqueError::Other(format!(
                "planar: {} receiver planes, at most 255 fit the stencil",
                scene.receivers.len()
            )));
        }
        let device = &ctx.gpu.device;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("planar projections"),
            size: (data.len().max(1) as u64) * SLOT,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        for (i, projection) in data.iter().enumerate() {
            ctx.gpu
                .queue
                .write_buffer(&buffer, i as u64 * SLOT, &gpu_bytes(&[*projection]));
        }
        let layout = &self.gpu.as_ref().expect("pipelines exist").layout;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("planar projections bind group"),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(Projection::SIZE as u64),
                }),
            }],
        });
        self.uniforms = Some((buffer, bind_group));
        Ok(())
    }
}

fn pass_name(light: usize) -> String {
    format!("Planar shadows: light {light}")
}

impl ShadowTechnique for Planar {
    fn resources(&self) -> Vec<ResourceInfo> {
        let mut out = Vec::new();
        if let Some((texture, _)) = &self.plane_ids {
            out.push(ResourceInfo::texture("plane ids", texture, true));
        }
        if let Some((buffer, _)) = &self.uniforms {
            out.push(ResourceInfo::buffer(
                "projections",
                buffer,
                "Projection (256-byte slots)",
            ));
        }
        out
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> Result<(), TechniqueError> {
        if self.gpu.is_none() {
            self.gpu = Some(self.create_pipelines(ctx)?);
        }
        if changes.scene || changes.lights || changes.params || self.uniforms.is_none() {
            self.plan(ctx)?;
        }
        if changes.resolution || self.plane_ids.is_none() {
            self.plane_ids = Some(zoo_host::gpu::render_target(
                &ctx.gpu.device,
                "planar plane ids",
                ctx.size,
                PLANE_IDS_FORMAT,
                wgpu::TextureUsages::empty(),
            ));
        }
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> Result<(), TechniqueError> {
        let (Some(gpu), Some((_, uniforms)), Some((_, plane_ids))) =
            (&self.gpu, &self.uniforms, &self.plane_ids)
        else {
            return Err(TechniqueError::Other(
                "planar: record before prepare".into(),
            ));
        };
        let scene = ctx.scene;
        for (k, light_pass) in self.lights.iter().enumerate() {
            let plane_ids = zoo_host::gpu::color_attachment(
                plane_ids,
                zoo_host::gpu::clear_first(k == 0, wgpu::Color::TRANSPARENT),
            );
            let stencil =
                zoo_host::gpu::stencil_attachment(&ctx.gbuffer.depth_view, wgpu::LoadOp::Clear(0));
            let name = pass_name(light_pass.light);
            let mut pass =
                ctx.light_pass_with(recorder, &name, light_pass.light, &[plane_ids], stencil);
            let buffers = ctx.scene_buffers;
            for plane in &light_pass.planes {
                let receiver = &scene.receivers[plane.receiver];
                pass.set_bind_group(2, uniforms, &[plane.offset]);
                pass.set_stencil_reference(plane.receiver as u32 + 1);
                pass.set_bind_group(1, &ctx.gbuffer.bind_group, &[]);
                pass.set_pipeline(&gpu.mark);
                buffers.draw_objects_where(&mut pass, scene, |i, _| i == receiver.object);
                pass.set_bind_group(1, &buffers.materials.bind_group, &[]);
                pass.set_pipeline(&gpu.shadow);
                buffers.draw_objects_where(&mut pass, scene, |i, o| {
                    o.casts_shadows && i != receiver.object
                });
            }
        }
        Ok(())
    }

    fn update_params(&mut self, values: &ParamValues) -> Result<ParamUpdate, TechniqueError> {
        // The depth offset is part of the marking pipeline (`flags(rebuild)`); receivers and
        // opacity are in the projection uniforms `plan` rewrites.
        Ok(self.params.update(values)?)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        match (resource, &self.plane_ids) {
            ("plane ids", Some((_, view))) => Some(DebugImage {
                view,
                mapping: ViewMapping::Integer,
            }),
            _ => None,
        }
    }

    fn counters(&self) -> Vec<(String, f64)> {
        let draws: usize = self.lights.iter().map(|l| l.planes.len()).sum();
        vec![("plane projections".to_string(), draws as f64)]
    }
}

fn create(
    _: &GpuContext,
    values: &ParamValues,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    Ok(Box::new(Planar {
        params: PlanarParams::from_values(values)?,
        gpu: None,
        uniforms: None,
        plane_ids: None,
        lights: Vec::new(),
    }))
}

zoo_host::register_technique! {
    id: "planar",
    name: "Planar projected shadows",
    description: "Casters flattened onto receiver planes (Blinn's matrix), stencil-limited",
    source: "seed 000 sections 5 and 14 (Blinn 1988)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    required_features: wgpu::Features::empty,
    optional_features: wgpu::Features::empty,
    required_limits: wgpu::Limits::downlevel_defaults,
    params: PlanarParams::schema,
    create: create,
}
