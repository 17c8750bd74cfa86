//! Dynamic diffuse global illumination (Majercik, Guertin, Nowrouzezahrai and McGuire, JCGT
//! 2019; probe relocation and classification from Majercik, Marrs, Spjut and McGuire, JCGT
//! 2021): a grid of probes fitted to the scene, each tracing a rotated set of rays every frame
//! through the ray-tracing library. At each hit, the light the surface reflects (its albedo
//! times every light's direct light, shadow rays traced to the light) goes into the probe's
//! small octahedral maps of irradiance and of the mean and mean square of the distance to what
//! it sees, blended over frames. Each pixel's indirect light interpolates the eight probes
//! around it, each weighted by the chance that it sees the pixel (Chebyshev's bound on its
//! distances), so light does not come through walls. Direct shadows are ray traced.

mod gpu;
mod grid;

use zoo_host::Scene;
use zoo_host::glam::{Mat3, Quat, UVec3, Vec3, Vec4};
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo};

use gpu::{Count, Frame, Gpu, Probes};
pub use gpu::{DEBUG_VIEWS, buffer_vec4s};
pub use grid::{MAX_PROBES, ProbeGrid};

/// Texels along an irradiance map's side, borders left out (`IRRADIANCE_TEXELS` in
/// `ddgi/probes.wgsl`).
pub const IRRADIANCE_TEXELS: u32 = 6;
/// Texels along a distance map's side, borders left out (`DISTANCE_TEXELS`).
pub const DISTANCE_TEXELS: u32 = 14;
/// Frames the judge waits past relocation: the maps then hold an even average of this many
/// frames' rays (or of fewer, where the hysteresis lets each frame count for more).
pub const AVERAGED_FRAMES: u32 = 16;
/// Frames at the start during which probes move and, on the last, are classified from rays
/// traced where they ended (`cs_relocate`); their maps start over after them.
pub const RELOCATION_FRAMES: u32 = 4;

zoo_host::param_choice! {
    /// Which light the probes gather: the direct light that surfaces reflect once (what the
    /// judge's one-bounce reference measures), or that plus the probes' own indirect light at
    /// each hit, one more bounce each frame (the full look).
    pub enum Bounces { One, Multi }
}

zoo_host::technique_params! {
    /// Parameters of ddgi.
    pub struct DdgiParams {
        /// Probes along the longest side of the scene's box (the other sides get as many as
        /// keep the spacing).
        probes: u32 = 16, range(2, 48), step(1);
        /// Rays each probe traces every frame.
        rays_per_probe: u32 = 64, range(16, 1024), step(16);
        /// How much of the stored maps a frame keeps once past the first frames (which
        /// average evenly): higher is smoother and slower to follow moving lights.
        hysteresis: f32 = 0.97, range(0.0, 0.99), step(0.01);
        /// One bounce (the judge's reference) or many (through the probes).
        bounces: Bounces = Bounces::Multi;
        /// How far lookups move off the surface, toward the normal and the eye, as a share of
        /// three quarters of the probe spacing (against self-shadowing).
        self_shadow_bias: f32 = 0.3, range(0.0, 1.0), step(0.05);
        /// Probes in walls or touching surfaces move (within 0.45 of the spacing) during the
        /// first frames.
        relocation: bool = true;
        /// Probes still inside geometry after relocation are switched off: lookups leave
        /// them out.
        classification: bool = true;
        /// Direct shadow rays a pixel and light: 1 to the light's centre (hard, the judge's
        /// hard visibility), more to points of its disk (soft, a new pattern each frame).
        shadow_rays: u32 = 1, range(1, 64), step(1);
        /// The probe whose rays the `probe rays` debug view shows (x fastest, then y, z).
        debug_probe: u32 = 0, range(0, 110591), step(1);
    }
}

zoo_host::gpu_struct! {
    "ddgi/ddgi_grid.wgsl" =>
    /// The probe grid and the frame's settings (`ddgi/probes.wgsl`'s `grid`).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct DdgiGrid {
        /// The first probe's home.
        origin: Vec3,
        /// Where [`zoo_ray_tracing::RayTracing::object_buffer`]'s instances start.
        instance_objects: u32,
        spacing: Vec3,
        rays: u32,
        counts: UVec3,
        /// 1: hits add the probes' indirect light ([`Bounces::Multi`]).
        multi_bounce: u32,
        /// The rows of the frame's rotation of the ray pattern.
        rotation: [Vec4; 3],
        /// The share of this frame's rays in the blended maps.
        weight: f32,
        /// Distances are clamped to this in the distance maps (1.5 spacings).
        max_distance: f32,
        self_shadow_bias: f32,
        /// How far shadow rays from a hit start off its surface.
        surface_offset: f32,
        /// 1: probes move this frame; 1: probes inside geometry are switched off.
        relocate: u32,
        classify: u32,
        /// 1: inactive probes trace too (while probes are still being classified).
        trace_inactive: u32,
        /// 1: the relocation pass counts the probes ([`Count`]; on its last frame).
        count: u32,
        /// Tiles a row of the debug views' probe atlases.
        tiles_per_row: u32,
        debug_probe: u32,
    }
}

