//! Running one configuration: warm-up, measured frames, pass samples, counters and flicker.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use zoo_host::gpu::{FrameTimings, PassCounts, PassOwner, TimingSource};
use zoo_host::judge::{Occluders, Surfaces, reference_visibility};
use zoo_host::judging::surface_points;
use zoo_host::scene::paths;
use zoo_host::{GpuContext, Renderer, Scene, ShaderLibrary, View};

use super::flicker::{Flicker, FrameVisibility};
use super::stats::Summary;
pub use crate::cli::PathMode;

use super::plan::*;

/// Measurements of one configuration.
#[derive(Debug, Clone)]
pub struct ConfigResult {
    pub config: Configuration,
    pub passes: Vec<(String, PassOwner, Summary)>,
    /// Median counts per pass (same order as `passes`), where the device has
    /// pipeline-statistics queries.
    pub counts: Vec<Option<PassCounts>>,
    /// Each pass's counts per measured frame (same order as `passes`; empty where not counted).
    pub frame_counts: Vec<Vec<PassCounts>>,
    pub frame_gpu: Summary,
    pub technique_gpu: Summary,
    pub frame_cpu: Summary,
    pub counters: Vec<(String, f64)>,
    /// Counters whose value changed between measured frames, with their value per measured
    /// frame (work kept or redone along the path, such as `maps rendered`).
    pub varying_counters: Vec<(String, Vec<f64>)>,
    pub flicker: Option<f64>,
    pub timing_source: TimingSource,
    pub triangles: usize,
}

/// Per-frame samples of one pass.
struct PassSamples {
    name: String,
    owner: PassOwner,
    times: Vec<f64>,
    counts: Vec<PassCounts>,
}

/// Renders one configuration along the path and measures it.
pub fn run_configuration(
    gpu: &Arc<GpuContext>,
    shaders: &ShaderLibrary,
    plan: &BenchPlan,
    config: &Configuration,
    mut tick: impl FnMut(),
) -> anyhow::Result<ConfigResult> {
    let scene = configured_scene(plan, config)?;
    // The work: instances counted.
    let triangles = scene.drawn_triangle_count();
    let occluders = plan
        .flicker
        .then(|| (Occluders::new(&scene), Surfaces::new(&scene)));
    let mut renderer =
        Renderer::with_shaders(gpu.clone(), scene.clone(), config.size, shaders.clone())?;
    renderer.set_technique(config.technique.id, &config.params)?;
    renderer.set_pipeline_statistics(!plan.cpu_timing);
    renderer.set_cpu_timing(plan.cpu_timing);
    renderer.set_reuse_unchanged(plan.reuse_unchanged);
    let (t0, t1) = paths::duration(&scene.paths);
    let mut samples = Samples::default();
    let mut flicker = Flicker::default();
    for f in 0..plan.warmup + plan.frames {
        let measured = f.saturating_sub(plan.warmup);
        let time = if plan.frames > 1 {
            t0 + (t1 - t0) * measured as f32 / (plan.frames - 1) as f32
        } else {
            t0
        };
        follow_path(&mut renderer, &scene, plan.path, time);
        let start = Instant::now();
        let timings = renderer.render(&View::Final)?;
        let cpu = start.elapsed().as_secs_f64() * 1e3;
        tick();
        if f < plan.warmup {
            continue;
        }
        samples.push(&timings, cpu, renderer.wait_for_counters());
        if let Some((occluders, surfaces)) = &occluders {
            flicker.push(frame_visibility(&renderer, occluders, surfaces));
        }
    }
    let flicker = occluders.is_some().then(|| flicker.index());
    Ok(samples.summarize(config, flicker, triangles))
}

/// The plan's scene with the configuration's tessellation and number of lights.
fn configured_scene(plan: &BenchPlan, config: &Configuration) -> anyhow::Result<Scene> {
    let base = plan.scene_path.parent().unwrap_or(Path::new("."));
    let mut description = plan.description.with_tessellation(config.tessellation);
    if let Some(n) = config.lights {
        if n > description.lights.len() {
            anyhow::bail!(
                "{}: scene.lights={n} but the scene has {} lights",
                plan.scene_path.display(),
                description.lights.len()
            );
        }
        description.lights.truncate(n);
        description.paths.lights.retain(|path| path.light < n);
    }
    Ok(Scene::from_description(
        &description,
        &plan.scene_path,
        base,
    )?)
}

/// Moves the camera and (or) the lights, as `mode` says, to where the scene's paths have
/// them at `time`.
fn follow_path(renderer: &mut Renderer, scene: &Scene, mode: PathMode, time: f32) {
    if matches!(mode, PathMode::Camera | PathMode::Both) {
        renderer.set_camera(paths::camera_at(&scene.camera, &scene.paths.camera, time));
    }
    if matches!(mode, PathMode::Light | PathMode::Both) {
        renderer.set_lights(paths::lights_at(&scene.lights, &scene.paths.lights, time));
    }
}

