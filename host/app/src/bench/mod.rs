//! `shadow-zoo bench`: techniques rendered along the scene's camera and light paths after a
//! warm-up, with per-pass GPU times, CPU frame times, workload counters and a flicker index,
//! summarised as CSV, markdown and PNG plots. Ratios to `unshadowed` in the same run are the
//! currency on a software driver.

pub mod flicker;
pub mod plot;
pub mod stats;
pub mod suite;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use zoo_host::gpu::{PassOwner, TimingSource};
use zoo_host::judge::{Occluders, reference_visibility};
use zoo_host::judging::surface_points;
use zoo_host::params::{self, ParamValues};
use zoo_host::scene::{SceneDescription, paths};
use zoo_host::{GpuContext, Renderer, Scene, TechniqueRegistration, View};

pub use crate::cli::PathMode;
use crate::cli::{BenchArgs, parse_size};
use flicker::{Flicker, FrameVisibility};
use stats::Summary;

/// A swept quantity.
#[derive(Debug, Clone, PartialEq)]
pub enum SweepKey {
    /// Output size (`size=256x256,512x512`).
    Size,
    /// Procedural tessellation factor (`scene.tessellation=0.5,1,2`).
    Tessellation,
    /// A technique parameter (`sm-pcf.map_size=512,1024`).
    Param { technique: String, key: String },
}

/// One sweep: a key and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    pub key: SweepKey,
    pub name: String,
    pub values: Vec<String>,
}

/// Parses `KEY` of `--sweep KEY=v1,v2`.
pub fn parse_sweep(key: &str, values: &[String]) -> anyhow::Result<Sweep> {
    if values.is_empty() || values.iter().any(|v| v.trim().is_empty()) {
        bail!("--sweep {key}: give at least one value, e.g. {key}=a,b");
    }
    let parsed = match key {
        "size" => {
            for v in values {
                parse_size(v).map_err(|e| anyhow::anyhow!("--sweep size: {e}"))?;
            }
            SweepKey::Size
        }
        "scene.tessellation" => {
            for v in values {
                match v.parse::<f32>() {
                    Ok(f) if f > 0.0 && f <= 16.0 => {}
                    _ => bail!("--sweep scene.tessellation: `{v}` is not a factor in (0, 16]"),
                }
            }
            SweepKey::Tessellation
        }
        other => match other.split_once('.') {
            Some((technique, param)) => {
                let registration = zoo_host::find_technique(technique)?;
                let schema = (registration.params)();
                let spec = params::find_spec(&schema, param)
                    .with_context(|| format!("--sweep {other}"))?;
                for v in values {
                    spec.parse(v).with_context(|| format!("--sweep {other}"))?;
                }
                SweepKey::Param {
                    technique: technique.to_string(),
                    key: param.to_string(),
                }
            }
            None => bail!("--sweep {other}: expected size, scene.tessellation or TECHNIQUE.PARAM"),
        },
    };
    Ok(Sweep {
        key: parsed,
        name: key.to_string(),
        values: values.iter().map(|v| v.trim().to_string()).collect(),
    })
}

/// Everything one benchmark run needs.
pub struct BenchPlan {
    pub run: String,
    pub scene_path: PathBuf,
    pub description: SceneDescription,
    pub techniques: Vec<&'static TechniqueRegistration>,
    pub size: zoo_host::glam::UVec2,
    pub frames: u32,
    pub warmup: u32,
    pub path: PathMode,
    pub sweeps: Vec<Sweep>,
    /// Fixed parameters as (technique, key, value).
    pub set: Vec<(String, String, String)>,
    pub flicker: bool,
}

/// One measured configuration.
#[derive(Debug, Clone)]
pub struct Configuration {
    pub run: String,
    pub technique: &'static TechniqueRegistration,
    pub params: ParamValues,
    /// The swept values that define it, as `key=value`.
    pub swept: Vec<(String, String)>,
    pub size: zoo_host::glam::UVec2,
    pub tessellation: f32,
}

impl Configuration {
    /// `technique [key=value, ...]`.
    pub fn label(&self) -> String {
        if self.swept.is_empty() {
            self.technique.id.to_string()
        } else {
            let swept: Vec<String> = self.swept.iter().map(|(k, v)| format!("{k}={v}")).collect();
            format!("{} [{}]", self.technique.id, swept.join(", "))
        }
    }

