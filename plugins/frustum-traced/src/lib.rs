//! Frustum-traced shadows over an irregular z-buffer (Wyman, Hoetzlein and Lefohn, I3D 2015;
//! TVCG 2016): exact hard shadows from any triangle soup, computed per light in three compute
//! steps and a resolve (`shaders/frustum-traced/izb.wgsl`):
//!
//! 1. each pixel's view sample (its hard shadow ray to the light, the judge's and rt-shadows'
//!    ray) placed on the light's image plane: one plane across the sun's direction, six cube
//!    faces around a point or spot light; the samples' extent on each is fitted;
//! 2. each sample joined to the list of its texel of a `grid` x `grid` grid over that extent:
//!    the irregular z-buffer, whose texels hold exactly the points the eye sees;
//! 3. every caster triangle rasterised conservatively on each plane (the texels its clipped
//!    projection can touch, widened by the rounding) and each listed sample's ray tested
//!    exactly against it, alpha mask included; large triangles are queued and shared out over a
//!    workgroup's invocations;
//! 4. a full-screen pass writes visibility 0 where a triangle stopped the ray.
//!
//! The casters come from the ray-tracing library's upload: instances share their mesh's
//! triangles, visited once per instance through its placement.

use std::sync::Mutex;
use zoo_host::prelude::*;

use zoo_host::gpu::readback::ReadbackRing;
use zoo_host::kit::{NamedTextures, TextureSize, TextureSpec};
use zoo_host::{DebugImage, ResourceInfo, ViewMapping};
use zoo_ray_tracing::{RESOLVE_SHADOWED_SHADER, RayTracing, Tracer};

mod grid;

use grid::{IrregularGrid, Shape};

zoo_host::param_choice! {
    /// How caster triangles find the texels they may cover: a compute pass walking each
    /// triangle's conservative rectangle (any device with compute), or the raster pipeline
    /// drawing each triangle conservatively, by the hardware's conservative mode where the
    /// device has it and grown by half a texel otherwise, each fragment walking its texel's list
    /// (needs vertex-stage storage reads and fragment-stage storage writes).
    pub enum Rasteriser { Compute, Raster }
}

zoo_host::technique_params! {
    /// Parameters of frustum-traced shadows.
    pub struct FtParams {
        /// Compute (rectangles walked in a compute pass) or Raster (triangles drawn
        /// conservatively, fragments walking the lists): the same shadows either way.
        rasteriser: Rasteriser = Rasteriser::Compute, flags(rebuild);
        /// Texels per side of each light plane's grid (a cube face for point and spot lights):
        /// finer grids make shorter lists and more texels per large triangle; the shadows are
        /// the same at any size.
        grid: u32 = 128, range(16, 1024), step(16);
        /// Light whose lists the debug views show.
        debug_light: u32 = 0, range(0, 1023), step(1);
    }
}

zoo_host::gpu_struct! {
    "frustum-traced/ft_light.wgsl" =>
    /// The per-light uniform of the grid passes: the light and the number of lights, the
    /// frame's size, the flat count of caster triangles, the grid's texels per side, and how
    /// far the raster path grows each triangle in the vertex stage (half a texel, or 0 where
    /// the rasteriser is conservative itself).
    #[derive(Debug, Clone, Copy)]
    pub(crate) struct FtLight {
        light: u32,
        lights: u32,
        width: u32,
        height: u32,
        triangles: u32,
        grid: u32,
        grow: f32,
    }
}

const SHADER: &str = "frustum-traced/izb.wgsl";
const RASTER_SHADER: &str = "frustum-traced/raster.wgsl";
/// Workgroups of `cs_triangles` at most (each invocation takes every
/// `TRIANGLE_GROUPS * GROUP`-th triangle) and of `cs_big_triangles` (`TRIANGLE_GROUPS`,
/// `BIG_GROUPS` in the shader).
const TRIANGLE_GROUPS: u32 = 2048;
const BIG_GROUPS: u32 = 512;
/// How far the raster path grows each triangle where the rasteriser is not conservative
/// itself, in texels: half a texel, and a fiftieth more for the projections' rounding (a ray
/// that grazes a triangle's edge on a texel's border still finds it).
const GROWTH: f32 = 0.52;
/// Invocations of a triangle pass workgroup (`GROUP` in the shader).
const GROUP: u32 = 64;

