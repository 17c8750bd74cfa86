//! Per-triangle shadow volumes over a hierarchy of view samples (Sintorn, Olsson and
//! Assarsson 2011; Sintorn, Kämpe, Olsson and Assarsson 2014): exact hard shadows from any
//! triangle soup without silhouettes or stencil, computed per light in three compute steps
//! (`shaders/per-triangle-volumes/volumes.wgsl`):
//!
//! 1. each pixel's view sample, the hard shadow ray its surface sends to the light (the judge's
//!    and rt-shadows' ray), and a hierarchy of boxes over the samples' origins: two depth
//!    clusters in each 8x8-pixel tile, then 8x8 tiles of those, twice;
//! 2. every caster triangle's volume (three planes through the light and its edges,
//!    and its own plane) tested against the hierarchy top down, one workgroup a triangle whose
//!    64 invocations take a node's 64 children, or a leaf's 64 samples, at once: nodes outside
//!    a plane are skipped, nodes inside all four are shadowed whole (opaque triangles), and at the leaves
//!    each sample's ray is tested exactly against the triangle, its alpha mask included (the
//!    ray-tracing library's own triangle test);
//! 3. a full-screen pass writes visibility 0 where a triangle stopped the ray.
//!
//! The casters come from the ray-tracing library's upload: instances share their mesh's
//! triangles, visited once per instance through its placement.

use std::sync::Mutex;
use zoo_host::prelude::*;

use zoo_host::gpu::readback::ReadbackRing;
use zoo_ray_tracing::{RESOLVE_SHADOWED_SHADER, RayTracing, Tracer};

mod samples;

use samples::ViewSamples;

zoo_host::technique_params! {
    /// Parameters of per-triangle shadow volumes.
    pub struct PtvParams {
        /// Cull the hierarchy's nodes by each triangle's volume; off, every triangle in the
        /// light's range tests every sample (the same shadows, to measure what the hierarchy
        /// saves).
        hierarchy: bool = true;
    }
}

zoo_host::gpu_struct! {
    "per-triangle-volumes/ptv_light.wgsl" =>
    /// The per-light uniform of the volume passes: the light, the frame's size, the flat count
    /// of caster triangles, and whether the hierarchy culls.
    #[derive(Debug, Clone, Copy)]
    pub(crate) struct PtvLight {
        light: u32,
        width: u32,
        height: u32,
        triangles: u32,
        hierarchy: u32,
    }
}

const VOLUMES_SHADER: &str = "per-triangle-volumes/volumes.wgsl";
/// Workgroups of the triangle pass, each taking 64 triangles in turn, every
/// `TRIANGLE_GROUPS`-th 64 (`TRIANGLE_GROUPS` in the shader).
const TRIANGLE_GROUPS: u32 = 2048;
/// Invocations of a triangle pass workgroup (`GROUP` in the shader).
const GROUP: u32 = 64;

/// The stages, the casters and the per-light uniforms.
struct Gpu {
    tracing_layout: wgpu::BindGroupLayout,
    tracing: Option<RayTracing>,
    uniforms: kit::UniformSlots<PtvLight>,
    samples: kit::Stage,
    reduce: [kit::Stage; 2],
    triangles: kit::Stage,
    resolve: kit::Stage,
    /// The view samples, the hierarchy and the shadowed flags, for the current frame size.
    buffers: Option<ViewSamples>,
    /// The lights' counters, read back a frame or two late.
    stats: Option<Mutex<ReadbackRing>>,
    device: wgpu::Device,
}

impl Gpu {
    /// Each counter summed over the lights, from the newest frame whose counters have arrived
    /// (none until one has; never waits for the GPU).
    fn totals(&self) -> Option<[u64; samples::COUNTERS as usize]> {
        let mut ring = self.stats.as_ref()?.lock().ok()?;
        let (_, bytes) = ring.latest(&self.device)?;
        let mut totals = [0u64; samples::COUNTERS as usize];
        for (i, word) in bytes.chunks_exact(4).enumerate() {
            let value = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
            totals[i % totals.len()] += u64::from(value);
        }
        Some(totals)
    }
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>) -> TechniqueResult<Gpu> {
        let tracing_layout = Tracer::Compute.layout(&ctx.gpu.device);
        let uniforms = kit::UniformSlots::new(
            ctx.gpu,
            "per-triangle volumes lights",
            ctx.lights.len().max(1),
            wgpu::ShaderStages::COMPUTE,
        );
        let tracing = Tracer::Compute.group(&tracing_layout, None);
        let compute = |entry| {
            kit::Stage::compute(VOLUMES_SHADER, entry)
                .shared(&[&uniforms.at(0), &tracing])
                .build(ctx)
        };
        Ok(Gpu {
            samples: compute("cs_samples")?,
            reduce: [compute("cs_reduce1")?, compute("cs_reduce2")?],
            triangles: compute("cs_triangles")?,
            resolve: kit::Stage::fullscreen(RESOLVE_SHADOWED_SHADER, "fs_resolve").build(ctx)?,
            tracing_layout,
            tracing: None,
            uniforms,
            buffers: None,
            stats: None,
            device: ctx.gpu.device.clone(),
        })
    }
}

struct PerTriangleVolumes {
    params: PtvParams,
    gpu: LazyGpu<Gpu>,
}