/// The technique's visibility of the frame just rendered beside the reference's hard
/// visibility of the same surface points, for the flicker index.
fn frame_visibility(
    renderer: &Renderer,
    occluders: &Occluders,
    surfaces: &Surfaces,
) -> FrameVisibility {
    let g = renderer.read_gbuffer();
    let points = surface_points(&g, surfaces);
    FrameVisibility {
        technique: (0..renderer.lights().len())
            .map(|l| renderer.read_visibility(l))
            .collect(),
        reference: renderer
            .lights()
            .iter()
            .map(|light| {
                let r = reference_visibility(occluders, light, &points, 1);
                r.contributing
                    .iter()
                    .zip(&r.hard)
                    .map(|(c, h)| c.then_some(*h >= 0.5))
                    .collect()
            })
            .collect(),
    }
}

/// The measured frames' samples, gathered frame by frame.
struct Samples {
    passes: Vec<PassSamples>,
    frame_gpu: Vec<f64>,
    technique_gpu: Vec<f64>,
    frame_cpu: Vec<f64>,
    timing_source: TimingSource,
    /// Each frame's counters.
    counter_frames: Vec<Vec<(String, f64)>>,
}

impl Default for Samples {
    fn default() -> Self {
        Samples {
            passes: Vec::new(),
            frame_gpu: Vec::new(),
            technique_gpu: Vec::new(),
            frame_cpu: Vec::new(),
            timing_source: TimingSource::GpuTimestamps,
            counter_frames: Vec::new(),
        }
    }
}

impl Samples {
    /// Adds one measured frame: its pass timings, CPU time (ms) and counters.
    fn push(&mut self, timings: &FrameTimings, cpu: f64, counters: Vec<(String, f64)>) {
        self.timing_source = timings.source;
        self.frame_gpu.push(timings.frame_total());
        self.technique_gpu.push(timings.total(PassOwner::Technique));
        self.frame_cpu.push(cpu);
        self.counter_frames.push(counters);
        for pass in &timings.passes {
            let index = match self.passes.iter().position(|p| p.name == pass.name) {
                Some(i) => i,
                None => {
                    self.passes.push(PassSamples {
                        name: pass.name.clone(),
                        owner: pass.owner,
                        times: Vec::new(),
                        counts: Vec::new(),
                    });
                    self.passes.len() - 1
                }
            };
            self.passes[index].times.push(pass.milliseconds);
            if let Some(counts) = pass.counts {
                self.passes[index].counts.push(counts);
            }
        }
    }

    /// The configuration's result: the samples summarized.
    fn summarize(
        self,
        config: &Configuration,
        flicker: Option<f64>,
        triangles: usize,
    ) -> ConfigResult {
        ConfigResult {
            config: config.clone(),
            counts: (self.passes.iter())
                .map(|p| median_counts(&p.counts))
                .collect(),
            frame_counts: self.passes.iter().map(|p| p.counts.clone()).collect(),
            passes: (self.passes.into_iter())
                .map(|p| (p.name, p.owner, Summary::of(&p.times)))
                .collect(),
            frame_gpu: Summary::of(&self.frame_gpu),
            technique_gpu: Summary::of(&self.technique_gpu),
            frame_cpu: Summary::of(&self.frame_cpu),
            counters: self.counter_frames.last().cloned().unwrap_or_default(),
            varying_counters: varying_counters(&self.counter_frames),
            flicker,
            timing_source: self.timing_source,
            triangles,
        }
    }
}

/// The median of each count over the frames (`None` without counts).
fn median_counts(counts: &[PassCounts]) -> Option<PassCounts> {
    (!counts.is_empty()).then(|| {
        PassCounts::from_values([0, 1, 2, 3].map(|k| {
            let mut v: Vec<u64> = counts.iter().map(|c| c.values()[k]).collect();
            v.sort_unstable();
            v[v.len() / 2]
        }))
    })
}

/// The counters of `frames` (each frame's counters) whose value is not the same in every frame,
/// with the value per frame (0 where a frame lacks it).
fn varying_counters(frames: &[Vec<(String, f64)>]) -> Vec<(String, Vec<f64>)> {
    let mut names: Vec<&str> = Vec::new();
    for (name, _) in frames.iter().flatten() {
        if !names.contains(&name.as_str()) {
            names.push(name);
        }
    }
    names
        .into_iter()
        .map(|name| {
            let values = frames
                .iter()
                .map(|frame| {
                    frame
                        .iter()
                        .find(|(n, _)| n == name)
                        .map_or(0.0, |(_, v)| *v)
                })
                .collect::<Vec<f64>>();
            (name.to_string(), values)
        })
        .filter(|(_, values)| values.windows(2).any(|w| w[0] != w[1]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::varying_counters;

    #[test]
    fn only_counters_that_change_are_listed_per_frame() {
        let frame = |maps: f64, pages: Option<f64>| {
            let mut counters = vec![("map layers".to_string(), 12.0)];
            counters.push(("maps rendered".to_string(), maps));
            counters.extend(pages.map(|p| ("atlas pages rendered".to_string(), p)));
            counters
        };
        let frames = [
            frame(12.0, Some(2.0)),
            frame(0.0, None),
            frame(3.0, Some(1.0)),
        ];
        assert_eq!(
            varying_counters(&frames),
            vec![
                ("maps rendered".to_string(), vec![12.0, 0.0, 3.0]),
                ("atlas pages rendered".to_string(), vec![2.0, 0.0, 1.0]),
            ]
        );
        assert!(varying_counters(&[frame(5.0, None), frame(5.0, None)]).is_empty());
    }
}