/// Each pixel's list length, for `debug_light`.
const LIST_LENGTH_VIEW: &str = "list length";
/// Each texel's list length (samples per texel) of `debug_light`'s planes, stacked.
const SAMPLES_PER_TEXEL_VIEW: &str = "samples per texel";
const COUNT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// The debug textures for grids of `grid` texels a side, on a device whose textures are at most
/// `max_texture` texels a side.
fn debug_specs(grid: u32, max_texture: u32) -> [TextureSpec; 2] {
    let spec = |name, size| TextureSpec {
        name,
        size,
        layers: 1,
        array: false,
        format: COUNT_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING,
        view: Some(ViewMapping::Integer),
        aliases: Vec::new(),
    };
    // (Cut to the device's largest texture: a finer grid's last faces are not shown.)
    let planes = zoo_host::glam::UVec2::new(grid, grid * grid::MAX_VIEWS as u32)
        .min(zoo_host::glam::UVec2::splat(max_texture));
    [
        spec(LIST_LENGTH_VIEW, TextureSize::SCREEN),
        spec(SAMPLES_PER_TEXEL_VIEW, TextureSize::Fixed(planes)),
    ]
}

/// The stages, the casters and the per-light uniforms.
struct Gpu {
    tracing_layout: wgpu::BindGroupLayout,
    tracing: Option<RayTracing>,
    uniforms: kit::UniformSlots<FtLight>,
    samples: kit::Stage,
    insert: kit::Stage,
    triangles: kit::Stage,
    big_triangles: kit::Stage,
    list_length: kit::Stage,
    samples_per_texel: kit::Stage,
    resolve: kit::Stage,
    /// The raster path's stage, when it is chosen.
    raster: Option<kit::Stage>,
    /// Whether the raster path's rasteriser is conservative itself.
    conservative: bool,
    buffers: Option<IrregularGrid>,
    /// The lights' counters, read back a frame or two late.
    stats: Option<Mutex<ReadbackRing>>,
    device: wgpu::Device,
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>, rasteriser: Rasteriser) -> TechniqueResult<Gpu> {
        let tracing_layout = Tracer::Compute.layout(&ctx.gpu.device);
        let uniforms = kit::UniformSlots::new(
            ctx.gpu,
            "frustum-traced lights",
            ctx.lights.len().max(1),
            wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::VERTEX_FRAGMENT,
        );
        let tracing = Tracer::Compute.group(&tracing_layout, None);
        let compute = |entry| {
            kit::Stage::compute(SHADER, entry)
                .shared(&[&uniforms.at(0), &tracing])
                .build(ctx)
        };
        let conservative =
            (ctx.gpu.device.features()).contains(wgpu::Features::CONSERVATIVE_RASTERIZATION);
        let raster = match rasteriser {
            Rasteriser::Compute => None,
            Rasteriser::Raster => Some(raster_stage(ctx, &uniforms, &tracing, conservative)?),
        };
        Ok(Gpu {
            raster,
            conservative,
            samples: compute("cs_samples")?,
            insert: compute("cs_insert")?,
            triangles: compute("cs_triangles")?,
            big_triangles: compute("cs_big_triangles")?,
            list_length: compute("cs_list_length")?,
            samples_per_texel: compute("cs_samples_per_texel")?,
            resolve: kit::Stage::fullscreen(RESOLVE_SHADOWED_SHADER, "fs_resolve").build(ctx)?,
            tracing_layout,
            tracing: None,
            uniforms,
            buffers: None,
            stats: None,
            device: ctx.gpu.device.clone(),
        })
    }

    /// Each counter over the lights (summed; the longest list's greatest), from the newest
    /// frame whose counters have arrived (none until one has; never waits for the GPU).
    fn totals(&self) -> Option<[u64; grid::COUNTERS as usize]> {
        let mut ring = self.stats.as_ref()?.lock().ok()?;
        let (_, bytes) = ring.latest(&self.device)?;
        let mut totals = [0u64; grid::COUNTERS as usize];
        for (i, word) in bytes.chunks_exact(4).enumerate() {
            let value = u64::from(u32::from_le_bytes([word[0], word[1], word[2], word[3]]));
            let counter = i % totals.len();
            totals[counter] = if counter == LONGEST_LIST {
                totals[counter].max(value)
            } else {
                totals[counter] + value
            };
        }
        Some(totals)
    }
}