    /// Swept values that apply to every technique (size, tessellation).
    fn common_key(&self) -> String {
        format!("{}x{}@{}", self.size.x, self.size.y, self.tessellation)
    }
}

/// Measurements of one configuration.
#[derive(Debug, Clone)]
pub struct ConfigResult {
    pub config: Configuration,
    pub passes: Vec<(String, PassOwner, Summary)>,
    /// Median vertex, fragment and compute invocations per pass (same order as `passes`),
    /// where the device has pipeline-statistics queries.
    pub invocations: Vec<Option<[u64; 3]>>,
    pub frame_gpu: Summary,
    pub technique_gpu: Summary,
    pub frame_cpu: Summary,
    pub counters: Vec<(String, f64)>,
    pub flicker: Option<f64>,
    pub timing_source: TimingSource,
    pub triangles: usize,
}

/// Expands the plan's sweeps into configurations (cartesian product; a technique-parameter
/// sweep only multiplies its own technique's configurations).
pub fn expand(plan: &BenchPlan) -> anyhow::Result<Vec<Configuration>> {
    let mut out = Vec::new();
    for technique in &plan.techniques {
        let schema = (technique.params)();
        let mut base = params::defaults(&schema);
        let fixed: Vec<(String, String)> = plan
            .set
            .iter()
            .filter(|(t, _, _)| t == technique.id)
            .map(|(_, k, v)| (k.clone(), v.clone()))
            .collect();
        params::apply_assignments(&schema, &mut base, &fixed)
            .with_context(|| format!("technique `{}`", technique.id))?;
        let mut configs = vec![Configuration {
            run: plan.run.clone(),
            technique,
            params: base,
            swept: Vec::new(),
            size: plan.size,
            tessellation: 1.0,
        }];
        for sweep in &plan.sweeps {
            if let SweepKey::Param { technique: t, .. } = &sweep.key
                && t != technique.id
            {
                continue;
            }
            let mut next = Vec::new();
            for config in &configs {
                for value in &sweep.values {
                    let mut c = config.clone();
                    match &sweep.key {
                        SweepKey::Size => {
                            c.size = parse_size(value).map_err(|e| anyhow::anyhow!(e))?
                        }
                        SweepKey::Tessellation => c.tessellation = value.parse()?,
                        SweepKey::Param { key, .. } => {
                            params::apply_assignments(
                                &schema,
                                &mut c.params,
                                &[(key.clone(), value.clone())],
                            )?;
                        }
                    }
                    c.swept.push((sweep.name.clone(), value.clone()));
                    next.push(c);
                }
            }
            configs = next;
        }
        out.extend(configs);
    }
    Ok(out)
}

/// Per-frame samples of one pass.
struct PassSamples {
    name: String,
    owner: PassOwner,
    times: Vec<f64>,
    invocations: Vec<[u64; 3]>,
}

