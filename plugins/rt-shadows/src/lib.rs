//! Ray-traced shadows on any adapter: from each pixel's surface, any-hit shadow rays through
//! the scene's casters (`zoo-ray-tracing`: a bounding volume hierarchy walked in a fragment
//! shader, or hardware ray queries where the device has them):
//! one ray to each light's centre gives exact hard shadows; several rays to points of the
//! light's disk (a rotated low-discrepancy pattern per pixel, continued frame after frame)
//! give soft ones, averaged over the frames of a still view ([`history`]) and smoothed by an
//! edge-aware spatial filter guided by the G-buffer's depth and normals.

use zoo_host::prelude::*;
use zoo_host::{ResourceInfo, Scene};
use zoo_ray_tracing::{RayTracing, TracePass, Tracer, Traversal};

mod blocker;
mod history;

use blocker::BlockerView;
use history::History;
use zoo_host::render::visibility::VISIBILITY_FORMAT;
use zoo_host::technique::DebugImage;

zoo_host::technique_params! {
    /// Parameters of ray-traced shadows.
    pub struct RtParams {
        /// Shadow rays per pixel and light toward points of the light's disk; 1 traces one ray
        /// to its centre (hard shadows), as do lights without a radius.
        rays_per_pixel: u32 = 4, range(1, 64), step(1);
        /// Radius in pixels of the filter that smooths soft shadows' noise (0: off); lights
        /// traced with one ray are left as they are. It narrows as frames accumulate.
        denoise_radius: u32 = 2, range(0, 8), step(1);
        /// Frames of soft shadows averaged while nothing moves (1: each frame on its own, its
        /// rays the same every frame); each frame traces a new pattern.
        accumulation: u32 = 16, range(1, 256), step(1);
        /// How rays find casters: hardware ray queries where the device has them (`Auto`), the
        /// portable BVH walk (`Compute`), or ray queries only (`RayQuery`).
        traversal: Traversal = Traversal::Auto, flags(rebuild);
        /// Trace the `blocker distance` debug view of `debug_light`: the distance to the
        /// nearest caster toward its centre (a closest-hit ray a pixel).
        blocker_distance: bool = false;
        /// Light whose blocker distance the debug view shows.
        debug_light: u32 = 0, range(0, 1023), step(1);
    }
}

zoo_host::gpu_struct! {
    "rt-shadows/rt_light.wgsl" =>
    /// The per-light uniform of rt-shadows' passes (`rt-shadows/light.wgsl`): the light, its
    /// rays per pixel, its visibility slot, the filter's radius for it and its accumulation.
    #[derive(Debug, Clone, Copy)]
    pub(crate) struct RtLight {
        light: u32,
        /// Rays per pixel toward the light's disk (1: its centre).
        rays: u32,
        /// The light's visibility slot: array layer and channel.
        layer: u32,
        channel: u32,
        /// Radius in pixels of the denoising filter (0: the history as it is).
        denoise_radius: u32,
        /// 1: a soft light, traced into the history (`fs_accumulate`) and resolved into its
        /// slot by the filter; 0: traced straight into its slot (`fs_main`).
        soft: u32,
        /// Frames since the view last changed: where the sample sequence continues.
        frame: u32,
    }
}

const TRACE_SHADER: &str = "rt-shadows/shadows.wgsl";
const DENOISE_SHADER: &str = "rt-shadows/denoise.wgsl";
/// Base names of the per-light passes.
const TRACE_PASS: &str = "Ray-traced shadows";
const DENOISE_PASS: &str = "Denoise";

