//! Helpers for plugin and integration tests: one shared headless GPU context per test binary.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use crate::gpu::GpuContext;

pub use zoo_judge::Metric;

/// The shared headless context, created on first use. Panics with the driver install hint when
/// no adapter exists, since GPU tests cannot run then.
pub fn gpu() -> Arc<GpuContext> {
    static GPU: OnceLock<Arc<GpuContext>> = OnceLock::new();
    GPU.get_or_init(|| match GpuContext::new_headless() {
        Ok(gpu) => {
            eprintln!("GPU tests run on {}", gpu.describe());
            Arc::new(gpu)
        }
        Err(e) => panic!("{e}"),
    })
    .clone()
}

/// A technique that records nothing (every light stays lit), for tests that register
/// techniques with particular light kinds or needs: `create: |_, _| Ok(Box::new(Inert))`.
pub struct Inert;

impl crate::ShadowTechnique for Inert {
    fn prepare(
        &mut self,
        _: &crate::RenderContext<'_>,
        _: crate::Changes,
    ) -> crate::TechniqueResult {
        Ok(())
    }
    fn record(
        &mut self,
        _: &crate::RenderContext<'_>,
        _: &mut crate::PassRecorder<'_>,
    ) -> crate::TechniqueResult {
        Ok(())
    }
}

/// The workspace root (where `scenes/` and `shaders/` are).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `../shared/models` beside the repository (real third-party meshes, not part of it), when
/// present; says that the test skips its part otherwise.
pub fn shared_models() -> Option<PathBuf> {
    let dir = workspace_root().join("../shared/models");
    if dir.join("spot.obj").exists() {
        return Some(dir);
    }
    eprintln!(
        "SKIPPED: {} is absent, so the real meshes are left out",
        dir.display()
    );
    None
}

/// Path of a scene shipped in `scenes/`.
pub fn scene_path(name: &str) -> PathBuf {
    workspace_root().join("scenes").join(name)
}

/// A technique rendered on a scene and judged.
pub struct JudgeRun {
    /// Scene name (used in error-map file names).
    pub scene: String,
    /// The scene as loaded.
    pub loaded: crate::scene::Scene,
    pub reference: crate::judging::SceneReference,
    pub judged: crate::judging::Judged,
}

/// Renders `scene` (a file in `scenes/`) with `technique` and `params` at `size` and judges
/// every light with the default number of area samples.
pub fn judge(scene: &str, technique: &str, params: &[(&str, &str)], size: glam::UVec2) -> JudgeRun {
    let loaded = crate::scene::Scene::load(&scene_path(scene)).unwrap_or_else(|e| panic!("{e}"));
    judge_with(gpu(), loaded, technique, params, size, Some(scene))
}

/// What the reference of a scene file holds (a [`crate::judging::SceneReference`] without its
/// lazily traced parts).
type TracedReference = (
    crate::render::GBufferData,
    Vec<zoo_judge::LightReference>,
    usize,
    f64,
);

/// The reference of scene file `scene` at `size` on the shared context, traced by `trace` the
/// first time a test of this binary asks for it: a scene judged with several techniques or
/// parameters is traced once.
fn cached_reference(
    scene: &str,
    size: glam::UVec2,
    trace: impl FnOnce() -> crate::judging::SceneReference,
) -> crate::judging::SceneReference {
    type Cache = std::sync::Mutex<HashMap<(String, glam::UVec2), Arc<OnceLock<TracedReference>>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let slot = {
        let mut cache = (CACHE.get_or_init(Default::default).lock())
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        cache.entry((scene.to_string(), size)).or_default().clone()
    };
    // Another test tracing the same scene waits here for its result.
    let (gbuffer, lights, triangles, seconds) = slot
        .get_or_init(|| {
            let r = trace();
            (r.gbuffer, r.lights, r.occluder_triangles, r.seconds)
        })
        .clone();
    crate::judging::SceneReference::from_traced(gbuffer, lights, triangles, seconds)
}

/// Every scene of `scenes/` (sorted) but the many-lamp benchmark plazas (`lights-*`, hundreds
/// of lights: the CPU reference alone would take minutes in a test) and the scenes set up to
/// show an artifact (`artifact-*`, which their technique's tests judge).
pub fn standard_scenes() -> Vec<PathBuf> {
    let skipped = |p: &Path| {
        (p.file_stem()).is_some_and(|s| {
            let s = s.to_string_lossy();
            s.starts_with("lights-") || s.starts_with("artifact-")
        })
    };
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(workspace_root().join("scenes"))
        .unwrap_or_else(|e| panic!("scenes/: {e}"))
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .filter(|p| !skipped(p))
        .collect();
    scenes.sort();
    scenes
}

