//! The GPU side of the light propagation volumes: the reflective shadow maps and the pass that
//! fills them, the grids' buffers and the compute passes over them.

use zoo_host::glam::{Mat4, UVec2, UVec3, Vec3, Vec4};
use zoo_host::gpu::GpuType;
use zoo_host::kit::{
    self, NamedTextures, SharedGroup, Stage, TextureSize, TextureSpec, UniformSlots,
};
use zoo_host::params::shader::padded_words;
use zoo_host::prelude::*;
use zoo_host::render::SceneBuffers;
use zoo_host::technique::ViewMapping;
use zoo_shadow_maps::light_space::LightFrustum;

use crate::LpvParams;
use crate::cascades::Grid;

/// Most grids (`MAX_CASCADES` in `lpv/volume.wgsl`).
pub const MAX_CASCADES: usize = 4;

/// The `flags(shader)` parameters as the shaders read them: `LpvParams` in the generated
/// `lpv/params.wgsl`, one word each, padded to 16 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShaderParams(pub [u32; PARAM_WORDS]);

impl GpuType for ShaderParams {
    const ALIGN: usize = 4;
    const SIZE: usize = 4 * PARAM_WORDS;
    fn wgsl_type() -> String {
        "LpvParams".to_string()
    }
    fn imports() -> Vec<&'static str> {
        vec!["lpv/params.wgsl"]
    }
    fn write(&self, out: &mut [u8]) {
        self.0.write(out);
    }
}

zoo_host::gpu_struct! {
    "lpv/lpv_settings.wgsl" =>
    /// The settings every LPV pass reads (`lpv/volume.wgsl`).
    #[derive(Debug, Clone, Copy)]
    pub struct LpvSettings {
        /// The plugin's parameters the shaders read (generated from their declaration: grid
        /// size, occlusion, camera occluders, coverage gain and lookup blocking, damping,
        /// intensity, blend cells, coarse far light, emitter orientation and its cells, skipping
        /// dark cells).
        pub params: ShaderParams,
        pub cascade_count: u32,
        /// Fixed-point scales of the injection sums (integer units per unit).
        pub light_scale: f32,
        pub occluder_scale: f32,
        /// The grid and volume the debug volume view shows (0 light, 1 occluders, 2 emitter
        /// normals).
        pub debug_cascade: u32,
        pub debug_source: u32,
        /// Reflective shadow maps injected (each sees the same surfaces: their surfels count
        /// once between them).
        pub map_count: u32,
    }
}

/// Words of the parameters the shaders read.
const PARAM_WORDS: usize = padded_words(<LpvParams as TechniqueParams>::SHADER_FIELDS);

zoo_host::gpu_struct! {
    "lpv/cascade.wgsl" =>
    /// One grid in `lpv/volume.wgsl`: its minimum corner and its cell size.
    #[derive(Debug, Clone, Copy, Default)]
    pub struct GpuCascade {
        pub min: Vec3,
        pub cell: f32,
    }
}

zoo_host::gpu_struct! {
    "lpv/lpv_data.wgsl" =>
    /// The data every LPV pass reads (`lpv/volume.wgsl`).
    #[derive(Debug, Clone, Copy)]
    pub struct LpvData {
        pub settings: LpvSettings,
        /// Where reflective-shadow-map positions are relative to (xyz).
        pub origin: Vec4,
        pub cascades: [GpuCascade; MAX_CASCADES],
    }
}

impl LpvData {
    /// The data for `settings` and `grids`, with map positions relative to `origin`.
    pub fn new(settings: LpvSettings, origin: Vec3, grids: &[Grid]) -> LpvData {
        let mut cascades = [GpuCascade::default(); MAX_CASCADES];
        for (slot, grid) in cascades.iter_mut().zip(grids) {
            *slot = GpuCascade {
                min: grid.min,
                cell: grid.cell,
            };
        }
        LpvData {
            settings,
            origin: origin.extend(1.0),
            cascades,
        }
    }
}

zoo_host::gpu_struct! {
    "lpv/rsm_camera.wgsl" =>
    /// The camera of one reflective shadow map (`lpv/rsm.wgsl`).
    #[derive(Debug, Clone, Copy)]
    pub struct RsmCamera {
        pub view_proj: Mat4,
        /// The light's position (perspective maps) and 1 when perspective.
        pub eye: Vec4,
        /// The map's axis, and the texel's world size per unit of distance along it
        /// (perspective) or absolute (orthographic).
        pub axis: Vec4,
        /// Positions are stored relative to this point (the scene's centre), for 16-bit floats.
        pub origin: Vec4,
        pub light: u32,
    }
}