impl ShadowTechnique for PerTriangleVolumes {
    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let gpu = self.gpu.prepare(false, || Gpu::new(ctx))?;
        let tracing = match &mut gpu.tracing {
            Some(tracing) if !changes.scene && tracing.is_for(ctx) => tracing,
            slot => {
                gpu.buffers = None;
                slot.insert(RayTracing::new(ctx, Tracer::Compute, &gpu.tracing_layout)?)
            }
        };
        if gpu.buffers.as_ref().is_none_or(|b| !b.fits(ctx)) {
            let stages = (&gpu.samples, &gpu.reduce, &gpu.triangles, &gpu.resolve);
            let buffers = ViewSamples::new(ctx, stages, tracing)?;
            let label = "per-triangle volumes counters";
            let ring = ReadbackRing::new(&ctx.gpu.device, label, buffers.counts.size(), 3);
            gpu.stats = Some(Mutex::new(ring));
            gpu.buffers = Some(buffers);
        }
        Ok(())
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let gpu = self.gpu.get_mut()?;
        let (Some(tracing), Some(buffers)) = (&gpu.tracing, &gpu.buffers) else {
            return Ok(());
        };
        let size = ctx.size;
        let triangles = tracing.caster_triangles();
        let values: Vec<PtvLight> = (0..ctx.lights.len())
            .map(|light| PtvLight {
                light: light as u32,
                width: size.x,
                height: size.y,
                triangles,
                hierarchy: u32::from(self.params.hierarchy),
            })
            .collect();
        gpu.uniforms.write(ctx.gpu, &values);
        let tracing = Tracer::Compute.group(&gpu.tracing_layout, Some(tracing));
        // A workgroup of 8x8 invocations a node of each level.
        let levels = samples::LEVEL_SPANS.map(|span| {
            let b = samples::BRANCHING;
            [size.x.div_ceil(span) * b, size.y.div_ceil(span) * b, 1]
        });
        for light in 0..ctx.lights.len() {
            let slot = gpu.uniforms.at(light);
            let shared = [&slot as &dyn kit::SharedGroup, &tracing];
            let name = kit::light_pass_name("Per-triangle volumes", light);
            let mut pass = rec.compute_pass(&name);
            let [samples, reduce1, reduce2, volumes] = &buffers.groups;
            gpu.samples
                .dispatch_in(ctx, &mut pass, (&[samples], &shared), levels[0])?;
            gpu.reduce[0].dispatch_in(ctx, &mut pass, (&[reduce1], &shared), levels[1])?;
            gpu.reduce[1].dispatch_in(ctx, &mut pass, (&[reduce2], &shared), levels[2])?;
            if triangles > 0 {
                let extent = [triangles.div_ceil(GROUP).min(TRIANGLE_GROUPS) * GROUP, 1, 1];
                gpu.triangles
                    .dispatch_in(ctx, &mut pass, (&[volumes], &shared), extent)?;
            }
            drop(pass);
            let name = kit::light_pass_name("Per-triangle volumes resolve", light);
            let mut pass = ctx.light_pass(rec, &name, light, None);
            gpu.resolve
                .set_on(ctx, &mut pass, &[&buffers.resolve_group], &[])?;
            pass.draw(0..3, 0..1);
        }
        let stats = gpu.stats.as_ref().and_then(|s| s.lock().ok());
        if let Some(target) = stats.and_then(|mut ring| ring.target().cloned()) {
            let bytes = buffers.counts.size();
            rec.encoder()
                .copy_buffer_to_buffer(&buffers.counts, 0, &target, 0, bytes);
        }
        Ok(())
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        Ok(self.params.update(values)?)
    }

    fn counters(&self) -> Vec<(String, f64)> {
        let gpu = self.gpu.built();
        let tracing = gpu.and_then(|g| g.tracing.as_ref());
        let triangles = tracing.map_or(0, RayTracing::caster_triangles);
        let batches = tracing.map_or(0, |t| t.batches.len());
        let mut counters = vec![
            ("caster triangles".to_string(), f64::from(triangles)),
            ("caster batches".to_string(), batches as f64),
        ];
        if let Some([descended, nodes, tests]) = gpu.and_then(Gpu::totals) {
            counters.extend([
                ("triangles down the hierarchy".to_string(), descended as f64),
                ("nodes classified".to_string(), nodes as f64),
                ("samples tested exactly".to_string(), tests as f64),
            ]);
        }
        counters
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    Ok(Box::new(PerTriangleVolumes {
        params: PtvParams::from_values(values)?,
        gpu: LazyGpu::default(),
    }))
}

zoo_host::register_technique! {
    id: "per-triangle-volumes",
    name: "Per-triangle shadow volumes",
    description: "Every caster triangle's shadow volume tested against a hierarchy of the pixels' shadow rays, the leaves exactly; compute only, masked casters included",
    source: "Sintorn, Olsson, Assarsson 2011; Sintorn, Kämpe, Olsson, Assarsson 2014",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    required_limits: zoo_ray_tracing::per_triangle_limits,
    required_downlevel: || wgpu::DownlevelFlags::COMPUTE_SHADERS,
    params: PtvParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_match_the_shader() {
        use zoo_host::gpu::layout::wgsl_integer_constant;
        let library = zoo_host::ShaderLibrary::embedded();
        let source = library.compose(VOLUMES_SHADER).unwrap().source;
        let constant = |name| wgsl_integer_constant(&source, name);
        assert_eq!(constant("TRIANGLE_GROUPS"), Ok(i64::from(TRIANGLE_GROUPS)));
        assert_eq!(constant("CLUSTERS"), Ok(samples::CLUSTERS as i64));
        assert_eq!(constant("BRANCHING"), Ok(i64::from(samples::BRANCHING)));
        // No more workgroups than a dispatch takes along one axis.
        let limits = wgpu::Limits::downlevel_defaults();
        assert_eq!(constant("GROUP"), Ok(i64::from(GROUP)));
        assert_eq!(constant("COUNTERS"), Ok(samples::COUNTERS as i64));
        assert!(TRIANGLE_GROUPS <= limits.max_compute_workgroups_per_dimension);
    }
}
