//! Planar projected shadows (seed 000, sections 5 and 14): every caster is flattened onto each
//! receiver plane with Blinn's matrix `M = (P . L) I - L P^T` and drawn into the light's
//! visibility slot, only on pixels the stencil marks as that plane.
//!
//! Correct by construction: a pixel is written once with a fixed value however many casters
//! overlap (no double darkening); the stencil keeps shadows inside the plane's extent; caster
//! parts beyond the light (anti-shadows) or below the plane (false shadows) are discarded per
//! fragment; a light behind a plane casts nothing onto it; and the shadow is not depth-tested
//! against the receiver, so it cannot z-fight with it. It is a planar-only technique: no
//! self-shadowing, nothing on curved receivers. Each of those fixes can be switched off to
//! show its classic artifact (`stencil_once`, `clip_casters`, `depth_test` with
//! `depth_offset`).

pub mod matrix;

use zoo_host::glam::{Mat4, Vec4};
use zoo_host::kit::{NamedTextures, SharedGroup, Stage, TextureSpec, UniformSlots, slot_target};
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
        /// Each pixel of a plane is shadowed once (default): the shadow replaces the light's
        /// visibility and the stencil is zeroed after the first write. Artifact when off
        /// (double blending): the shadow is blended multiplicatively wherever a flattened
        /// triangle lands, so where they overlap (a caster's front and back always do) it
        /// darkens twice or more; the stencil's once-per-pixel test fixes it.
        stencil_once: bool = true, flags(rebuild);
        /// Caster parts below the plane or at and beyond the light are discarded (default).
        /// Artifact when off: the projection is applied regardless, so parts below the plane
        /// cast false shadows and parts beyond the light anti-shadows; clipping them (Herf and
        /// Heckbert) fixes it.
        clip_casters: bool = true;
        /// Depth-test the flattened casters against the scene instead of relying on the
        /// stencil alone (off by default). With `depth_offset` 0 this shows z-fighting: the
        /// shadow's depths, computed through the shadow matrix, tie with the plane's own, so
        /// about half its pixels lose; the offset toward the camera fixes it.
        depth_test: bool = false, flags(rebuild);
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
        /// x: visibility written in shadow, y: plane id, z: distance tolerance for plane pixels,
        /// w: 1 to discard caster parts below the plane or beyond the light.
        params: Vec4,
    }
}

const PLANE_IDS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Uint;

/// One receiver plane to draw for one light.
struct PlaneDraw {
    /// Index into the scene's receivers (stencil id = index + 1).
    receiver: usize,
    /// Its [`Projection`]'s slot.
    slot: usize,
}

/// The passes of one light.
struct LightPass {
    light: usize,
    planes: Vec<PlaneDraw>,
}

struct Gpu {
    /// Marks the receiver's pixels in the stencil and the plane ids.
    mark: Stage,
    /// Writes shadows into the light's slot (`kit::slot_target`).
    shadow: Stage,
    projections: UniformSlots<Projection>,
}

/// The planar technique.
pub struct Planar {
    params: PlanarParams,
    gpu: Option<Gpu>,
    targets: NamedTextures,
    lights: Vec<LightPass>,
}

/// The stencil's plane ids, as the debug view shows them.
const PLANE_IDS: &str = "plane ids";

/// Both faces of every triangle: a caster's projection may face either way.
const BOTH_FACES: wgpu::PrimitiveState = wgpu::PrimitiveState {
    topology: wgpu::PrimitiveTopology::TriangleList,
    strip_index_format: None,
    front_face: wgpu::FrontFace::Ccw,
    cull_mode: None,
    unclipped_depth: false,
    polygon_mode: wgpu::PolygonMode::Fill,
    conservative: false,
};

/// The G-buffer's depth-stencil, not written, tested with `depth_compare` and `stencil`.
fn depth_stencil(
    depth_compare: wgpu::CompareFunction,
    (compare, pass_op): (wgpu::CompareFunction, wgpu::StencilOperation),
    bias: wgpu::DepthBiasState,
) -> wgpu::DepthStencilState {
    let face = wgpu::StencilFaceState {
        compare,
        fail_op: wgpu::StencilOperation::Keep,
        depth_fail_op: wgpu::StencilOperation::Keep,
        pass_op,
    };
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(false),
        depth_compare: Some(depth_compare),
        stencil: wgpu::StencilState {
            front: face,
            back: face,
            read_mask: 0xff,
            write_mask: 0xff,
        },
        bias,
    }
}

/// The plane-ids target, written (`RED`) or not.
fn plane_ids_target(write_mask: wgpu::ColorWrites) -> Option<wgpu::ColorTargetState> {
    Some(wgpu::ColorTargetState {
        format: PLANE_IDS_FORMAT,
        blend: None,
        write_mask,
    })
}