zoo_host::gpu_struct! {
    "ddgi/ddgi_light.wgsl" =>
    /// The light of one direct-shadow pass (`ddgi/shadows.wgsl`), its rays and the frame
    /// (where the rays' sequence continues).
    #[derive(Debug, Clone, Copy, PartialEq)]
    struct DdgiLight {
        light: u32,
        rays: u32,
        frame: u32,
    }
}

impl DdgiParams {
    /// The parameters the probes start over for (see `Ddgi::started_with`).
    fn start(&self) -> (bool, bool, Bounces) {
        (self.relocation, self.classification, self.bounces)
    }
}

struct Ddgi {
    params: DdgiParams,
    gpu: LazyGpu<Gpu>,
    /// Frames since the probes started over.
    frames: u32,
    /// What the probes started over with: a change of placement (`relocation`,
    /// `classification`) or of what the maps gather (`bounces`) starts them over again; other
    /// parameters apply from the next frame.
    started_with: (bool, bool, Bounces),
}

/// A rotation of the ray pattern for frame `frame`: uniformly distributed (Shoemake's
/// quaternion from three numbers), the numbers from the R3 low-discrepancy sequence.
fn frame_rotation(frame: u32) -> [Vec4; 3] {
    let g = 1.220_744_1_f64;
    let a = [1.0 / g, 1.0 / (g * g), 1.0 / (g * g * g)];
    let u = a.map(|a| ((0.5 + a * f64::from(frame)).fract()) as f32);
    let tau = std::f32::consts::TAU;
    let (s1, s2) = ((1.0 - u[0]).sqrt(), u[0].sqrt());
    let q = Quat::from_xyzw(
        s1 * (tau * u[1]).sin(),
        s1 * (tau * u[1]).cos(),
        s2 * (tau * u[2]).sin(),
        s2 * (tau * u[2]).cos(),
    )
    .normalize();
    let m = Mat3::from_quat(q).transpose();
    [m.x_axis, m.y_axis, m.z_axis].map(|row| row.extend(0.0))
}

impl Ddgi {
    /// The share of this frame's rays in the maps: all of it during relocation and on the
    /// first frame after, then an even average, never below 1 - hysteresis.
    fn blend_weight(&self) -> f32 {
        let averaged = self.frames.saturating_sub(RELOCATION_FRAMES) + 1;
        (1.0 / averaged as f32).max(1.0 - self.params.hysteresis)
    }

    /// What this frame runs on `probes`.
    fn frame(&self, ctx: &RenderContext<'_>, probes: &Probes, instance_objects: u32) -> Frame {
        let p = &self.params;
        let relocating = self.frames < RELOCATION_FRAMES;
        let grid = probes.grid;
        let (lo, hi) = ctx.scene.bounds();
        // The last relocation frame classifies and counts, from rays traced where the probes
        // ended; the frames before move them.
        let counting = self.frames + 1 == RELOCATION_FRAMES;
        Frame {
            grid: DdgiGrid {
                origin: grid.origin,
                instance_objects,
                spacing: grid.spacing,
                rays: probes.rays,
                counts: grid.counts,
                multi_bounce: u32::from(p.bounces == Bounces::Multi),
                rotation: frame_rotation(self.frames),
                weight: self.blend_weight(),
                max_distance: 1.5 * grid.spacing.min_element(),
                self_shadow_bias: p.self_shadow_bias,
                surface_offset: SURFACE_OFFSET * (hi - lo).length().max(1e-3),
                relocate: u32::from(relocating && !counting && p.relocation),
                classify: u32::from(counting && p.classification),
                trace_inactive: u32::from(relocating),
                count: u32::from(counting),
                tiles_per_row: gpu::tiles_per_row(grid.probe_count()),
                debug_probe: p.debug_probe,
            },
            start: self.frames == 0,
            relocating,
            counting,
            shadow_rays: p.shadow_rays,
            frame: self.frames,
        }
    }
}

/// How far shadow rays from a probe ray's hit start off the surface, as a share of the
/// scene's diagonal.
const SURFACE_OFFSET: f32 = 1e-5;