impl RsmCamera {
    /// The camera of `frustum` for light `light` at `resolution` texels a side, storing
    /// positions relative to `origin`.
    pub fn new(frustum: &LightFrustum, light: usize, resolution: u32, origin: Vec3) -> RsmCamera {
        use zoo_shadow_maps::light_space::Projection;
        let inverse = frustum.view.inverse();
        let eye = inverse.w_axis.truncate();
        let axis = -inverse.z_axis.truncate().normalize();
        let (perspective, texel) = match frustum.projection {
            Projection::Perspective { tan_half_fov, .. } => {
                (1.0, 2.0 * tan_half_fov / resolution as f32)
            }
            Projection::Orthographic { extent, .. } => (0.0, extent / resolution as f32),
            Projection::Warped => (0.0, 0.0),
        };
        RsmCamera {
            view_proj: frustum.view_proj,
            eye: eye.extend(perspective),
            axis: axis.extend(texel),
            origin: origin.extend(1.0),
            light: light as u32,
        }
    }
}

/// The reflective shadow maps (flux, normal and area, position; a layer per light) and the
/// pass that renders them into [`RSM_MAPS`] and [`RSM_DEPTH`].
pub struct Rsm {
    stage: Stage,
    cameras: UniformSlots<RsmCamera>,
}

/// The reflective shadow maps' colour targets: name, format and how the debug view shows it.
pub const RSM_MAPS: [(&str, wgpu::TextureFormat, ViewMapping); 3] = [
    // Flux: scaled so a texel of the sun's brightness shows.
    (
        "RSM flux",
        wgpu::TextureFormat::Rgba16Float,
        color(0.0, 1e-3),
    ),
    (
        "RSM normals",
        wgpu::TextureFormat::Rgba16Float,
        color(-1.0, 1.0),
    ),
    (
        "RSM positions",
        wgpu::TextureFormat::Rgba16Float,
        color(-20.0, 20.0),
    ),
];
/// The reflective shadow maps' depth.
pub const RSM_DEPTH: &str = "RSM depth";
/// The volume debug views, in the order of `DEBUG_SOURCE_*` in `lpv/debug.wgsl` (one grid drawn
/// into one volume), each with its mapping.
pub static VOLUME_VIEWS: [(&str, ViewMapping); 3] = [
    ("light volume", color(0.0, 0.05)),
    ("geometry volume", color(0.0, 0.5)),
    ("emitter normals", color(0.0, 1.0)),
];
/// The grid bounds drawn over the screen.
pub const BOUNDS_VIEW: &str = "cascade bounds";

const fn color(min: f32, max: f32) -> ViewMapping {
    ViewMapping::Color { min, max }
}

/// Every texture: the reflective shadow maps of `rsm_layers` lights at `rsm_size` texels a
/// side, the debug volume of one `grid_size`³ grid and the grid bounds image.
pub fn texture_specs(rsm_size: u32, rsm_layers: u32, grid_size: u32) -> Vec<TextureSpec> {
    let rsm = |name, format, view| TextureSpec {
        size: TextureSize::Fixed(UVec2::splat(rsm_size)),
        layers: rsm_layers.max(1),
        array: true,
        ..TextureSpec::screen_target(name, format, view)
    };
    let mut specs: Vec<TextureSpec> = (RSM_MAPS.iter())
        .map(|&(name, format, view)| rsm(name, format, Some(view)))
        .collect();
    specs.push(rsm(RSM_DEPTH, wgpu::TextureFormat::Depth32Float, None));
    let [(volume, view), ref rest @ ..] = VOLUME_VIEWS;
    let storage = wgpu::TextureUsages::STORAGE_BINDING;
    specs.push(TextureSpec {
        size: TextureSize::Volume(UVec3::splat(grid_size)),
        usage: storage,
        aliases: rest.to_vec(),
        ..TextureSpec::screen_target(volume, wgpu::TextureFormat::Rgba16Float, Some(view))
    });
    let bounds = wgpu::TextureFormat::Rgba8Unorm;
    specs.push(TextureSpec {
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | storage,
        ..TextureSpec::screen_target(BOUNDS_VIEW, bounds, Some(color(0.0, 1.0)))
    });
    specs
}

/// The reflective shadow map passes (one per map: a light's, or each cube face's of a point
/// light, `"LPV RSM: light {l}"`, `"… face {f}"`).
pub const RSM_PASS: &str = "LPV RSM";
/// The injection of virtual point lights and their surfels.
pub const INJECT_PASS: &str = "LPV injection";
/// The injection of the camera's surfels into the occluders.
pub const CAMERA_OCCLUDERS_PASS: &str = "LPV camera occluders";
/// The pass that turns the fixed-point sums into the first step.
pub const RESOLVE_PASS: &str = "LPV resolve";
/// The propagation steps (`"LPV propagation {i}"`).
pub const PROPAGATE_PASS: &str = "LPV propagation";
/// The passes that spread the emitters' normal moments (one per axis, twice).
pub const SPREAD_PASS: &str = "LPV spread emitter normals";
/// The lookup into the indirect target.
pub const LOOKUP_PASS: &str = "LPV lookup";
/// The pass that draws a grid into the debug volume.
pub const DEBUG_VOLUME_PASS: &str = "LPV debug volume";
/// The pass that draws the grid bounds.
pub const DEBUG_BOUNDS_PASS: &str = "LPV debug bounds";