/// Renders one configuration along the path and measures it.
pub fn run_configuration(
    gpu: &Arc<GpuContext>,
    plan: &BenchPlan,
    config: &Configuration,
    mut tick: impl FnMut(),
) -> anyhow::Result<ConfigResult> {
    let base = plan.scene_path.parent().unwrap_or(Path::new("."));
    let description = plan.description.with_tessellation(config.tessellation);
    let scene = Scene::from_description(&description, &plan.scene_path, base)?;
    let triangles = scene.triangle_count();
    let occluders = plan.flicker.then(|| Occluders::new(&scene));
    let mut renderer = Renderer::new(gpu.clone(), scene.clone(), config.size)?;
    renderer.set_technique(config.technique.id, &config.params)?;
    renderer.set_pipeline_statistics(true);
    let (t0, t1) = paths::duration(&scene.paths);
    let mut pass_samples: Vec<PassSamples> = Vec::new();
    let (mut frame_gpu, mut technique_gpu, mut frame_cpu) = (Vec::new(), Vec::new(), Vec::new());
    let mut timing_source = TimingSource::GpuTimestamps;
    let mut flicker = Flicker::default();
    for f in 0..plan.warmup + plan.frames {
        let measured = f.saturating_sub(plan.warmup);
        let time = if plan.frames > 1 {
            t0 + (t1 - t0) * measured as f32 / (plan.frames - 1) as f32
        } else {
            t0
        };
        if matches!(plan.path, PathMode::Camera | PathMode::Both) {
            renderer.set_camera(paths::camera_at(&scene.camera, &scene.paths.camera, time));
        }
        if matches!(plan.path, PathMode::Light | PathMode::Both) {
            renderer.set_lights(paths::lights_at(&scene.lights, &scene.paths.lights, time));
        }
        let start = Instant::now();
        let timings = renderer.render(&View::Final)?;
        let cpu = start.elapsed().as_secs_f64() * 1e3;
        tick();
        if f < plan.warmup {
            continue;
        }
        timing_source = timings.source;
        frame_gpu.push(timings.frame_total());
        technique_gpu.push(timings.total(PassOwner::Technique));
        frame_cpu.push(cpu);
        for pass in &timings.passes {
            let index = match pass_samples.iter().position(|p| p.name == pass.name) {
                Some(i) => i,
                None => {
                    pass_samples.push(PassSamples {
                        name: pass.name.clone(),
                        owner: pass.owner,
                        times: Vec::new(),
                        invocations: Vec::new(),
                    });
                    pass_samples.len() - 1
                }
            };
            pass_samples[index].times.push(pass.milliseconds);
            if let Some(counts) = pass.invocations {
                pass_samples[index].invocations.push(counts);
            }
        }
        if let Some(occluders) = &occluders {
            let g = renderer.read_gbuffer();
            let points = surface_points(&g);
            let frame = FrameVisibility {
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
            };
            flicker.push(frame);
        }
    }
    let flicker = occluders.is_some().then(|| flicker.index());
    let median_counts = |counts: &[[u64; 3]]| -> Option<[u64; 3]> {
        (!counts.is_empty()).then(|| {
            [0, 1, 2].map(|k| {
                let mut v: Vec<u64> = counts.iter().map(|c| c[k]).collect();
                v.sort_unstable();
                v[v.len() / 2]
            })
        })
    };
    Ok(ConfigResult {
        config: config.clone(),
        invocations: pass_samples
            .iter()
            .map(|p| median_counts(&p.invocations))
            .collect(),
        passes: pass_samples
            .into_iter()
            .map(|p| (p.name, p.owner, Summary::of(&p.times)))
            .collect(),
        frame_gpu: Summary::of(&frame_gpu),
        technique_gpu: Summary::of(&technique_gpu),
        frame_cpu: Summary::of(&frame_cpu),
        counters: renderer.wait_for_counters(),
        flicker,
        timing_source,
        triangles,
    })
}