/// The pipelines, the hierarchy they trace and the soft lights' history.
struct Gpu {
    tracer: Tracer,
    tracing_layout: wgpu::BindGroupLayout,
    trace: FullscreenLightPass<RtLight>,
    accumulation: TracePass<RtLight>,
    denoise: FullscreenLightPass<RtLight>,
    transmittance: TracePass<RtLight>,
    blocker: BlockerView,
    tracing: Option<RayTracing>,
    history: Option<History>,
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>, traversal: Traversal) -> TechniqueResult<Gpu> {
        let device = &ctx.gpu.device;
        let tracer = Tracer::choose(traversal, device, "rt-shadows")?;
        let tracing_layout = tracer.layout(device);
        let trace_text = zoo_ray_tracing::shader_source(ctx.shaders, TRACE_SHADER, tracer)?;
        let tracing = tracer.group(&tracing_layout, None);
        let shared = [&tracing as &dyn kit::SharedGroup];
        let trace =
            FullscreenLightPass::from_source(ctx, TRACE_SHADER, &trace_text, "fs_main", &shared)?;
        let entry = |entry| (TRACE_SHADER, trace_text.as_str(), entry);
        let accumulation = TracePass::new(
            ctx,
            "Accumulate",
            entry("fs_accumulate"),
            history::accumulation_target(),
            &tracing,
        )?;
        let denoise = FullscreenLightPass::new(ctx, DENOISE_SHADER, "fs_denoise", &[])?;
        let transmittance = TracePass::new(
            ctx,
            "Transmittance",
            entry("fs_transmittance"),
            zoo_ray_tracing::replace_target(VISIBILITY_FORMAT),
            &tracing,
        )?;
        let blocker = BlockerView::new(&trace_text);
        Ok(Gpu {
            tracer,
            tracing_layout,
            trace,
            accumulation,
            denoise,
            transmittance,
            blocker,
            tracing: None,
            history: None,
        })
    }
}

struct RtShadows {
    params: RtParams,
    gpu: LazyGpu<Gpu>,
    /// Frames accumulated since the view, the lights, the scene or a parameter last changed.
    frames: u32,
    /// Whether the last frame had soft lights (which accumulate).
    soft_lights: bool,
}

