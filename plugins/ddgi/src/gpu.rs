//! ddgi's GPU side: the stages, the probes' buffer, the counters read back and the debug
//! views.

use std::sync::Mutex;

use zoo_host::glam::UVec2;
use zoo_host::gpu::readback::ReadbackRing;
use zoo_host::gpu::{GpuType, gpu_bytes};
use zoo_host::kit::{NamedTextures, SharedGroup, Stage, TextureSize, TextureSpec};
use zoo_host::prelude::*;
use zoo_host::render::visibility::VISIBILITY_FORMAT;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_ray_tracing::{RayTracing, TracePass, Tracer, replace_target, transmittance_slot};

use crate::{DISTANCE_TEXELS, DdgiGrid, DdgiLight, IRRADIANCE_TEXELS, ProbeGrid};

pub const TRACE_PASS: &str = "Probe rays";
pub const RELOCATE_PASS: &str = "Probe relocation";
pub const IRRADIANCE_PASS: &str = "Probe irradiance";
pub const DISTANCE_PASS: &str = "Probe distance";
pub const LOOKUP_PASS: &str = "Indirect lookup";
pub const SHADOW_PASS: &str = "Ray-traced shadows";
const TRANSMITTANCE_PASS: &str = "Transmittance";
const SHADOW_SHADER: &str = "ddgi/shadows.wgsl";
const DEBUG_PASS: &str = "Probe debug view";

/// What the relocation pass counts (`ddgi_counts` in `ddgi/probes.wgsl`), in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Count {
    Active,
    Moved,
    Inside,
}

impl Count {
    pub const ALL: [Count; 3] = [Count::Active, Count::Moved, Count::Inside];

    /// How the counters name it.
    pub fn name(self) -> &'static str {
        match self {
            Count::Active => "probes active",
            Count::Moved => "probes moved",
            Count::Inside => "probes inside geometry",
        }
    }
}

/// The debug views: their names, the entry of `ddgi/debug.wgsl` that draws them, and the
/// texels of a probe's tile (0: a fixed 64 x 64 image).
pub const DEBUG_VIEWS: [(&str, &str, u32); 4] = [
    (
        "probe irradiance",
        "cs_irradiance_tiles",
        IRRADIANCE_TEXELS + 2,
    ),
    ("probe distance", "cs_distance_tiles", DISTANCE_TEXELS + 2),
    ("probe states", "cs_states", 1),
    ("probe rays", "cs_rays", 0),
];

/// Vec4s of `ddgi/probes.wgsl`'s buffer for `probes` probes of `rays` rays: states, irradiance
/// tiles, distance tiles and rays.
pub fn buffer_vec4s(probes: u32, rays: u32) -> u64 {
    let tile = |texels: u32| u64::from(texels + 2).pow(2);
    u64::from(probes) * (1 + tile(IRRADIANCE_TEXELS) + tile(DISTANCE_TEXELS) + u64::from(rays))
}

/// Probe tiles a row of the debug atlases: about as many rows as columns.
pub fn tiles_per_row(probes: u32) -> u32 {
    (f64::from(probes).sqrt().ceil() as u32).max(1)
}

/// The debug views' textures for `probes` probes.
fn view_specs(probes: u32) -> Vec<TextureSpec> {
    let columns = tiles_per_row(probes);
    let rows = probes.div_ceil(columns).max(1);
    (DEBUG_VIEWS.iter())
        .map(|&(name, _, tile)| TextureSpec {
            name,
            size: TextureSize::Fixed(match tile {
                0 => UVec2::splat(64),
                tile => UVec2::new(columns, rows) * tile,
            }),
            layers: 1,
            array: false,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING,
            view: Some(ViewMapping::Color { min: 0.0, max: 1.0 }),
            aliases: Vec::new(),
        })
        .collect()
}

/// The probes' buffer and what it was made for.
pub struct Probes {
    pub grid: ProbeGrid,
    pub rays: u32,
    pub data: wgpu::Buffer,
}

struct Stages {
    trace: Stage,
    relocate: Stage,
    irradiance: Stage,
    distance: Stage,
    lookup: Stage,
    /// One per [`DEBUG_VIEWS`] entry.
    debug: Vec<Stage>,
}

/// Everything on the GPU.
pub struct Gpu {
    device: wgpu::Device,
    tracing_layout: wgpu::BindGroupLayout,
    pub tracing: Option<RayTracing>,
    /// The object of each traced triangle and instance, and where the instances start.
    pub objects: Option<(wgpu::Buffer, u32)>,
    stages: Stages,
    shadows: FullscreenLightPass<DdgiLight>,
    /// Each light's colour that translucent casters let through, into its transmittance slot.
    transmittance: TracePass<DdgiLight>,
    uniform: wgpu::Buffer,
    pub probes: Option<Probes>,
    /// [`Count`]s of the last relocation, and their way back.
    counts: wgpu::Buffer,
    readback: Mutex<ReadbackRing>,
    /// The readback frame ([`ReadbackRing::frames`]) the last counting frame copied into: older
    /// results (a run before the probes started over) are not this run's.
    counted: Option<u64>,
    views: NamedTextures,
}