impl ShadowTechnique for Ddgi {
    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let gpu = self.gpu.prepare(false, || Gpu::new(ctx))?;
        if changes.scene || gpu.tracing.as_ref().is_none_or(|t| !t.is_for(ctx)) {
            gpu.trace_scene(ctx)?;
            self.frames = 0;
        }
        let (lo, hi) = ctx.scene.bounds();
        let grid = ProbeGrid::fitted(lo, hi, self.params.probes);
        let start = self.params.start();
        let new_buffer = gpu.probes_for(ctx, grid, self.params.rays_per_probe)?;
        if new_buffer || (changes.params && start != self.started_with) {
            self.frames = 0;
        }
        if self.frames == 0 {
            self.started_with = start;
        }
        Ok(())
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let gpu = self.gpu.get()?;
        let probes = gpu.probes.as_ref().expect("made in prepare");
        let (_, instance_objects) = gpu.objects.as_ref().expect("made in prepare");
        let frame = self.frame(ctx, probes, *instance_objects);
        self.gpu.get_mut()?.record(ctx, rec, &frame)?;
        self.frames = self.frames.saturating_add(1);
        Ok(())
    }

    fn writes_transmittance(&self, scene: &Scene) -> bool {
        scene.has_translucent_casters()
    }

    fn frames_to_converge(&self) -> u32 {
        // Past relocation, an even average of `AVERAGED_FRAMES` frames' rays (1 024 a probe at
        // the default 64), or fewer where the hysteresis' floor comes first.
        let floor = (1.0 / (1.0 - self.params.hysteresis)).ceil() as u32;
        RELOCATION_FRAMES + floor.min(AVERAGED_FRAMES) + 1
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        Ok(self.params.update(values)?)
    }

    fn counters(&self) -> Vec<(String, f64)> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let mut counters = (gpu.tracing.as_ref()).map_or_else(Vec::new, |t| t.stats.counters());
        if let Some(probes) = &gpu.probes {
            let count = f64::from(probes.grid.probe_count());
            counters.push(("probes".into(), count));
            counters.push(("rays a frame".into(), count * f64::from(probes.rays)));
            let bytes = gpu::buffer_vec4s(probes.grid.probe_count(), probes.rays) * 16;
            counters.push(("probe memory MiB".into(), bytes as f64 / f64::from(1 << 20)));
        }
        if self.frames >= RELOCATION_FRAMES {
            // Nothing until the relocation's counts have arrived (callers that wait retry on
            // empty).
            let Some(counts) = gpu.counts() else {
                return Vec::new();
            };
            for (count, value) in Count::ALL.iter().zip(counts) {
                counters.push((count.name().into(), f64::from(value)));
            }
        }
        counters.push(("frames accumulated".into(), f64::from(self.frames)));
        counters
    }

    fn resources(&self) -> Vec<ResourceInfo> {
        self.gpu.built().map_or_else(Vec::new, Gpu::resources)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        self.gpu.built()?.debug_view(resource)
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = DdgiParams::from_values(values)?;
    Ok(Box::new(Ddgi {
        started_with: params.start(),
        params,
        gpu: LazyGpu::default(),
        frames: 0,
    }))
}

zoo_host::register_technique! {
    id: "ddgi",
    name: "Dynamic diffuse global illumination",
    description: "A grid of probes tracing rays every frame into octahedral irradiance and distance maps, looked up with a Chebyshev visibility test: indirect light that does not leak; direct shadows ray traced",
    source: "Majercik et al., JCGT 2019 and 2021 (dynamic diffuse global illumination)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    adds_light: true,
    required_downlevel: || wgpu::DownlevelFlags::COMPUTE_SHADERS,
    // The probe pass: the frame's lights and objects, the objects' materials, the casters'
    // five buffers, the probes' buffer and the surfaces' objects.
    required_limits: || wgpu::Limits {
        max_storage_buffers_per_shader_stage: 10,
        ..wgpu::Limits::downlevel_defaults()
    },
    params: DdgiParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_match_the_shader() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose("ddgi/probes.wgsl")
            .unwrap()
            .source;
        let constant = |name| zoo_host::gpu::layout::wgsl_integer_constant(&source, name);
        assert_eq!(
            constant("IRRADIANCE_TEXELS"),
            Ok(i64::from(IRRADIANCE_TEXELS))
        );
        assert_eq!(constant("DISTANCE_TEXELS"), Ok(i64::from(DISTANCE_TEXELS)));
    }

    #[test]
    fn frame_rotations_are_rotations_and_differ() {
        let rows = |f| frame_rotation(f).map(|r| r.truncate());
        for frame in 0..8 {
            let [x, y, z] = rows(frame);
            for (a, b) in [(x, y), (y, z), (x, z)] {
                assert!(a.dot(b).abs() < 1e-5);
            }
            assert!((x.cross(y) - z).length() < 1e-5, "right-handed");
        }
        assert!((rows(0)[0] - rows(1)[0]).length() > 0.1);
    }

    #[test]
    fn the_blend_averages_evenly_then_keeps_the_hysteresis() {
        let mut ddgi = Ddgi {
            params: DdgiParams::default(),
            gpu: LazyGpu::default(),
            frames: 0,
            started_with: DdgiParams::default().start(),
        };
        let weights: Vec<f32> = (0..RELOCATION_FRAMES + 40)
            .map(|frame| {
                ddgi.frames = frame;
                ddgi.blend_weight()
            })
            .collect();
        let start = RELOCATION_FRAMES as usize;
        assert!(weights[..=start].iter().all(|&w| w == 1.0));
        assert_eq!(weights[start + 1], 0.5);
        assert!((weights.last().unwrap() - 0.03).abs() < 1e-6);
        assert!(ddgi.frames_to_converge() as usize <= weights.len());
    }
}