impl Rsm {
    /// Builds the pipeline (MRT: flux, normal and area, position; depth).
    pub fn new(ctx: &RenderContext<'_>) -> TechniqueResult<Rsm> {
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let cameras = UniformSlots::new(ctx.gpu, "lpv rsm cameras", 1, stages);
        let targets: Vec<Option<wgpu::ColorTargetState>> = RSM_MAPS
            .iter()
            .map(|&(_, format, _)| {
                Some(wgpu::ColorTargetState {
                    format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })
            })
            .collect();
        let stage = Stage::render("lpv/rsm.wgsl", "vs_rsm")
            .fragment("fs_rsm")
            .vertex_buffers(&SceneBuffers::VERTEX_LAYOUTS)
            .targets(&targets)
            .depth_stencil(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: Default::default(),
                bias: Default::default(),
            })
            .shared(&[&cameras.at(0)])
            .build(ctx)?;
        Ok(Rsm { stage, cameras })
    }

    /// Uploads one camera per layer.
    pub fn prepare(&mut self, ctx: &RenderContext<'_>, cameras: &[RsmCamera]) {
        self.cameras.write(ctx.gpu, cameras);
    }

    /// Renders every layer of the maps in `targets` (see [`texture_specs`]), one a (light,
    /// face) of `layers`: one pass each, `"LPV RSM: light {l}"` (`"… face {f}"` for a point
    /// light's cube faces).
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        targets: &NamedTextures,
        layers: &[(usize, usize)],
    ) -> TechniqueResult {
        for (layer, &(light, face)) in layers.iter().enumerate() {
            let view = |name| {
                (targets.layer_view(name, layer as u32)).ok_or_else(TechniqueError::not_prepared)
            };
            let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
            let colors = (RSM_MAPS.iter())
                .map(|m| Ok(zoo_host::gpu::color_attachment(view(m.0)?, clear)))
                .collect::<TechniqueResult<Vec<_>>>()?;
            let depth = view(RSM_DEPTH)?;
            let cube = layers.iter().filter(|(l, _)| *l == light).count() > 1;
            let mut label = kit::light_pass_name(RSM_PASS, light);
            if cube {
                label = format!("{label} face {face}");
            }
            let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
                label: Some(&label),
                color_attachments: &colors,
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: depth,
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
            let camera = [&self.cameras.at(layer) as &dyn SharedGroup];
            self.stage.set_on(ctx, &mut pass, &[], &camera)?;
            ctx.scene_buffers.draw_objects(&mut pass, ctx.scene, false);
        }
        Ok(())
    }
}

/// The grids' buffers: fixed-point injection sums, two propagation steps and the accumulated
/// light.
pub struct Volumes {
    pub cells: u64,
    pub light_sums: wgpu::Buffer,
    pub occluder_sums: wgpu::Buffer,
    pub steps: [wgpu::Buffer; 2],
    pub accumulated: wgpu::Buffer,
    /// The accumulated light after half the steps (a coarser grid's share of what the next
    /// finer grid already carries).
    pub near: wgpu::Buffer,
    /// Fixed-point sums of the emitters' normal moments (per colour: flux x normal, flux).
    pub moment_sums: wgpu::Buffer,
    /// The moments, resolved (0) and spread (ping-pong with 1; back in 0 after the six
    /// passes).
    pub moments: [wgpu::Buffer; 2],
}

impl Volumes {
    /// Buffers for `cells` cells over all grids.
    pub fn new(gpu: &GpuContext, cells: u64) -> Volumes {
        let buffer = |label: &str, size: u64| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let light = cells * 3 * 16;
        Volumes {
            cells,
            light_sums: buffer("lpv light sums", cells * 12 * 4),
            occluder_sums: buffer("lpv occluder sums", 2 * cells * 4 * 4),
            steps: [buffer("lpv step a", light), buffer("lpv step b", light)],
            accumulated: buffer("lpv accumulated light", light),
            near: buffer("lpv light within half the steps", light),
            moment_sums: buffer("lpv emitter moment sums", cells * 12 * 4),
            moments: [
                buffer("lpv emitter moments a", light),
                buffer("lpv emitter moments b", light),
            ],
        }
    }
}

/// The largest channel of a colour.
pub fn brightest(c: Vec3) -> f32 {
    c.max_element().max(0.0)
}