/// Builds the plan for a command-line run.
pub fn plan_from_args(args: &BenchArgs, scene: &Path) -> anyhow::Result<BenchPlan> {
    let mut techniques = crate::compare::select_techniques(&args.techniques)?;
    // The baseline every ratio is taken against.
    let baseline = zoo_host::find_technique(zoo_host::builtin::UNSHADOWED_ID)?;
    if !techniques.iter().any(|t| t.id == baseline.id) {
        techniques.insert(0, baseline);
    }
    let sweeps = args
        .sweep
        .iter()
        .map(|(key, values)| {
            let values: Vec<String> = values.split(',').map(str::to_string).collect();
            parse_sweep(key, &values)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let set = split_sets(&args.set, &techniques)?;
    Ok(BenchPlan {
        run: scene
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "bench".into()),
        scene_path: scene.to_path_buf(),
        description: zoo_host::scene::read_description(scene)?,
        techniques,
        size: args.size,
        frames: args.frames.unwrap_or(30),
        warmup: args.warmup,
        path: args.path,
        sweeps,
        set,
        flicker: !args.no_flicker,
    })
}

fn split_sets(
    set: &[(String, String)],
    techniques: &[&'static TechniqueRegistration],
) -> anyhow::Result<Vec<(String, String, String)>> {
    set.iter()
        .map(|(key, value)| {
            let (id, k) = key
                .split_once('.')
                .with_context(|| format!("--set {key}: expected ID.KEY=VALUE"))?;
            if !techniques.iter().any(|t| t.id == id) {
                bail!("--set {key}: technique `{id}` is not being benchmarked");
            }
            Ok((id.to_string(), k.to_string(), value.clone()))
        })
        .collect()
}

/// Runs plans, writes the outputs, and returns the results.
pub fn run_plans(
    plans: &[BenchPlan],
    out: &Path,
    suite: Option<&suite::Suite>,
) -> anyhow::Result<Vec<ConfigResult>> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output folder {}", out.display()))?;
    let probe = out.join("bench.csv");
    std::fs::write(&probe, "")
        .with_context(|| format!("output folder {} is not writable", out.display()))?;
    let configs: Vec<(usize, Configuration)> = plans
        .iter()
        .enumerate()
        .map(|(i, plan)| expand(plan).map(|c| c.into_iter().map(move |c| (i, c))))
        .collect::<anyhow::Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let gpu = crate::setup::headless_gpu()?;
    let total: u64 = configs
        .iter()
        .map(|(i, _)| (plans[*i].frames + plans[*i].warmup) as u64)
        .sum();
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {msg} [{elapsed}<{eta}]")
            .expect("valid template"),
    );
    let mut results = Vec::new();
    for (i, config) in &configs {
        bar.set_message(config.label());
        let result = run_configuration(&gpu, &plans[*i], config, || bar.inc(1))
            .with_context(|| format!("{} in run {}", config.label(), config.run))?;
        results.push(result);
    }
    bar.finish_and_clear();
    let adapter = gpu.describe();
    std::fs::write(out.join("bench.csv"), bench_csv(&results))?;
    std::fs::write(out.join("summary.csv"), summary_csv(&results))?;
    std::fs::write(
        out.join("bench.md"),
        bench_md(plans, &results, &adapter, suite),
    )?;
    write_plots(plans, &results, out)?;
    Ok(results)
}

/// The `unshadowed` result with the same run, size and tessellation as `r`.
fn baseline<'a>(results: &'a [ConfigResult], r: &ConfigResult) -> Option<&'a ConfigResult> {
    results.iter().find(|b| {
        b.config.technique.id == zoo_host::builtin::UNSHADOWED_ID
            && b.config.run == r.config.run
            && b.config.common_key() == r.config.common_key()
    })
}

fn ratio_to_baseline(results: &[ConfigResult], r: &ConfigResult) -> Option<f64> {
    baseline(results, r)
        .map(|b| b.frame_gpu.median)
        .filter(|m| *m > 0.0)
        .map(|m| r.frame_gpu.median / m)
}

/// `bench.csv`: one row per configuration and pass (plus frame and technique totals).
pub fn bench_csv(results: &[ConfigResult]) -> String {
    let mut out = String::from(
        "run,configuration,technique,size,tessellation,pass,owner,median_ms,p95_ms,p99_ms,min_ms,max_ms,frames,vertex_invocations,fragment_invocations,compute_invocations\n",
    );
    for r in results {
        let c = &r.config;
        let rows = r
            .passes
            .iter()
            .zip(&r.invocations)
            .map(|((name, owner, s), counts)| {
                let owner = match owner {
                    PassOwner::Host => "host",
                    PassOwner::Technique => "technique",
                };
                (name.clone(), owner, *s, *counts)
            })
            .chain([
                (
                    "technique total (gpu)".to_string(),
                    "total",
                    r.technique_gpu,
                    None,
                ),
                ("frame total (gpu)".to_string(), "total", r.frame_gpu, None),
                ("frame (cpu wall)".to_string(), "total", r.frame_cpu, None),
            ]);
        for (name, owner, s, counts) in rows {
            let counts = counts.map_or(",,".to_string(), |[v, f, c]| format!("{v},{f},{c}"));
            let _ = writeln!(
                out,
                "{},\"{}\",{},{}x{},{},\"{}\",{},{:.4},{:.4},{:.4},{:.4},{:.4},{},{counts}",
                c.run,
                c.label().replace('"', "'"),
                c.technique.id,
                c.size.x,
                c.size.y,
                c.tessellation,
                name.replace('"', "'"),
                owner,
                s.median,
                s.p95,
                s.p99,
                s.min,
                s.max,
                s.count
            );
        }
    }
    out
}