/// Parses a scene from RON text (OBJ paths relative to `scenes/`).
pub fn scene_from_ron(name: &str, text: &str) -> crate::scene::Scene {
    crate::scene::Scene::from_ron(text, Path::new(name), &workspace_root().join("scenes"))
        .unwrap_or_else(|e| panic!("{e}"))
}

pub use crate::technique::counter;

/// A technique's defaults with its dearest work at the least it allows: shadow maps
/// (`map_size`) at their smallest and rays (`rays_per_pixel`) at their fewest. For tests of
/// what renders, not of how accurately (big depth maps and many rays are the dearest work on a
/// software rasterizer).
pub fn cheapest_params(schema: &[crate::params::ParamSpec]) -> crate::params::ParamValues {
    let mut values = crate::params::defaults(schema);
    for spec in schema {
        let dear = matches!(spec.key, "map_size" | "rays_per_pixel");
        if let (true, crate::params::ParamKind::Int { min, .. }) = (dear, &spec.kind) {
            values.insert(spec.key.to_string(), crate::params::ParamValue::Int(*min));
        }
    }
    values
}

/// A new context on the test adapter without `removed` features (to test a technique's
/// fallback where a device lacks them).
pub fn gpu_without(removed: wgpu::Features) -> Arc<GpuContext> {
    GpuContext::new_headless_without(removed)
        .map(Arc::new)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A new context on the test adapter with WebGPU's default limits (256 array layers, 8192²
/// textures...) instead of the adapter's.
pub fn gpu_with_webgpu_limits() -> Arc<GpuContext> {
    GpuContext::new_headless_limited(wgpu::Limits::default())
        .map(Arc::new)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// As [`judge`], for a scene built in the test.
pub fn judge_scene(
    loaded: crate::scene::Scene,
    technique: &str,
    params: &[(&str, &str)],
    size: glam::UVec2,
) -> JudgeRun {
    judge_scene_on(gpu(), loaded, technique, params, size)
}

/// As [`judge_scene`], on the context `gpu`.
pub fn judge_scene_on(
    gpu: Arc<GpuContext>,
    loaded: crate::scene::Scene,
    technique: &str,
    params: &[(&str, &str)],
    size: glam::UVec2,
) -> JudgeRun {
    judge_with(gpu, loaded, technique, params, size, None)
}

/// Judges `technique` on `loaded`; the reference of scene file `file` (on the shared context)
/// is traced once per test binary.
fn judge_with(
    gpu: Arc<GpuContext>,
    loaded: crate::scene::Scene,
    technique: &str,
    params: &[(&str, &str)],
    size: glam::UVec2,
    file: Option<&str>,
) -> JudgeRun {
    let scene = loaded.name.clone();
    let registration = crate::find_technique(technique).unwrap_or_else(|e| panic!("{e}"));
    let schema = (registration.params)();
    let mut values = crate::params::defaults(&schema);
    let assignments: Vec<(String, String)> = params
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    crate::params::apply_assignments(&schema, &mut values, &assignments)
        .unwrap_or_else(|e| panic!("{technique}: {e}"));
    let mut renderer =
        crate::Renderer::new(gpu, loaded.clone(), size).unwrap_or_else(|e| panic!("{e}"));
    let mut trace = || {
        let samples = crate::judging::DEFAULT_SAMPLES;
        crate::judging::SceneReference::compute(&mut renderer, samples, |_| {})
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let reference = match file {
        Some(file) => cached_reference(file, size, trace),
        None => trace(),
    };
    let judged = crate::judging::judge_technique(&mut renderer, &reference, technique, &values)
        .unwrap_or_else(|e| panic!("{technique} on {scene}: {e}"));
    JudgeRun {
        scene,
        loaded,
        reference,
        judged,
    }
}

/// Scenes whose point and spot lights hang 0.2 to 0.5 m in front of a wall or desk (files in
/// `scenes/`): receivers right behind a soft light.
pub const NEAR_WALL_SCENES: [&str; 3] = ["wall-lamps.ron", "sconce-corridor.ron", "desk-lamp.ron"];

/// Judges `technique` with `params` on every [`NEAR_WALL_SCENES`] scene at 256x256 and asserts
/// that each light it supports keeps its mae against the area reference within `bound`, or
/// within the bound `exceptions` names for that (scene file, light). Returns the number of
/// lights judged.
pub fn assert_soft_near_walls(
    technique: &str,
    params: &[(&str, &str)],
    bound: f64,
    exceptions: &[(&str, usize, f64)],
) -> usize {
    let mut judged = 0;
    for scene in NEAR_WALL_SCENES {
        let run = judge(scene, technique, params, glam::UVec2::new(256, 256));
        for light in 0..run.loaded.lights.len() {
            if run.judged.scores[light].metrics.is_none() {
                continue;
            }
            let m = run.metrics(light);
            eprintln!(
                "{technique} on {scene}, light {light} ({}): mae {:.4}",
                run.loaded.lights[light].kind.name(),
                m.mae
            );
            let bound = exceptions
                .iter()
                .find(|(s, l, _)| *s == scene && *l == light)
                .map_or(bound, |e| e.2);
            run.assert_bounds(light, &m, &[(Metric::Mae, bound)]);
            judged += 1;
        }
    }
    judged
}

impl JudgeRun {
    /// Asserts that every light's core error (false shadow and false lit off the shadow edges)
    /// is at most `bound`, printing each; every light kind must be supported.
    pub fn assert_core_error(&self, bound: f64) {
        for light in 0..self.judged.scores.len() {
            let m = self.metrics(light);
            let core = m.false_shadow_core + m.false_lit_core;
            let (id, scene) = (&self.judged.technique, &self.scene);
            eprintln!("{id} on {scene} light {light}: core {core:.5} {m:?}");
            assert!(
                core <= bound,
                "{id} on {scene} light {light}: core error {core}"
            );
        }
    }

    /// The metrics of `light`; panics if the technique does not support its kind.
    pub fn metrics(&self, light: usize) -> zoo_judge::Metrics {
        self.judged.scores[light].metrics.unwrap_or_else(|| {
            panic!(
                "{} does not support light {light} ({})",
                self.judged.technique,
                self.judged.scores[light].kind.name()
            )
        })
    }

    /// The mean over lights of each light's mean absolute error.
    pub fn mean_mae(&self) -> f64 {
        let lights = self.loaded.lights.len();
        (0..lights).map(|l| self.metrics(l).mae).sum::<f64>() / lights.max(1) as f64
    }

    /// Mean visibility the technique gives `light` where the area reference sees none of the
    /// light (full umbra, contributing pixels): light leaking into shadow, the flaw of
    /// filtered moment maps. Panics when the view holds fewer than 500 umbra pixels.
    pub fn umbra_leak(&self, light: usize) -> f64 {
        let reference = &self.reference.lights[light];
        let visibility = &self.judged.visibility[light];
        let umbra: Vec<usize> = (0..visibility.len())
            .filter(|&i| reference.contributing[i] && reference.area[i] == 0.0)
            .collect();
        assert!(
            umbra.len() > 500,
            "{}: only {} umbra pixels of light {light} in view",
            self.scene,
            umbra.len()
        );
        umbra.iter().map(|&i| visibility[i] as f64).sum::<f64>() / umbra.len() as f64
    }

    /// Metrics of `light` counted only where `mask` is true.
    pub fn metrics_masked(&self, light: usize, mask: &[bool]) -> zoo_judge::Metrics {
        let (width, height) = self.reference.size();
        zoo_judge::Metrics::compute(
            &self.reference.lights[light],
            &self.judged.visibility[light],
            width,
            height,
            Some(mask),
        )
    }

    /// [`Self::assert_bounds`] for every light of the scene, each light's metrics printed.
    pub fn assert_every_light(&self, bounds: &[(Metric, f64)]) {
        for light in 0..self.loaded.lights.len() {
            let m = self.metrics(light);
            let kind = self.loaded.lights[light].kind.name();
            eprintln!("{} light {light} ({kind}): {m:?}", self.scene);
            self.assert_bounds(light, &m, bounds);
        }
    }

    /// Asserts `metric <= bound` for each pair. On failure, writes the light's error map and
    /// panics naming the metric, the measured value, the bound and the image.
    pub fn assert_bounds(
        &self,
        light: usize,
        metrics: &zoo_judge::Metrics,
        bounds: &[(Metric, f64)],
    ) {
        let failures: Vec<String> = bounds
            .iter()
            .filter(|(metric, bound)| metric.of(metrics) > *bound)
            .map(|(metric, bound)| {
                format!(
                    "{} = {:.5} exceeds {bound}",
                    metric.name(),
                    metric.of(metrics)
                )
            })
            .collect();
        if failures.is_empty() {
            return;
        }
        let dir = workspace_root().join("target/judge-failures");
        let path = dir.join(format!(
            "{}-{}-light{light}-error.png",
            self.scene, self.judged.technique
        ));
        let map = crate::judging::error_map(
            &self.reference.lights[light],
            &self.judged.visibility[light],
            &self.judged.image,
        );
        let saved = std::fs::create_dir_all(&dir)
            .map_err(|e| e.to_string())
            .and_then(|_| map.save(&path).map_err(|e| e.to_string()));
        panic!(
            "{} on {}, light {light}: {}; error map: {}",
            self.judged.technique,
            self.scene,
            failures.join(", "),
            match saved {
                Ok(()) => path.display().to_string(),
                Err(e) => format!("could not be written ({e})"),
            }
        );
    }

    /// Asserts the shadow-map family's core bounds for every light the technique scores
    /// (lights of kinds it does not support are skipped): `false_shadow_core` at most
    /// `false_shadow` and `false_lit_core` at most `false_lit`, printing each light's metrics.
    pub fn assert_core_bounds(&self, false_shadow: f64, false_lit: f64) {
        for (light, score) in self.judged.scores.iter().enumerate() {
            let Some(m) = score.metrics else { continue };
            eprintln!(
                "{} {} light {light} ({}): {m:?}",
                self.judged.technique,
                self.scene,
                score.kind.name()
            );
            let bounds = [
                (Metric::FalseShadowCore, false_shadow),
                (Metric::FalseLitCore, false_lit),
            ];
            self.assert_bounds(light, &m, &bounds);
        }
    }

    /// Mask of pixels that belong to the scene's receiver planes.
    pub fn receiver_mask(&self) -> Vec<bool> {
        let scene = &self.loaded;
        self.reference
            .gbuffer
            .positions
            .iter()
            .map(|p| {
                p.w > 0.5
                    && scene
                        .receivers
                        .iter()
                        .any(|r| (r.plane.truncate().dot(p.truncate()) + r.plane.w).abs() < 1e-3)
            })
            .collect()
    }
}

/// The real mesh of [`shared_models`] named `model` (`fandisk`, `teapot`, `cow`, `spot` or
/// `stanford-bunny`) and the transform that stands it on the ground about a metre across.
fn crowd_member(dir: &Path, model: &str) -> (PathBuf, &'static str) {
    let transform = match model {
        "fandisk" => "(translation: (-0.483, -2.52, 0.268), scale: (0.2, 0.2, 0.2))",
        "teapot" => "(translation: (-0.035, 0, 0), scale: (0.16, 0.16, 0.16))",
        "cow" => "(translation: (-0.078, 0.364, 0), scale: (0.1, 0.1, 0.1))",
        "spot" => "(translation: (0, 0.74, 0), scale: (1, 1, 1))",
        "stanford-bunny" => "(translation: (0.1, -0.2, 0), scale: (6, 6, 6))",
        other => panic!("crowd_scene: no crowd of `{other}`"),
    };
    (dir.join(format!("{model}.obj")), transform)
}

/// A crowd: `count` instances of the real mesh `model` (see [`shared_models`]; `fandisk`,
/// `teapot`, `cow`, `spot` or `stanford-bunny`), each turned its own way, on a square grid on
/// a ground plane, seen from above at an angle and lit by one light of each of `lights` (a
/// spot light and a point light above the crowd, a sun from the side). `None`, saying so,
/// where the shared models are absent.
pub fn crowd_scene(
    model: &str,
    count: usize,
    lights: &[crate::LightKind],
) -> Option<crate::scene::Scene> {
    let dir = shared_models()?;
    let (path, transform) = crowd_member(&dir, model);
    let side = (count as f32).sqrt().ceil().max(1.0) as usize;
    let spacing = 1.3;
    let width = side as f32 * spacing;
    let instances: Vec<String> = (0..count)
        .map(|i| {
            let x = ((i % side) as f32 + 0.5) * spacing - width / 2.0;
            let z = ((i / side) as f32 + 0.5) * spacing - width / 2.0;
            let yaw = (i * 137 % 360) as f32;
            format!(
                "(translation: ({x}, 0, {z}), rotation_degrees: (0, {yaw}, 0), scale: (1, 1, 1))"
            )
        })
        .collect();
    let (h, range) = (width + 3.0, 4.0 * width + 20.0);
    let lights: Vec<String> = (lights.iter())
        .map(|kind| match kind {
            crate::LightKind::Spot => format!(
                "Spot(position: ({}, {h}, {}), direction: ({}, {}, {}), intensity: {}, \
                 range: {range}, angle_degrees: 45)",
                0.3 * width,
                0.2 * width,
                -0.3 * width,
                -h,
                -0.2 * width,
                h * h
            ),
            crate::LightKind::Point => format!(
                "Point(position: ({}, {}, {}), intensity: {}, range: {range})",
                -0.25 * width,
                0.6 * h,
                0.3 * width,
                h * h
            ),
            crate::LightKind::Directional => {
                "Directional(direction: (-0.6, -0.7, -0.4), intensity: 1)".to_string()
            }
        })
        .collect();
    let text = format!(
        "(name: \"crowd-{count}-{model}\",
          camera: (position: (0, {}, {}), target: (0, 0, 0), fov_y_degrees: 50),
          lights: [{}],
          objects: [(mesh: Plane(size: {}), receiver: true),
                    (mesh: Obj(\"{}\"), transform: {transform}, instances: [{}])])",
        0.9 * width + 2.0,
        0.8 * width + 2.0,
        lights.join(", "),
        width + 4.0,
        path.display(),
        instances.join(", ")
    );
    Some(
        crate::scene::Scene::from_ron(&text, Path::new("crowd.ron"), &dir)
            .unwrap_or_else(|e| panic!("{e}")),
    )
}

/// A crowd's reference and renderer (see [`crowd_scene`]), for judging one volume technique
/// with several parameter sets against the one reference.
pub struct CrowdRun {
    technique: &'static str,
    renderer: crate::Renderer,
    reference: crate::judging::SceneReference,
}

impl CrowdRun {
    /// `technique` on `scene` at `size`, and the scene's reference.
    pub fn new(technique: &'static str, scene: crate::Scene, size: glam::UVec2) -> CrowdRun {
        let mut renderer = crate::Renderer::new(gpu(), scene, size).unwrap();
        let samples = crate::judging::DEFAULT_SAMPLES;
        let reference =
            crate::judging::SceneReference::compute(&mut renderer, samples, |_| {}).unwrap();
        CrowdRun {
            technique,
            renderer,
            reference,
        }
    }

    /// The technique judged with parameters `params` over its defaults, and the number of
    /// pieces each light's volumes took (its `light N volume pieces` counters).
    pub fn judge(&mut self, params: &[(&str, &str)]) -> (crate::judging::Judged, Vec<f64>) {
        let registration = crate::find_technique(self.technique).unwrap();
        let schema = (registration.params)();
        let mut values = crate::params::defaults(&schema);
        let params: Vec<(String, String)> = (params.iter())
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        crate::params::apply_assignments(&schema, &mut values, &params).unwrap();
        let (renderer, reference) = (&mut self.renderer, &self.reference);
        let judged = crate::judging::judge_technique(renderer, reference, self.technique, &values);
        let judged = judged.unwrap();
        let counters = self.renderer.technique_instance().counters();
        let pieces = (0..self.renderer.lights().len())
            .map(|l| counter(&counters, &format!("light {l} volume pieces")).unwrap())
            .collect();
        (judged, pieces)
    }

    /// Asserts the judge's bounds of an exact method on every light of `judged` (of crowd
    /// `scene`): core errors at most 0.001, all errors (raster edges) at most `edges`; and
    /// that nothing was left out (no warnings).
    pub fn assert_exact(&self, scene: &str, judged: &crate::judging::Judged, edges: f64) {
        for score in &judged.scores {
            let m = score.metrics.unwrap();
            eprintln!("{}, {scene}, {}: {m:?}", self.technique, score.kind.name());
            assert!(
                m.false_lit_core + m.false_shadow_core <= 0.001
                    && m.false_lit + m.false_shadow <= edges,
                "{scene}, light {}: {m:?}",
                score.light
            );
        }
        assert!(judged.warnings.is_empty(), "{:?}", judged.warnings);
    }
}

/// Crowds whose volumes fit one buffer, drawn by volume technique `technique` again in
/// pieces of a small budget (its `volume_buffer_mib`): a teapot's volume may need about 150
/// thousand vertices (2.4 MiB), so in pieces of 1 MiB each teapot is cut into stretches of
/// triangles and of edges; in pieces of 8 MiB, three cows share a piece. Asserts every
/// light's shadows exact, and the same to the bit as in one piece. Returns early, saying so,
/// where the shared models are absent.
pub fn assert_crowds_in_pieces_match_one_piece(technique: &'static str) {
    use crate::LightKind;
    let all = [LightKind::Spot, LightKind::Directional, LightKind::Point];
    for (model, count, lights, mib) in [("teapot", 24, &all[..], "1"), ("cow", 30, &all[..1], "8")]
    {
        let Some(scene) = crowd_scene(model, count, lights) else {
            return;
        };
        let name = scene.name.clone();
        let mut crowd = CrowdRun::new(technique, scene, glam::UVec2::new(192, 192));
        let (whole, one) = crowd.judge(&[]);
        let (pieced, several) = crowd.judge(&[("volume_buffer_mib", mib)]);
        eprintln!("{name}: pieces {one:?}, then {several:?} of {mib} MiB");
        assert!(one.iter().all(|&n| n == 1.0), "{one:?}");
        assert!(several.iter().all(|&n| n > 2.0), "{several:?}");
        crowd.assert_exact(&name, &pieced, 0.02);
        for light in 0..lights.len() {
            assert!(
                whole.visibility[light] == pieced.visibility[light],
                "{name}, light {light}: pieces change the shadows"
            );
        }
    }
}

/// The defaults of technique `id`'s parameters with `assignments` (`key`, `value`) applied.
pub fn technique_params(id: &str, assignments: &[(&str, &str)]) -> crate::params::ParamValues {
    let registration = crate::find_technique(id).unwrap_or_else(|e| panic!("{e}"));
    let schema = (registration.params)();
    let mut values = crate::params::defaults(&schema);
    let pairs: Vec<(String, String)> = (assignments.iter())
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    crate::params::apply_assignments(&schema, &mut values, &pairs)
        .unwrap_or_else(|e| panic!("{id}: {e}"));
    values
}

/// A scene file rendered at a size, with its reference, for judging the indirect light of
/// techniques that add light.
pub struct IndirectRun {
    pub scene: crate::scene::Scene,
    pub renderer: crate::Renderer,
    pub reference: crate::judging::SceneReference,
}

/// A technique's indirect light judged against the one-bounce reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IndirectScore {
    /// Relative RMSE.
    pub rmse: f64,
    /// Light on surfaces no lit surface sees, over the reference's mean
    /// ([`crate::judging::Leak`]).
    pub leak: f64,
    /// Its total over the reference's, on every surface pixel.
    pub amount: f32,
}

impl IndirectRun {
    /// Scene file `scene` (in `scenes/`) at `size` on the shared context, and its reference.
    pub fn new(scene: &str, size: glam::UVec2) -> IndirectRun {
        let loaded =
            crate::scene::Scene::load(&scene_path(scene)).unwrap_or_else(|e| panic!("{e}"));
        let mut renderer = crate::Renderer::new(gpu(), loaded.clone(), size).unwrap();
        let reference = crate::judging::SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
        IndirectRun {
            scene: loaded,
            renderer,
            reference,
        }
    }

    /// Technique `id` with `assignments` judged against the reference with `rays` cosine
    /// rays a pixel.
    pub fn score(&mut self, id: &str, assignments: &[(&str, &str)], rays: u32) -> IndirectScore {
        let values = technique_params(id, assignments);
        let judged =
            crate::judging::judge_technique(&mut self.renderer, &self.reference, id, &values)
                .unwrap_or_else(|e| panic!("{id}: {e}"));
        let (scene, reference) = (&self.scene, &mut self.reference);
        let lights = &scene.lights;
        let rmse = judged.indirect_rmse(reference, scene, lights, rays);
        let leak = judged.indirect_leak(reference, scene, lights, rays);
        let (Some(rmse), Some(leak)) = (rmse, leak) else {
            panic!("{id} adds no light");
        };
        let mask = reference.surface_mask();
        let expected = reference.indirect(scene, lights, rays);
        let sum = |light: &[glam::Vec3]| {
            (light.iter().zip(&mask))
                .filter(|(_, keep)| **keep)
                .map(|(l, _)| l.element_sum())
                .sum::<f32>()
        };
        let got = judged.indirect.as_deref().unwrap_or_default();
        IndirectScore {
            rmse,
            leak: leak.leak,
            amount: sum(got) / sum(expected),
        }
    }
}