/// The raster path's stage: caster triangles drawn into the grid, conservatively.
fn raster_stage(
    ctx: &RenderContext<'_>,
    uniforms: &kit::UniformSlots<FtLight>,
    tracing: &dyn kit::SharedGroup,
    conservative: bool,
) -> TechniqueResult<kit::Stage> {
    let needs =
        wgpu::DownlevelFlags::VERTEX_STORAGE | wgpu::DownlevelFlags::FRAGMENT_WRITABLE_STORAGE;
    let missing = needs - ctx.gpu.adapter.get_downlevel_capabilities().flags;
    if !missing.is_empty() {
        return Err(TechniqueError::Unavailable {
            id: "frustum-traced".into(),
            reason: format!("rasteriser Raster needs {missing:?}, which this device lacks"),
        });
    }
    let target = wgpu::ColorTargetState {
        format: grid::RASTER_FORMAT,
        blend: None,
        write_mask: wgpu::ColorWrites::empty(),
    };
    kit::Stage::render(RASTER_SHADER, "vs_caster")
        .fragment("fs_walk")
        .shared(&[&uniforms.at(0), tracing])
        .targets(&[Some(target)])
        .primitive(wgpu::PrimitiveState {
            conservative,
            ..Default::default()
        })
        .build(ctx)
}

/// The longest list among the counters (`LONGEST_LIST` in the shader).
const LONGEST_LIST: usize = 3;
/// The counters' names, in the shader's order.
const COUNTER_NAMES: [&str; grid::COUNTERS as usize] = [
    "samples inserted",
    "lists walked",
    "samples tested exactly",
    "longest list",
    "large triangles queued",
    "large triangles past the queue",
];

struct FrustumTraced {
    params: FtParams,
    gpu: LazyGpu<Gpu>,
    debug: NamedTextures,
}

/// The debug pass of `light`, just recorded, when one of the debug views is shown.
fn record_debug(
    (ctx, rec): (&RenderContext<'_>, &mut PassRecorder<'_>),
    (gpu, buffers, debug): (&Gpu, &IrregularGrid, &NamedTextures),
    light: usize,
    grid: u32,
) -> TechniqueResult {
    let (stage, name, extent) = match ctx.debug_view {
        Some(LIST_LENGTH_VIEW) => {
            let extent = [ctx.size.x, ctx.size.y, 1];
            (&gpu.list_length, LIST_LENGTH_VIEW, extent)
        }
        Some(SAMPLES_PER_TEXEL_VIEW) => {
            let extent = [grid, grid * grid::MAX_VIEWS as u32, 1];
            (&gpu.samples_per_texel, SAMPLES_PER_TEXEL_VIEW, extent)
        }
        _ => return Ok(()),
    };
    let Some(view) = debug.view(name) else {
        return Ok(());
    };
    let variable = name.replace(' ', "_");
    let group = buffers.debug_group(ctx, stage, (&variable, view))?;
    let slot = gpu.uniforms.at(light);
    let shared = [&slot as &dyn kit::SharedGroup];
    stage.dispatch(
        ctx,
        rec,
        "Frustum-traced debug view",
        &[&group],
        &shared,
        extent,
    )
}

/// Each light's uniform: `triangles` casters over a grid of `grid` texels a side, triangles
/// grown by `grow` texels on the raster path.
fn light_uniforms(ctx: &RenderContext<'_>, triangles: u32, grid: u32, grow: f32) -> Vec<FtLight> {
    (0..ctx.lights.len())
        .map(|light| FtLight {
            light: light as u32,
            lights: ctx.lights.len() as u32,
            width: ctx.size.x,
            height: ctx.size.y,
            triangles,
            grid,
            grow,
        })
        .collect()
}

/// One light's raster pass: the views' bounds copied where the vertex stage reads them, then
/// every caster triangle drawn once a view.
struct RasterDraw<'a> {
    stage: &'a kit::Stage,
    target: &'a grid::RasterTarget,
    triangles: u32,
    views: u32,
}

impl RasterDraw<'_> {
    fn record(
        &self,
        (ctx, rec): (&RenderContext<'_>, &mut PassRecorder<'_>),
        state: &wgpu::Buffer,
        bounds_offset: u64,
        name: &str,
        shared: &[&dyn kit::SharedGroup],
    ) -> TechniqueResult {
        let bytes = grid::Shape::bounds_bytes();
        (rec.encoder()).copy_buffer_to_buffer(state, bounds_offset, &self.target.bounds, 0, bytes);
        if self.triangles == 0 {
            return Ok(());
        }
        let attachments = [zoo_host::gpu::color_attachment(
            &self.target.view,
            wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
        )];
        let mut pass = rec.render_pass(&zoo_host::gpu::color_pass(name, &attachments));
        self.stage
            .set_on(ctx, &mut pass, &[&self.target.group], shared)?;
        pass.draw(0..self.triangles * 6, 0..self.views);
        Ok(())
    }
}