/// `summary.csv`: one row per configuration.
pub fn summary_csv(results: &[ConfigResult]) -> String {
    let mut out = String::from(
        "run,configuration,technique,size,tessellation,triangles,frame_median_ms,technique_median_ms,cpu_median_ms,ratio_to_unshadowed,flicker_index\n",
    );
    for r in results {
        let c = &r.config;
        let _ = writeln!(
            out,
            "{},\"{}\",{},{}x{},{},{},{:.4},{:.4},{:.4},{},{}",
            c.run,
            c.label().replace('"', "'"),
            c.technique.id,
            c.size.x,
            c.size.y,
            c.tessellation,
            r.triangles,
            r.frame_gpu.median,
            r.technique_gpu.median,
            r.frame_cpu.median,
            ratio_to_baseline(results, r).map_or(String::new(), |x| format!("{x:.4}")),
            r.flicker.map_or(String::new(), |x| format!("{x:.6}")),
        );
    }
    out
}

/// Today's date (UTC) as YYYY-MM-DD.
fn today() -> String {
    let days = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() / 86_400)
        .unwrap_or(0) as i64;
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

/// Median of a measure for a result: `frame`, `technique`, or the passes starting with a prefix.
fn measure(r: &ConfigResult, passes: &str) -> f64 {
    match passes {
        "frame" => r.frame_gpu.median,
        "technique" => r.technique_gpu.median,
        prefix => r
            .passes
            .iter()
            .filter(|(n, _, _)| n.starts_with(prefix))
            .map(|(_, _, s)| s.median)
            .sum(),
    }
}

/// Suite ratios: (label, configuration key, value, seed figure) for every matching pair.
pub fn suite_ratios(
    s: &suite::Suite,
    results: &[ConfigResult],
) -> Vec<(String, String, f64, String)> {
    let mut out = Vec::new();
    for ratio in &s.ratios {
        let (n, d) = (&ratio.numerator, &ratio.denominator);
        for num in results
            .iter()
            .filter(|r| r.config.run == n.run && r.config.technique.id == n.technique)
        {
            // Same size and tessellation, and equal values for every sweep both sides share.
            let den = results.iter().find(|r| {
                r.config.run == d.run
                    && r.config.technique.id == d.technique
                    && r.config.common_key() == num.config.common_key()
                    && num
                        .config
                        .swept
                        .iter()
                        .all(|(k, v)| r.config.swept.iter().all(|(k2, v2)| k2 != k || v2 == v))
            });
            if let Some(den) = den {
                let bottom = measure(den, &d.passes);
                if bottom > 0.0 {
                    let key = format!(
                        "{}x{}, tessellation {}{}",
                        num.config.size.x,
                        num.config.size.y,
                        num.config.tessellation,
                        if num.config.swept.is_empty() {
                            String::new()
                        } else {
                            format!(" ({})", num.config.label())
                        }
                    );
                    out.push((
                        ratio.label.clone(),
                        key,
                        measure(num, &n.passes) / bottom,
                        ratio.seed.clone(),
                    ));
                }
            }
        }
    }
    out
}