impl Planar {
    fn create_stages(&self, ctx: &RenderContext<'_>) -> Result<Gpu, TechniqueError> {
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let projections = UniformSlots::new(ctx.gpu, "planar projections", 1, stages);
        let slot = projections.at(0);
        let offset = self.params.depth_offset;
        // Toward the camera, so the plane wins the depth test against its own depth.
        let bias = wgpu::DepthBiasState {
            constant: -(offset as i32),
            slope_scale: if offset > 0 { -2.0 } else { 0.0 },
            clamp: 0.0,
        };
        let replace = (
            wgpu::CompareFunction::Always,
            wgpu::StencilOperation::Replace,
        );
        let no_visibility = Some(wgpu::ColorTargetState {
            format: VISIBILITY_FORMAT,
            blend: None,
            write_mask: wgpu::ColorWrites::empty(),
        });
        let mark = Stage::render("planar/mark.wgsl", "vs_mark")
            .fragment("fs_mark")
            .vertex_buffers(&SceneBuffers::VERTEX_LAYOUTS)
            .primitive(BOTH_FACES)
            .depth_stencil(depth_stencil(
                wgpu::CompareFunction::LessEqual,
                replace,
                bias,
            ))
            .targets(&[no_visibility, plane_ids_target(wgpu::ColorWrites::RED)])
            .shared(&[&slot])
            .build(ctx)?;
        let shadow = Stage::render("planar/shadow.wgsl", "vs_shadow")
            .fragment("fs_shadow")
            .vertex_buffers(&SceneBuffers::VERTEX_LAYOUTS)
            .primitive(BOTH_FACES)
            .depth_stencil(self.shadow_depth_stencil(bias))
            .targets(&[
                Some(self.shadow_target()),
                plane_ids_target(wgpu::ColorWrites::empty()),
            ])
            .shared(&[&slot])
            .build(ctx)?;
        Ok(Gpu {
            mark,
            shadow,
            projections,
        })
    }

    /// The shadow pass's depth-stencil: on the marked plane's pixels, zeroing the stencil
    /// after the first write unless `stencil_once` is off; depth-tested with the marking
    /// draw's `bias` where `depth_test` is on.
    fn shadow_depth_stencil(&self, bias: wgpu::DepthBiasState) -> wgpu::DepthStencilState {
        let pass_op = match self.params.stencil_once {
            true => wgpu::StencilOperation::Zero,
            false => wgpu::StencilOperation::Keep,
        };
        let stencil = (wgpu::CompareFunction::Equal, pass_op);
        match self.params.depth_test {
            true => depth_stencil(wgpu::CompareFunction::LessEqual, stencil, bias),
            false => depth_stencil(wgpu::CompareFunction::Always, stencil, Default::default()),
        }
    }

    /// The light's slot, replaced by the shadow, or multiplied by it (the classic blended
    /// shadow polygon: each overlapping draw darkens it again) where `stencil_once` is off.
    fn shadow_target(&self) -> wgpu::ColorTargetState {
        if self.params.stencil_once {
            return slot_target();
        }
        // The selected channel becomes src x dst, the others keep dst.
        let multiply = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Dst,
            dst_factor: wgpu::BlendFactor::OneMinusConstant,
            operation: wgpu::BlendOperation::Add,
        };
        wgpu::ColorTargetState {
            blend: Some(wgpu::BlendState {
                color: multiply,
                alpha: multiply,
            }),
            ..slot_target()
        }
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
                    slot: data.len(),
                });
                data.push(Projection {
                    shadow_matrix: shadow_matrix(receiver.plane, l),
                    plane: receiver.plane,
                    light: l,
                    params: Vec4::new(
                        1.0 - self.params.opacity,
                        (r + 1) as f32,
                        tolerance,
                        f32::from(u8::from(self.params.clip_casters)),
                    ),
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
        let gpu = self.gpu.as_mut().ok_or_else(TechniqueError::not_prepared)?;
        gpu.projections.write(ctx.gpu, &data);
        Ok(())
    }
}

fn pass_name(light: usize) -> String {
    format!("Planar shadows: light {light}")
}

impl ShadowTechnique for Planar {
    fn resources(&self) -> Vec<ResourceInfo> {
        let mut out = self.targets.resources();
        if let Some(gpu) = &self.gpu {
            let slots = format!("Projection ({}-byte slots)", gpu.projections.stride());
            out.push(ResourceInfo::buffer(
                "projections",
                gpu.projections.buffer(),
                &slots,
            ));
        }
        out
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> Result<(), TechniqueError> {
        let rebuilt = self.gpu.is_none();
        if rebuilt {
            self.gpu = Some(self.create_stages(ctx)?);
        }
        if changes.scene || changes.lights || changes.params || rebuilt {
            self.plan(ctx)?;
        }
        self.targets.prepare(ctx);
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> Result<(), TechniqueError> {
        let (Some(gpu), Some(plane_ids)) = (&self.gpu, self.targets.view(PLANE_IDS)) else {
            return Err(TechniqueError::not_prepared());
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
                let projection = [&gpu.projections.at(plane.slot) as &dyn SharedGroup];
                pass.set_stencil_reference(plane.receiver as u32 + 1);
                gpu.mark.set_on(ctx, &mut pass, &[], &projection)?;
                buffers.draw_objects_where(&mut pass, scene, |i, _| i == receiver.object);
                gpu.shadow.set_on(ctx, &mut pass, &[], &projection)?;
                buffers.draw_objects_where(&mut pass, scene, |i, o| {
                    o.casts_shadows && i != receiver.object
                });
            }
        }
        Ok(())
    }

    fn update_params(&mut self, values: &ParamValues) -> Result<ParamUpdate, TechniqueError> {
        // The depth offset, stencil and depth tests are part of the pipelines
        // (`flags(rebuild)`); receivers, opacity and clipping are in the projection uniforms
        // `plan` rewrites.
        Ok(self.params.update(values)?)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        self.targets.debug_view(resource)
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
        targets: NamedTextures::new(
            "planar",
            [TextureSpec::screen_target(
                PLANE_IDS,
                PLANE_IDS_FORMAT,
                Some(ViewMapping::Integer),
            )],
        ),
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