impl ShadowTechnique for FrustumTraced {
    fn resources(&self) -> Vec<ResourceInfo> {
        self.debug.resources()
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        self.debug.debug_view(resource)
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let rasteriser = self.params.rasteriser;
        let gpu = self.gpu.prepare(false, || Gpu::new(ctx, rasteriser))?;
        let tracing = match &mut gpu.tracing {
            Some(tracing) if !changes.scene && tracing.is_for(ctx) => tracing,
            slot => {
                gpu.buffers = None;
                slot.insert(RayTracing::new(ctx, Tracer::Compute, &gpu.tracing_layout)?)
            }
        };
        let shape = Shape {
            size: ctx.size,
            grid: self.params.grid,
            lights: ctx.lights.len(),
        };
        if gpu.buffers.as_ref().is_none_or(|b| b.shape != shape) {
            let stages = grid::Stages {
                compute: [
                    &gpu.samples,
                    &gpu.insert,
                    &gpu.triangles,
                    &gpu.big_triangles,
                ],
                resolve: &gpu.resolve,
                raster: gpu.raster.as_ref(),
            };
            let buffers = IrregularGrid::new(ctx, stages, tracing, shape)?;
            let bytes = shape.counter_words() * 4;
            let ring = ReadbackRing::new(&ctx.gpu.device, "frustum-traced counters", bytes, 3);
            gpu.stats = Some(Mutex::new(ring));
            gpu.buffers = Some(buffers);
        }
        let max_texture = ctx.gpu.device.limits().max_texture_dimension_2d;
        self.debug
            .respec_all(debug_specs(self.params.grid, max_texture));
        self.debug.prepare(ctx);
        Ok(())
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let gpu = self.gpu.get_mut()?;
        let (Some(tracing), Some(buffers)) = (&gpu.tracing, &gpu.buffers) else {
            return Ok(());
        };
        let size = ctx.size;
        let triangles = tracing.caster_triangles();
        let grow = if gpu.conservative { 0.0 } else { GROWTH };
        let values = light_uniforms(ctx, triangles, self.params.grid, grow);
        gpu.uniforms.write(ctx.gpu, &values);
        let tracing = Tracer::Compute.group(&gpu.tracing_layout, Some(tracing));
        let shape = buffers.shape;
        let counter_bytes = shape.counter_words() * 4;
        rec.encoder()
            .clear_buffer(&buffers.state, 0, Some(counter_bytes));
        let last = ctx.lights.len().saturating_sub(1);
        let debug_light = (self.params.debug_light as usize).min(last);
        for light in 0..ctx.lights.len() {
            // Empty lists on the light's views, and no bounds or queued triangles yet.
            let views = match ctx.lights[light].kind {
                LightKind::Directional => 1,
                _ => grid::MAX_VIEWS,
            };
            let encoder = rec.encoder();
            for range in shape.list_ranges(views) {
                encoder.clear_buffer(&buffers.grid, range.start, Some(range.end - range.start));
            }
            encoder.clear_buffer(&buffers.state, counter_bytes, None);
            let slot = gpu.uniforms.at(light);
            let shared = [&slot as &dyn kit::SharedGroup, &tracing];
            let name = kit::light_pass_name("Frustum-traced", light);
            let mut pass = rec.compute_pass(&name);
            let [samples, insert, triangle_group, big] = &buffers.groups;
            let pixels = [size.x, size.y, 1];
            gpu.samples
                .dispatch_in(ctx, &mut pass, (&[samples], &shared), pixels)?;
            gpu.insert
                .dispatch_in(ctx, &mut pass, (&[insert], &shared), pixels)?;
            if triangles > 0 && gpu.raster.is_none() {
                let extent = [triangles.div_ceil(GROUP).min(TRIANGLE_GROUPS) * GROUP, 1, 1];
                gpu.triangles
                    .dispatch_in(ctx, &mut pass, (&[triangle_group], &shared), extent)?;
                let extent = [BIG_GROUPS * GROUP, 1, 1];
                gpu.big_triangles
                    .dispatch_in(ctx, &mut pass, (&[big], &shared), extent)?;
            }
            drop(pass);
            if let (Some(stage), Some(target)) = (&gpu.raster, &buffers.raster) {
                let name = kit::light_pass_name("Frustum-traced raster", light);
                let draw = RasterDraw {
                    stage,
                    target,
                    triangles,
                    views: views as u32,
                };
                draw.record((ctx, rec), &buffers.state, counter_bytes, &name, &shared)?;
            }
            if light == debug_light {
                let grid = self.params.grid;
                record_debug((ctx, rec), (gpu, buffers, &self.debug), light, grid)?;
            }
            let name = kit::light_pass_name("Frustum-traced resolve", light);
            let mut pass = ctx.light_pass(rec, &name, light, None);
            gpu.resolve
                .set_on(ctx, &mut pass, &[&buffers.resolve_group], &[])?;
            pass.draw(0..3, 0..1);
        }
        let stats = gpu.stats.as_ref().and_then(|s| s.lock().ok());
        if let Some(target) = stats.and_then(|mut ring| ring.target().cloned()) {
            rec.encoder()
                .copy_buffer_to_buffer(&buffers.state, 0, &target, 0, counter_bytes);
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
        let mut counters = vec![("caster triangles".to_string(), f64::from(triangles))];
        if let Some(gpu) = gpu.filter(|g| g.raster.is_some()) {
            // 1 where the raster path's rasteriser is conservative itself, 0 where the vertex
            // stage grows the triangles.
            let hardware = f64::from(u8::from(gpu.conservative));
            counters.push(("hardware conservative rasterisation".to_string(), hardware));
        }
        if let Some(totals) = gpu.and_then(Gpu::totals) {
            let named = COUNTER_NAMES.iter().zip(totals);
            counters.extend(named.map(|(name, value)| (name.to_string(), value as f64)));
        }
        counters
    }
}

fn create(gpu: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = FtParams::from_values(values)?;
    let max_texture = gpu.device.limits().max_texture_dimension_2d;
    Ok(Box::new(FrustumTraced {
        debug: NamedTextures::new("frustum-traced", debug_specs(params.grid, max_texture)),
        params,
        gpu: LazyGpu::default(),
    }))
}

zoo_host::register_technique! {
    id: "frustum-traced",
    name: "Frustum-traced shadows",
    description: "The pixels' shadow rays in a light-space grid of lists (an irregular z-buffer); each caster triangle rasterised conservatively over it and every listed ray it may cross tested exactly; compute only, masked casters included",
    source: "Wyman, Hoetzlein, Lefohn 2015 (I3D), 2016 (TVCG)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    required_limits: zoo_ray_tracing::per_triangle_limits,
    required_downlevel: || wgpu::DownlevelFlags::COMPUTE_SHADERS,
    optional_features: || wgpu::Features::CONSERVATIVE_RASTERIZATION,
    params: FtParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_match_the_shader() {
        use zoo_host::gpu::layout::wgsl_integer_constant;
        let library = zoo_host::ShaderLibrary::embedded();
        let source = library.compose(SHADER).unwrap().source;
        let constant = |name| wgsl_integer_constant(&source, name);
        assert_eq!(constant("TRIANGLE_GROUPS"), Ok(i64::from(TRIANGLE_GROUPS)));
        assert_eq!(constant("BIG_GROUPS"), Ok(i64::from(BIG_GROUPS)));
        assert_eq!(constant("GROUP"), Ok(i64::from(GROUP)));
        assert_eq!(constant("COUNTERS"), Ok(grid::COUNTERS as i64));
        assert_eq!(constant("MAX_VIEWS"), Ok(grid::MAX_VIEWS as i64));
        assert_eq!(constant("BOUNDS"), Ok(grid::BOUNDS as i64));
        assert_eq!(constant("QUEUE_CAPACITY"), Ok(grid::QUEUE_CAPACITY as i64));
        assert_eq!(constant("LONGEST_LIST"), Ok(LONGEST_LIST as i64));
        // No more workgroups than a dispatch takes along one axis.
        let limits = wgpu::Limits::downlevel_defaults();
        assert!(TRIANGLE_GROUPS <= limits.max_compute_workgroups_per_dimension);
        // The shader's debug textures are the views' names.
        for name in [LIST_LENGTH_VIEW, SAMPLES_PER_TEXEL_VIEW] {
            let variable = format!("var {}:", name.replace(' ', "_"));
            assert!(source.contains(&variable), "{variable}");
        }
    }
}