/// `bench.md`: readable tables with the environment, ratios and flicker.
pub fn bench_md(
    plans: &[BenchPlan],
    results: &[ConfigResult],
    adapter: &str,
    suite: Option<&suite::Suite>,
) -> String {
    let mut out = String::new();
    let w = &mut out;
    let title = suite.map_or("Shadow Zoo benchmark".to_string(), |s| {
        format!("Shadow Zoo benchmark suite `{}`", s.name)
    });
    let _ = writeln!(w, "# {title}\n");
    if let Some(s) = suite {
        let _ = writeln!(w, "{}\n", s.description.trim());
    }
    let _ = writeln!(w, "- Date: {}", today());
    let _ = writeln!(w, "- Adapter: {adapter}");
    let _ = writeln!(
        w,
        "- OS: {} ({})",
        std::env::consts::OS,
        std::env::consts::ARCH
    );
    let _ = writeln!(
        w,
        "- Timing: {}",
        results.first().map_or("none", |r| r.timing_source.label())
    );
    for plan in plans {
        let _ = writeln!(
            w,
            "- Run `{}`: scene `{}`, {}x{} (unless swept), {} frames after {} warm-up frames, path: {:?}",
            plan.run,
            plan.scene_path.display(),
            plan.size.x,
            plan.size.y,
            plan.frames,
            plan.warmup,
            plan.path
        );
    }
    let _ = writeln!(
        w,
        "\nFrame times are GPU pass sums (medians over frames); the ratio is to `unshadowed` with the same run, size and tessellation. The flicker index is the mean fraction of pixels whose visibility flips between consecutive frames where the reference visibility does not change.\n"
    );
    let _ = writeln!(
        w,
        "| run | configuration | triangles | frame median (ms) | p95 | technique median (ms) | CPU frame (ms) | × unshadowed | flicker |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|");
    for r in results {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} |",
            r.config.run,
            r.config.label(),
            r.triangles,
            r.frame_gpu.median,
            r.frame_gpu.p95,
            r.technique_gpu.median,
            r.frame_cpu.median,
            ratio_to_baseline(results, r).map_or("–".into(), |x| format!("{x:.2}")),
            r.flicker.map_or("–".into(), |x| format!("{x:.5}")),
        );
    }
    if let Some(s) = suite {
        let ratios = suite_ratios(s, results);
        if !ratios.is_empty() {
            let _ = writeln!(w, "\n## This project beside the seeds\n");
            let _ = writeln!(w, "| ratio | configuration | this project | seed |");
            let _ = writeln!(w, "|---|---|---|---|");
            for (label, key, value, seed) in ratios {
                let _ = writeln!(w, "| {label} | {key} | {value:.2} | {seed} |");
            }
        }
        if !s.seed_figures.is_empty() {
            let _ = writeln!(w, "\nWhat the seeds report:\n");
            for f in &s.seed_figures {
                let _ = writeln!(w, "- {f}");
            }
        }
    }
    let _ = writeln!(
        w,
        "\n## Passes (median / p95 ms; vertex / fragment / compute invocations where counted)\n"
    );
    for r in results {
        let passes: Vec<String> = r
            .passes
            .iter()
            .zip(&r.invocations)
            .map(|((n, _, s), counts)| match counts {
                Some([v, f, c]) => format!("{n} {:.2}/{:.2} ({v}/{f}/{c})", s.median, s.p95),
                None => format!("{n} {:.2}/{:.2}", s.median, s.p95),
            })
            .collect();
        let _ = writeln!(
            w,
            "- {} `{}`: {}",
            r.config.run,
            r.config.label(),
            passes.join(", ")
        );
    }
    let counted: Vec<&ConfigResult> = results.iter().filter(|r| !r.counters.is_empty()).collect();
    if !counted.is_empty() {
        let _ = writeln!(w, "\n## Workload counters (last frame)\n");
        for r in counted {
            let values: Vec<String> = r.counters.iter().map(|(k, v)| format!("{k} {v}")).collect();
            let _ = writeln!(
                w,
                "- {} `{}`: {}",
                r.config.run,
                r.config.label(),
                values.join(", ")
            );
        }
    }
    out
}