impl ShadowTechnique for RtShadows {
    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let traversal = self.params.traversal;
        let gpu = self.gpu.prepare(false, || Gpu::new(ctx, traversal))?;
        if changes.scene || gpu.tracing.as_ref().is_none_or(|t| !t.is_for(ctx)) {
            let tracing = RayTracing::new(ctx, gpu.tracer, &gpu.tracing_layout)?;
            gpu.tracing = Some(tracing);
        }
        let Changes {
            scene,
            lights,
            resolution,
            camera,
            params,
        } = changes;
        if scene || lights || resolution || camera || params {
            self.frames = 0;
        }
        Ok(())
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let p = &self.params;
        let gpu = self.gpu.get_mut()?;
        // Soft lights are traced into the history and resolved by the filter; hard ones (one
        // ray, or no radius) are exact as traced.
        let soft = |light: usize| p.rays_per_pixel > 1 && ctx.lights[light].radius > 0.0;
        let soft_lights: Vec<usize> = (0..ctx.lights.len()).filter(|&l| soft(l)).collect();
        self.soft_lights = !soft_lights.is_empty();
        if gpu.history.as_ref().is_some_and(|h| !h.fits(ctx)) || !self.soft_lights {
            gpu.history = None;
        }
        if self.soft_lights && gpu.history.is_none() {
            gpu.history = Some(History::new(ctx, gpu.denoise.stage())?);
            self.frames = 0;
        }
        // The n-th frame since a change weighs 1/n; past `accumulation`, a moving average.
        let accumulated = self.frames.min(p.accumulation - 1);
        let new_frame_weight = 1.0 / f64::from(accumulated + 1);
        // The filter narrows as the noise falls with the frames averaged.
        let radius = (p.denoise_radius as f32 / ((accumulated + 1) as f32).sqrt()) as u32;
        let frame = if p.accumulation > 1 { self.frames } else { 0 };
        let per_light = |light: usize| {
            let (layer, channel) = ctx.visibility.slots.slot(light);
            RtLight {
                light: light as u32,
                rays: p.rays_per_pixel,
                layer,
                channel,
                denoise_radius: radius,
                soft: u32::from(soft(light)),
                frame,
            }
        };
        let traced = gpu.tracing.as_ref();
        let tracing = gpu.tracer.group(&gpu.tracing_layout, traced);
        let tracing: &dyn kit::SharedGroup = &tracing;
        (gpu.trace).record_with(ctx, rec, TRACE_PASS, per_light, &[], &[tracing])?;
        if let Some(history) = &gpu.history {
            let layer = |light: usize| {
                (soft_lights.contains(&light))
                    .then(|| history.target(ctx, light))
                    .flatten()
            };
            let blend = |light| Some(History::blend(ctx, light, new_frame_weight));
            (gpu.accumulation).record(ctx, rec, tracing, per_light, layer, blend)?;
            let own = [&history.group];
            (gpu.denoise).record_with(ctx, rec, DENOISE_PASS, per_light, &own, &[])?;
            self.frames = self.frames.saturating_add(1);
        }
        if ctx.transmittance.in_use {
            // Each light's colour into its transmittance slot (white until written).
            let slot = |light| zoo_ray_tracing::transmittance_slot(ctx, light);
            let no_blend = |_| None;
            (gpu.transmittance).record(ctx, rec, tracing, per_light, slot, no_blend)?;
        }
        let debug_light = p.debug_light as usize;
        if p.blocker_distance && debug_light < ctx.lights.len() {
            let tracing = (TRACE_SHADER, tracing);
            (gpu.blocker).record(ctx, rec, tracing, per_light, debug_light)?;
        }
        Ok(())
    }

    fn writes_transmittance(&self, scene: &Scene) -> bool {
        scene.has_translucent_casters()
    }

    fn frames_to_converge(&self) -> u32 {
        if self.soft_lights {
            self.params.accumulation
        } else {
            1
        }
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        Ok(self.params.update(values)?)
    }

    fn counters(&self) -> Vec<(String, f64)> {
        let tracing = self.gpu.built().and_then(|g| g.tracing.as_ref());
        let mut counters = tracing.map(|t| t.stats.counters()).unwrap_or_default();
        if self.soft_lights {
            // Frames in the average (past `accumulation`, a moving average of about as many).
            let frames = self.frames.min(self.params.accumulation);
            counters.push(("frames accumulated".to_string(), f64::from(frames)));
        }
        counters
    }

    fn resources(&self) -> Vec<ResourceInfo> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let history = (gpu.history.iter()).flat_map(History::resources);
        let blocker = (gpu.blocker.resource()).filter(|_| self.params.blocker_distance);
        history.chain(blocker).collect()
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let gpu = self.gpu.built()?;
        // Only while it is traced: a view left from before would be stale.
        (resource == blocker::VIEW && self.params.blocker_distance)
            .then(|| gpu.blocker.debug_image())
            .flatten()
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = RtParams::from_values(values)?;
    Ok(Box::new(RtShadows {
        params,
        gpu: LazyGpu::default(),
        frames: 0,
        soft_lights: false,
    }))
}

zoo_host::register_technique! {
    id: "rt-shadows",
    name: "Ray-traced shadows",
    description: "Any-hit shadow rays through the scene's BVH in a fragment shader, or by hardware ray queries: one to each light (hard) or several to its disk (soft)",
    source: "ray tracing (the judge's visibility on the GPU)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    // The frame's lights and objects and the hierarchy's five buffers (nodes, triangles,
    // texture coordinates, translucent objects, instances), in fragment shaders.
    required_limits: || wgpu::Limits {
        max_storage_buffers_per_shader_stage: 7,
        ..wgpu::Limits::downlevel_defaults()
    },
    // Hardware ray queries where the adapter has them (`traversal` Auto or RayQuery).
    optional_features: || wgpu::Features::EXPERIMENTAL_RAY_QUERY,
    params: RtParams::schema,
    create: create,
}