/// What one frame runs.
pub struct Frame {
    pub grid: DdgiGrid,
    /// The maps start over (every probe at home and active until classified).
    pub start: bool,
    pub relocating: bool,
    /// The relocation pass counts the probes ([`Count`]).
    pub counting: bool,
    /// Direct shadow rays a pixel and light.
    pub shadow_rays: u32,
    /// Frames since the probes started over (where the shadow rays' sequence continues).
    pub frame: u32,
}

impl Gpu {
    pub fn new(ctx: &RenderContext<'_>) -> TechniqueResult<Gpu> {
        let device = &ctx.gpu.device;
        let tracing_layout = Tracer::Compute.layout(device);
        let tracing = Tracer::Compute.group(&tracing_layout, None);
        let shared = [&tracing as &dyn SharedGroup];
        let stage = |shader, entry| Stage::compute(shader, entry).shared(&shared).build(ctx);
        let debug = (DEBUG_VIEWS.iter())
            .map(|(_, entry, _)| stage("ddgi/debug.wgsl", entry))
            .collect::<TechniqueResult<Vec<_>>>()?;
        let stages = Stages {
            trace: stage("ddgi/trace.wgsl", "cs_trace")?,
            relocate: stage("ddgi/update.wgsl", "cs_relocate")?,
            irradiance: stage("ddgi/update.wgsl", "cs_irradiance")?,
            distance: stage("ddgi/update.wgsl", "cs_distance")?,
            lookup: stage("ddgi/lookup.wgsl", "cs_lookup")?,
            debug,
        };
        let shadows = FullscreenLightPass::new(ctx, SHADOW_SHADER, "fs_shadow", &shared)?;
        let text = ctx.shaders.source(SHADOW_SHADER)?;
        let transmittance = TracePass::new(
            ctx,
            TRANSMITTANCE_PASS,
            (SHADOW_SHADER, &text, "fs_transmittance"),
            replace_target(VISIBILITY_FORMAT),
            &tracing,
        )?;
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let uniform = buffer(
            "ddgi grid",
            DdgiGrid::SIZE as u64,
            wgpu::BufferUsages::UNIFORM,
        );
        let count_bytes = 4 * Count::ALL.len() as u64;
        let counts = buffer(
            "ddgi probe counts",
            count_bytes,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        );
        let readback = ReadbackRing::new(device, "ddgi probe counts", count_bytes, 3);
        Ok(Gpu {
            device: device.clone(),
            tracing_layout,
            tracing: None,
            objects: None,
            stages,
            shadows,
            transmittance,
            uniform,
            probes: None,
            counts,
            readback: Mutex::new(readback),
            counted: None,
            views: NamedTextures::new("ddgi", view_specs(1)),
        })
    }

    /// Uploads `ctx`'s scene's casters for the probes' rays and the direct shadows.
    pub fn trace_scene(&mut self, ctx: &RenderContext<'_>) -> TechniqueResult {
        let tracing = RayTracing::new(ctx, Tracer::Compute, &self.tracing_layout)?;
        self.objects = Some(tracing.object_buffer(ctx, "ddgi surface objects"));
        self.tracing = Some(tracing);
        Ok(())
    }