fn file_name(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn write_plots(plans: &[BenchPlan], results: &[ConfigResult], out: &Path) -> anyhow::Result<()> {
    // One segment per pass family ("Shadow map: light 0 face 2" -> "Shadow map").
    let bars: Vec<plot::Bar> = results
        .iter()
        .map(|r| {
            let mut segments: Vec<(String, f64)> = Vec::new();
            for (name, _, s) in &r.passes {
                let family = name.split(':').next().unwrap_or(name).trim().to_string();
                match segments.iter_mut().find(|(n, _)| *n == family) {
                    Some((_, total)) => *total += s.median,
                    None => segments.push((family, s.median)),
                }
            }
            plot::Bar {
                label: format!("{}: {}", r.config.run, r.config.label()),
                segments,
            }
        })
        .collect();
    plot::pass_bars(&bars, "Per-pass GPU time (median)", &out.join("passes.png"))?;
    for plan in plans {
        for sweep in &plan.sweeps {
            let x_of = |value: &str| -> Option<f64> {
                match sweep.key {
                    SweepKey::Size => parse_size(value).ok().map(|s| (s.x * s.y) as f64),
                    _ => value.parse().ok(),
                }
            };
            let mut lines: Vec<plot::Line> = Vec::new();
            for r in results.iter().filter(|r| r.config.run == plan.run) {
                let Some((_, value)) = r.config.swept.iter().find(|(k, _)| *k == sweep.name) else {
                    continue;
                };
                let Some(x) = x_of(value) else { continue };
                let others: Vec<String> = r
                    .config
                    .swept
                    .iter()
                    .filter(|(k, _)| *k != sweep.name)
                    .map(|(k, v)| format!("{k}={v}"))
                    .collect();
                let name = if others.is_empty() {
                    r.config.technique.id.to_string()
                } else {
                    format!("{} [{}]", r.config.technique.id, others.join(", "))
                };
                match lines.iter_mut().find(|l| l.name == name) {
                    Some(line) => line.points.push((x, r.frame_gpu.median)),
                    None => lines.push(plot::Line {
                        name,
                        points: vec![(x, r.frame_gpu.median)],
                    }),
                }
            }
            for line in &mut lines {
                line.points.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
            if !lines.is_empty() {
                let x_label = match sweep.key {
                    SweepKey::Size => "pixels".to_string(),
                    _ => sweep.name.clone(),
                };
                plot::sweep_lines(
                    &lines,
                    &format!("{}: frame time against {}", plan.run, sweep.name),
                    &x_label,
                    &out.join(format!(
                        "sweep-{}-{}.png",
                        file_name(&plan.run),
                        file_name(&sweep.name)
                    )),
                )?;
            }
        }
    }
    Ok(())
}

/// Runs `shadow-zoo bench`.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let (plans, suite) = match (&args.suite, &args.scene) {
        (Some(name), _) => {
            let path = suite::locate(name)?;
            let s = suite::load(&path)?;
            let dir = path.parent().unwrap_or(Path::new("."));
            let plans = s
                .runs
                .iter()
                .map(|run| {
                    let scene_path = dir.join(&run.scene);
                    let mut techniques = run
                        .techniques
                        .iter()
                        .map(|t| zoo_host::find_technique(t).map_err(anyhow::Error::from))
                        .collect::<anyhow::Result<Vec<_>>>()?;
                    let baseline = zoo_host::find_technique(zoo_host::builtin::UNSHADOWED_ID)?;
                    if !techniques.iter().any(|t| t.id == baseline.id) {
                        techniques.insert(0, baseline);
                    }
                    Ok(BenchPlan {
                        run: run.name.clone(),
                        description: zoo_host::scene::read_description(&scene_path)?,
                        scene_path,
                        size: zoo_host::glam::UVec2::new(run.size.0, run.size.1),
                        frames: args.frames.unwrap_or(run.frames),
                        warmup: run.warmup,
                        path: run.path,
                        sweeps: run
                            .sweeps
                            .iter()
                            .map(|(k, v)| parse_sweep(k, v))
                            .collect::<anyhow::Result<_>>()?,
                        set: split_sets(&run.set, &techniques)?,
                        techniques,
                        flicker: !args.no_flicker,
                    })
                })
                .collect::<anyhow::Result<Vec<_>>>()
                .with_context(|| format!("suite {}", path.display()))?;
            (plans, Some(s))
        }
        (None, Some(scene)) => (vec![plan_from_args(args, scene)?], None),
        (None, None) => bail!("give --scene FILE or --suite NAME"),
    };
    if plans.iter().any(|p| p.frames == 0) {
        bail!("--frames must be at least 1");
    }
    let results = run_plans(&plans, &args.out, suite.as_ref())?;
    for r in &results {
        println!(
            "  {:10} {:50} frame {:8.2} ms  {}  flicker {}",
            r.config.run,
            r.config.label(),
            r.frame_gpu.median,
            ratio_to_baseline(&results, r).map_or("         ".into(), |x| format!("x{x:7.2}")),
            r.flicker.map_or("-".into(), |f| format!("{f:.5}"))
        );
    }
    println!(
        "wrote {}/bench.csv, summary.csv, bench.md and plots",
        args.out.display()
    );
    Ok(())
}