    /// The probes' buffer for `grid` and `rays`, made anew when either changes (true then);
    /// an error when the device cannot bind it whole.
    pub fn probes_for(
        &mut self,
        ctx: &RenderContext<'_>,
        grid: ProbeGrid,
        rays: u32,
    ) -> TechniqueResult<bool> {
        if self
            .probes
            .as_ref()
            .is_some_and(|p| p.grid == grid && p.rays == rays)
        {
            return Ok(false);
        }
        let limits = ctx.gpu.device.limits();
        let groups = limits.max_compute_workgroups_per_dimension;
        if grid.probe_count() > groups {
            // The passes over probes dispatch a workgroup (row) a probe along one axis.
            return Err(TechniqueError::Other(format!(
                "{} probes ({} x {} x {}), above the device's {groups} workgroups along one                  axis; lower `probes`",
                grid.probe_count(),
                grid.counts.x,
                grid.counts.y,
                grid.counts.z
            )));
        }
        let bytes = buffer_vec4s(grid.probe_count(), rays) * 16;
        let limit = limits.max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(TechniqueError::Other(format!(
                "{} probes of {rays} rays need {} MiB, above the device's {} MiB a storage \
                 buffer; lower `probes` or `rays_per_probe`",
                grid.probe_count(),
                bytes >> 20,
                limit >> 20
            )));
        }
        let data = ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ddgi probes"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.probes = Some(Probes { grid, rays, data });
        self.views.respec_all(view_specs(grid.probe_count()));
        self.views.prepare(ctx);
        Ok(true)
    }

    /// Records the frame: the probes' rays, relocation, the maps' blending, the lookup, the
    /// direct shadows, and the debug view shown.
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        rec: &mut PassRecorder<'_>,
        frame: &Frame,
    ) -> TechniqueResult {
        let probes = self.probes.as_ref().expect("made in prepare");
        let (objects, _) = self.objects.as_ref().expect("made in prepare");
        ctx.gpu
            .queue
            .write_buffer(&self.uniform, 0, &gpu_bytes(&[frame.grid]));
        let count = probes.grid.probe_count();
        if frame.start {
            // (The queue's write lands before the frame's commands: the clear leaves it.)
            let states = gpu_bytes(&vec![zoo_host::glam::Vec4::W; count as usize]);
            ctx.gpu.queue.write_buffer(&probes.data, 0, &states);
            rec.encoder()
                .clear_buffer(&probes.data, states.len() as u64, None);
        }
        if frame.counting {
            rec.encoder().clear_buffer(&self.counts, 0, None);
        }
        let tracing = Tracer::Compute.group(&self.tracing_layout, self.tracing.as_ref());
        let shared = [&tracing as &dyn SharedGroup];
        let resources = [
            ("grid", self.uniform.as_entire_binding()),
            ("ddgi", probes.data.as_entire_binding()),
            ("surface_objects", objects.as_entire_binding()),
            (
                "indirect_out",
                wgpu::BindingResource::TextureView(&ctx.indirect.view),
            ),
            ("ddgi_counts", self.counts.as_entire_binding()),
        ];
        let run = |rec: &mut PassRecorder<'_>,
                   stage: &Stage,
                   name: &str,
                   extent,
                   extra: &[(&str, wgpu::BindingResource<'_>)]| {
            let list: Vec<_> = resources.iter().chain(extra).cloned().collect();
            let group = stage.bind(ctx, "ddgi group", &list)?;
            stage.dispatch(ctx, rec, name, &[&group], &shared, extent)
        };
        let s = &self.stages;
        run(rec, &s.trace, TRACE_PASS, [probes.rays, count, 1], &[])?;
        if frame.relocating {
            run(rec, &s.relocate, RELOCATE_PASS, [count, 1, 1], &[])?;
        }
        let side = IRRADIANCE_TEXELS + 2;
        run(
            rec,
            &s.irradiance,
            IRRADIANCE_PASS,
            [side, side, count],
            &[],
        )?;
        let side = DISTANCE_TEXELS + 2;
        run(rec, &s.distance, DISTANCE_PASS, [side, side, count], &[])?;
        let screen = [ctx.size.x, ctx.size.y, 1];
        run(rec, &s.lookup, LOOKUP_PASS, screen, &[])?;
        let per_light = |light: usize| DdgiLight {
            light: light as u32,
            rays: frame.shadow_rays,
            frame: frame.frame,
        };
        (self.shadows).record_with(ctx, rec, SHADOW_PASS, per_light, &[], &shared)?;
        if ctx.transmittance.in_use {
            let slot = |light| transmittance_slot(ctx, light);
            let no_blend = |_| None;
            (self.transmittance).record(ctx, rec, &tracing, per_light, slot, no_blend)?;
        }
        let shown = DEBUG_VIEWS
            .iter()
            .position(|(name, _, _)| Some(*name) == ctx.debug_view);
        if let Some(k) = shown {
            let name = DEBUG_VIEWS[k].0;
            let texture = self.views.texture(name).expect("declared");
            let view = self.views.view(name).expect("declared");
            let extent = [texture.width(), texture.height(), 1];
            let target = [("debug_out", wgpu::BindingResource::TextureView(view))];
            run(rec, &s.debug[k], DEBUG_PASS, extent, &target)?;
        }
        if frame.start {
            self.counted = None;
        }
        if frame.counting
            && let Ok(mut ring) = self.readback.lock()
            && let Some(target) = ring.target().cloned()
        {
            let bytes = self.counts.size();
            (rec.encoder()).copy_buffer_to_buffer(&self.counts, 0, &target, 0, bytes);
            self.counted = Some(ring.frames());
        }
        Ok(())
    }

    /// The [`Count`]s of the last relocation once they have arrived (never waits).
    pub fn counts(&self) -> Option<Vec<u32>> {
        let counted = self.counted?;
        let mut ring = self.readback.lock().ok()?;
        let (frame, bytes) = ring.latest(&self.device)?;
        if frame < counted {
            return None;
        }
        Some(
            (bytes.chunks_exact(4))
                .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
                .collect(),
        )
    }

    pub fn resources(&self) -> Vec<ResourceInfo> {
        self.views.resources()
    }

    pub fn debug_view(&self, name: &str) -> Option<DebugImage<'_>> {
        self.views.debug_view(name)
    }
}
