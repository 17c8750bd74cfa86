//! `shadow-zoo compare`: render techniques, judge them, write CSV, markdown and error maps.

use std::fmt::Write as _;
use std::fs::File;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use zoo_host::judge::Metrics;
use zoo_host::judging::perceptual::{FlipScore, score_image};
use zoo_host::judging::{Judged, Leak, LightScore, SceneReference, error_map, judge_technique};
use zoo_host::params::{self, ParamValues};
use zoo_host::scene::paths;
use zoo_host::technique::unbounced_sentence;
use zoo_host::{LightKind, Renderer, Scene, TechniqueRegistration};

use crate::cli::{CompareArgs, Judge};
use crate::setup::headless_gpu;

/// The exact header of `results.csv`.
pub const CSV_HEADER: &str = "scene,technique,view,light,light_kind,pixels,false_shadow,false_lit,\
false_shadow_core,false_lit_core,mae,p95_error,gpu_ms";
/// The exact header of `images.csv`.
pub const IMAGES_CSV_HEADER: &str = "scene,technique,view,flip_mean,flip_p95";

/// One view of the scene, judged.
pub struct JudgedView {
    /// Index along the paths (0 for the scene's own camera).
    pub view: usize,
    /// Time on the scene's paths (`None`: the scene's camera and lights as they are).
    pub time: Option<f32>,
    pub reference: SceneReference,
    pub judged: Vec<Judged>,
    /// FLIP of each judged technique's final image against the reference image, in the order
    /// of `judged`.
    pub flip: Vec<Option<FlipScore>>,
    /// The indirect-light scores of the techniques that add light.
    pub indirect: Vec<IndirectScore>,
}

/// One technique's indirect light judged against the one-bounce reference.
#[derive(Debug, Clone)]
pub struct IndirectScore {
    /// The technique's id.
    pub technique: String,
    /// Relative RMSE over the pixels with a surface.
    pub rmse: f64,
    /// Its light on surfaces no directly lit surface sees.
    pub leak: Leak,
    /// The lights that add nothing to its indirect light, and why.
    pub unbounced: Vec<(usize, LightKind, String)>,
}

impl IndirectScore {
    /// The lights that do not bounce, as `1 (point), 2 (spot)`, or `none`.
    fn unbounced_list(&self, separator: &str) -> String {
        if self.unbounced.is_empty() {
            return "none".to_string();
        }
        (self.unbounced.iter())
            .map(|(light, kind, _)| format!("{light} ({})", kind.name()))
            .collect::<Vec<_>>()
            .join(separator)
    }
}

/// The times of `views` views spread evenly over the scene's paths, both ends included; one
/// view (`None`) is the scene's camera and lights as they are.
pub fn view_times(scene: &Scene, views: u32) -> anyhow::Result<Vec<Option<f32>>> {
    if views <= 1 {
        return Ok(vec![None]);
    }
    if scene.paths.camera.is_empty() && scene.paths.lights.is_empty() {
        bail!(
            "--views {views}: {} has no camera or light path to spread views along (add `paths` to the scene, or judge one view)",
            scene.path.display()
        );
    }
    let (start, end) = paths::duration(&scene.paths);
    if end <= start {
        log::warn!(
            "{}: the paths' keys all have time {start}: every view is the same",
            scene.path.display()
        );
    }
    Ok((0..views)
        .map(|k| Some(start + (end - start) * k as f32 / (views - 1) as f32))
        .collect())
}

/// Moves `renderer`'s camera and lights to `time` on the scene's paths.
fn go_to(renderer: &mut Renderer, time: Option<f32>) {
    let scene = renderer.scene();
    let (camera, lights) = match time {
        None => (scene.camera, scene.lights.clone()),
        Some(t) => (
            paths::camera_at(&scene.camera, &scene.paths.camera, t),
            paths::lights_at(&scene.lights, &scene.paths.lights, t),
        ),
    };
    renderer.set_camera(camera);
    renderer.set_lights(lights);
}

/// Resolves `ids` (comma-separated or `all`) to registrations.
pub fn select_techniques(ids: &str) -> anyhow::Result<Vec<&'static TechniqueRegistration>> {
    if ids.trim() == "all" {
        return Ok(zoo_host::registry());
    }
    let mut out = Vec::new();
    for id in ids.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let registration = zoo_host::find_technique(id)?;
        if !out.iter().any(|r: &&TechniqueRegistration| r.id == id) {
            out.push(registration);
        }
    }
    if out.is_empty() {
        bail!("--techniques: no technique given");
    }
    Ok(out)
}

/// Applies `ID.KEY=VALUE` assignments to each technique's defaults.
pub fn technique_params(
    techniques: &[&'static TechniqueRegistration],
    assignments: &[(String, String)],
) -> anyhow::Result<Vec<ParamValues>> {
    for (key, _) in assignments {
        let Some((id, _)) = key.split_once('.') else {
            bail!("--set {key}: expected ID.KEY=VALUE");
        };
        if !techniques.iter().any(|t| t.id == id) {
            bail!("--set {key}: technique `{id}` is not being compared");
        }
    }
    techniques
        .iter()
        .map(|t| {
            let schema = (t.params)();
            let mut values = params::defaults(&schema);
            let mine: Vec<(String, String)> = assignments
                .iter()
                .filter_map(|(key, value)| {
                    let (id, key) = key.split_once('.')?;
                    (id == t.id).then(|| (key.to_string(), value.clone()))
                })
                .collect();
            params::apply_assignments(&schema, &mut values, &mine)
                .with_context(|| format!("technique `{}`", t.id))?;
            Ok(values)
        })
        .collect()
}

/// One judged configuration: a technique, its parameters, and its label in the results (the
/// id, then `@KEY=VALUE` for each swept value).
struct Configuration {
    technique: &'static TechniqueRegistration,
    params: ParamValues,
    label: String,
}

/// The configurations of a run: each technique with its `--set` values, multiplied by the
/// `--sweep`s of its own parameters.
fn configurations(args: &CompareArgs) -> anyhow::Result<Vec<Configuration>> {
    let techniques = select_techniques(&args.techniques)?;
    let params = technique_params(&techniques, &args.set)?;
    let sweeps = crate::bench::parse_sweeps(&args.sweep)?;
    let mut out = Vec::new();
    for (technique, values) in techniques.iter().zip(params) {
        let mut own = Vec::new();
        for sweep in &sweeps {
            let crate::bench::SweepKey::Param { technique: id, .. } = &sweep.key else {
                bail!(
                    "--sweep {}: compare sweeps technique parameters (ID.KEY)",
                    sweep.name
                );
            };
            if !techniques.iter().any(|t| t.id == id) {
                bail!(
                    "--sweep {}: technique `{id}` is not being compared",
                    sweep.name
                );
            }
            if id == technique.id {
                own.push(sweep);
            }
        }
        let schema = (technique.params)();
        let base = (values, Vec::<String>::new());
        let swept = crate::bench::cartesian(vec![base], &own, |(values, swept), sweep, value| {
            let crate::bench::SweepKey::Param { key, .. } = &sweep.key else {
                unreachable!("only parameter sweeps are kept")
            };
            params::apply_assignments(&schema, values, &[(key.clone(), value.to_string())])?;
            swept.push(format!("{key}={value}"));
            Ok(())
        })?;
        out.extend(swept.into_iter().map(|(params, swept)| Configuration {
            technique,
            params,
            label: if swept.is_empty() {
                technique.id.to_string()
            } else {
                format!("{}@{}", technique.id, swept.join("@"))
            },
        }));
    }
    Ok(out)
}

/// A technique run that failed: (view, configuration label, error).
type Failure<'a> = (usize, &'a str, String);

/// Runs `shadow-zoo compare`.
pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    let configurations = configurations(args)?;
    let scene = Scene::load(&args.scene)?;
    let times = view_times(&scene, args.views)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output folder {}", args.out.display()))?;
    let csv_path = args.out.join("results.csv");
    let csv = File::create(&csv_path)
        .with_context(|| format!("output folder {} is not writable", args.out.display()))?;

    let gpu = headless_gpu()?;
    let shaders = crate::setup::shader_library(args.shaders.as_deref())?;
    let adapter = gpu.describe();
    print_plan(&scene, configurations.len(), args, times.len());
    let light_count = scene.lights.len();
    let scene_name = scene.name.clone();
    let triangles = scene.triangle_summary();
    let mut renderer = Renderer::with_shaders(gpu, scene, args.size, shaders)?;

    let (views, failures) = judge_views(&mut renderer, args, &configurations, &times)?;
    print_references(&views, args.judge);
    let [images_path, report_path] = write_outputs(
        &args.out,
        csv,
        &csv_path,
        &ReportInputs {
            scene: &scene_name,
            scene_path: &args.scene,
            triangles,
            lights: light_count,
            size: (args.size.x, args.size.y),
            adapter: &adapter,
            judge: args.judge,
            views: &views,
            failures: &failures,
        },
    )?;
    print_summaries(&views);
    println!(
        "wrote {}, {}, {} and the error maps",
        csv_path.display(),
        images_path.display(),
        report_path.display()
    );
    check_failures(&failures, configurations.len() * views.len())
}

/// Prints what the run will do: the scene, the configurations, the resolution and the views.
fn print_plan(scene: &Scene, configurations: usize, args: &CompareArgs, views: usize) {
    println!(
        "scene: {} ({}, {} lights); {} configurations at {}x{}, {} view{}",
        scene.name,
        scene.triangle_summary(),
        scene.lights.len(),
        configurations,
        args.size.x,
        args.size.y,
        views,
        if views == 1 { "" } else { "s" }
    );
}

/// Traces the reference of each view and judges every configuration against it, showing
/// progress; returns the judged views and the runs that failed.
fn judge_views<'a>(
    renderer: &mut Renderer,
    args: &CompareArgs,
    configurations: &'a [Configuration],
    times: &[Option<f32>],
) -> anyhow::Result<(Vec<JudgedView>, Vec<Failure<'a>>)> {
    let light_count = renderer.scene().lights.len();
    let bar = ProgressBar::new((times.len() * (light_count + configurations.len())) as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed}]")
            .expect("valid template"),
    );
    let mut views = Vec::new();
    let mut failures = Vec::new();
    for (view, &time) in times.iter().enumerate() {
        go_to(renderer, time);
        bar.set_message(format!("view {view}: reference"));
        let mut reference = trace_reference(renderer, args, &bar)?;
        let judged = judge_configurations(
            renderer,
            &reference,
            configurations,
            view,
            &bar,
            &mut failures,
        );
        bar.set_message(format!("view {view}: images"));
        let flip = judged
            .iter()
            .map(|j| score_image(renderer, &mut reference, j, args.samples))
            .collect();
        let view = JudgedView {
            view,
            time,
            indirect: Vec::new(),
            reference,
            judged,
            flip,
        };
        views.push(judge_view_outputs(view, renderer, args, times.len() > 1)?);
    }
    bar.finish_and_clear();
    Ok((views, failures))
}

/// Traces the area-light reference of the current view with the chosen judge, advancing
/// `bar` by one per light.
fn trace_reference(
    renderer: &mut Renderer,
    args: &CompareArgs,
    bar: &ProgressBar,
) -> anyhow::Result<SceneReference> {
    Ok(match args.judge {
        Judge::Cpu => SceneReference::compute(renderer, args.samples, |_| bar.inc(1))?,
        Judge::Gpu => {
            let traced = crate::gpu_judge::trace_reference(renderer, args.samples)?;
            bar.inc(renderer.scene().lights.len() as u64);
            traced
        }
    })
}

/// Judges every configuration against the reference of view `view`, advancing `bar` by one
/// per configuration; the runs that fail go to `failures`.
fn judge_configurations<'a>(
    renderer: &mut Renderer,
    reference: &SceneReference,
    configurations: &'a [Configuration],
    view: usize,
    bar: &ProgressBar,
    failures: &mut Vec<Failure<'a>>,
) -> Vec<Judged> {
    let mut judged = Vec::new();
    for config in configurations {
        bar.set_message(format!("view {view}: {}", config.label));
        let id = config.technique.id;
        match judge_technique(renderer, reference, id, &config.params) {
            Ok(j) => judged.push(Judged {
                technique: config.label.clone(),
                ..j
            }),
            Err(e) => failures.push((view, config.label.as_str(), e.to_string())),
        }
        bar.inc(1);
    }
    judged
}

/// Prints how each view's reference was traced.
fn print_references(views: &[JudgedView], judge: Judge) {
    for v in views {
        println!(
            "reference{}: {} occluder triangles, {} area samples, traced on the {} in {:.2} s",
            view_label(v, views.len()),
            v.reference.occluder_triangles,
            v.reference.lights.first().map_or(0, |l| l.samples),
            judge_name(judge),
            v.reference.seconds
        );
    }
}

/// Writes `results.csv` (into the already created `csv`), `indirect.csv` when a technique
/// adds light, `images.csv` and `report.md` into `out`; returns the paths of the images
/// table and the report.
fn write_outputs(
    out: &Path,
    mut csv: File,
    csv_path: &Path,
    r: &ReportInputs<'_>,
) -> anyhow::Result<[PathBuf; 2]> {
    csv.write_all(results_csv(r.scene, r.views).as_bytes())
        .with_context(|| format!("cannot write {}", csv_path.display()))?;
    if let Some(indirect) = indirect_csv(r.scene, r.views) {
        let path = out.join("indirect.csv");
        std::fs::write(&path, indirect)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let images_path = out.join("images.csv");
    std::fs::write(&images_path, images_csv(r.scene, r.views))
        .with_context(|| format!("cannot write {}", images_path.display()))?;
    let report_path = out.join("report.md");
    std::fs::write(&report_path, report_md(r))
        .with_context(|| format!("cannot write {}", report_path.display()))?;
    Ok([images_path, report_path])
}

/// Prints each view's summary table and indirect-light scores.
fn print_summaries(views: &[JudgedView]) {
    for v in views {
        if views.len() > 1 {
            println!("view {} (time {:.2}):", v.view, v.time.unwrap_or(0.0));
        }
        print!("{}", summary_table(v));
        for score in &v.indirect {
            println!(
                "  {:16} indirect_rmse {:.4} leak {:.4} (unlit {:.3} of pixels)",
                score.technique, score.rmse, score.leak.leak, score.leak.unlit_share
            );
            for (light, kind, why) in &score.unbounced {
                let sentence = unbounced_sentence(*light, *kind, why);
                println!("  {:16} {sentence}", score.technique);
            }
        }
    }
}

/// Prints the runs that failed, if any, and then fails: `runs` is how many there were.
fn check_failures(failures: &[Failure<'_>], runs: usize) -> anyhow::Result<()> {
    if failures.is_empty() {
        return Ok(());
    }
    for (view, id, e) in failures {
        eprintln!("{id} failed (view {view}): {e}");
    }
    bail!("{} of {runs} technique runs failed", failures.len());
}

/// `" (view N)"` when there are several views, else nothing.
fn view_label(view: &JudgedView, views: usize) -> String {
    if views > 1 {
        format!(" (view {})", view.view)
    } else {
        String::new()
    }
}

/// An output file name: `<technique>-<rest>` for a single view, `<technique>-view<N>-<rest>`
/// with several.
fn output_name(technique: &str, view: usize, several: bool, rest: &str) -> String {
    if several {
        format!("{technique}-view{view}-{rest}")
    } else {
        format!("{technique}-{rest}")
    }
}

/// Writes one view's error maps, FLIP maps and indirect-light files, and scores its indirect
/// light.
fn judge_view_outputs(
    mut view: JudgedView,
    renderer: &Renderer,
    args: &CompareArgs,
    several: bool,
) -> anyhow::Result<JudgedView> {
    for (j, flip) in view.judged.iter().zip(&view.flip) {
        for score in j.scores.iter().filter(|s| s.metrics.is_some()) {
            let name = output_name(
                &j.technique,
                view.view,
                several,
                &format!("light{}-error.png", score.light),
            );
            let path = args.out.join(name);
            error_map(
                &view.reference.lights[score.light],
                &j.visibility[score.light],
                &j.image,
            )
            .save(&path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if let Some(flip) = flip {
            let path = args
                .out
                .join(output_name(&j.technique, view.view, several, "flip.png"));
            flip.map
                .save(&path)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
    }
    view.indirect = judge_indirect(&mut view, renderer, args, several)?;
    Ok(view)
}

/// `results.csv`: one row per view, technique and light (unsupported lights have empty
/// metrics); with several views, then a `worst` and a `mean` row per technique and light.
pub fn results_csv(scene: &str, views: &[JudgedView]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    let row = |out: &mut String,
               technique: &str,
               view: &str,
               s: &LightScore,
               m: Option<&Metrics>,
               ms: f64| {
        let metrics = match m {
            Some(m) => format!(
                "{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
                m.pixels,
                m.false_shadow,
                m.false_lit,
                m.false_shadow_core,
                m.false_lit_core,
                m.mae,
                m.p95_error
            ),
            None => ",,,,,,".to_string(),
        };
        writeln!(
            out,
            "{scene},{technique},{view},{},{},{metrics},{ms:.4}",
            s.light,
            s.kind.name(),
        )
        .expect("write to string");
    };
    for v in views {
        for j in &v.judged {
            for s in &j.scores {
                row(
                    &mut out,
                    &j.technique,
                    &v.view.to_string(),
                    s,
                    s.metrics.as_ref(),
                    j.gpu_ms,
                );
            }
        }
    }
    if views.len() > 1 {
        for series in per_technique_and_light(views) {
            let score = &series.scores[0].0;
            let [(worst, worst_ms), (mean, mean_ms)] = series.worst_and_mean();
            row(
                &mut out,
                series.technique,
                "worst",
                score,
                worst.as_ref(),
                worst_ms,
            );
            row(
                &mut out,
                series.technique,
                "mean",
                score,
                mean.as_ref(),
                mean_ms,
            );
        }
    }
    out
}

/// One technique's scores of one light over the views: (score, frame time) per view.
struct LightSeries<'a> {
    technique: &'a str,
    light: usize,
    scores: Vec<(LightScore, f64)>,
}

impl LightSeries<'_> {
    /// The worst (largest) and the mean metrics over the views, and the frame time of each.
    /// Only the views where the light was scored and reached some pixel count (a spot light
    /// off-screen in one view does not pull the mean down); the mean weighs every such view
    /// alike, and `pixels` is their total.
    fn worst_and_mean(&self) -> [(Option<Metrics>, f64); 2] {
        let scored: Vec<&Metrics> = self
            .scores
            .iter()
            .filter_map(|(s, _)| s.metrics.as_ref())
            .filter(|m| m.pixels > 0)
            .collect();
        let n = self.scores.len() as f64;
        let ms = self.scores.iter().map(|(_, ms)| *ms);
        [
            (aggregate(&scored, f64::max), ms.clone().fold(0.0, f64::max)),
            (
                aggregate(&scored, |a, b| a + b).map(|m| scale(m, 1.0 / scored.len() as f64)),
                ms.sum::<f64>() / n,
            ),
        ]
    }
}

/// Per technique and light, in order: its scores over the views.
fn per_technique_and_light(views: &[JudgedView]) -> Vec<LightSeries<'_>> {
    let mut out: Vec<LightSeries<'_>> = Vec::new();
    for v in views {
        for j in &v.judged {
            for s in &j.scores {
                match out
                    .iter_mut()
                    .find(|x| x.technique == j.technique && x.light == s.light)
                {
                    Some(series) => series.scores.push((s.clone(), j.gpu_ms)),
                    None => out.push(LightSeries {
                        technique: &j.technique,
                        light: s.light,
                        scores: vec![(s.clone(), j.gpu_ms)],
                    }),
                }
            }
        }
    }
    out
}

/// Folds the metrics of every view with `combine` (pixels are summed), or `None` when the light
/// was not scored.
fn aggregate(metrics: &[&Metrics], combine: impl Fn(f64, f64) -> f64) -> Option<Metrics> {
    let (first, rest) = metrics.split_first()?;
    Some(rest.iter().fold(**first, |a, m| Metrics {
        pixels: a.pixels + m.pixels,
        false_shadow: combine(a.false_shadow, m.false_shadow),
        false_lit: combine(a.false_lit, m.false_lit),
        false_shadow_core: combine(a.false_shadow_core, m.false_shadow_core),
        false_lit_core: combine(a.false_lit_core, m.false_lit_core),
        mae: combine(a.mae, m.mae),
        p95_error: combine(a.p95_error, m.p95_error),
    }))
}

/// `m`'s fractions times `factor` (pixels kept).
fn scale(m: Metrics, factor: f64) -> Metrics {
    Metrics {
        false_shadow: m.false_shadow * factor,
        false_lit: m.false_lit * factor,
        false_shadow_core: m.false_shadow_core * factor,
        false_lit_core: m.false_lit_core * factor,
        mae: m.mae * factor,
        p95_error: m.p95_error * factor,
        ..m
    }
}

/// The worst and the mean (mean FLIP, p95 FLIP) over the views.
fn worst_and_mean_flip(scores: &[(f64, f64)]) -> [(f64, f64); 2] {
    let n = scores.len().max(1) as f64;
    let worst = scores
        .iter()
        .fold((0.0f64, 0.0f64), |(a, b), (m, p)| (a.max(*m), b.max(*p)));
    let mean = scores
        .iter()
        .fold((0.0, 0.0), |(a, b), (m, p)| (a + m / n, b + p / n));
    [worst, mean]
}

/// `images.csv`: the FLIP score of every technique's final image per view; with several
/// views, then its worst and mean.
pub fn images_csv(scene: &str, views: &[JudgedView]) -> String {
    let mut out = format!("{IMAGES_CSV_HEADER}\n");
    let mut per_technique: Vec<(&str, Vec<(f64, f64)>)> = Vec::new();
    for v in views {
        for (j, flip) in v.judged.iter().zip(&v.flip) {
            let Some(flip) = flip else { continue };
            writeln!(
                out,
                "{scene},{},{},{:.6},{:.6}",
                j.technique, v.view, flip.mean, flip.p95
            )
            .expect("write to string");
            match per_technique.iter_mut().find(|(t, _)| *t == j.technique) {
                Some((_, scores)) => scores.push((flip.mean, flip.p95)),
                None => per_technique.push((&j.technique, vec![(flip.mean, flip.p95)])),
            }
        }
    }
    if views.len() > 1 {
        for (technique, scores) in per_technique {
            let [worst, mean] = worst_and_mean_flip(&scores);
            writeln!(
                out,
                "{scene},{technique},worst,{:.6},{:.6}",
                worst.0, worst.1
            )
            .expect("write to string");
            writeln!(out, "{scene},{technique},mean,{:.6},{:.6}", mean.0, mean.1)
                .expect("write to string");
        }
    }
    out
}

/// The summary `compare` prints for one view: per technique and light its metrics, its image
/// score, and its notes and warnings.
pub fn summary_table(view: &JudgedView) -> String {
    let mut out = String::new();
    for (j, flip) in view.judged.iter().zip(&view.flip) {
        for s in &j.scores {
            match &s.metrics {
                Some(m) => writeln!(
                    out,
                    "  {:16} light {} ({:11}) false_shadow {:.4}  false_lit {:.4}  core {:.4}/{:.4}  mae {:.4}  p95 {:.3}  {:.2} ms",
                    j.technique, s.light, s.kind.name(), m.false_shadow, m.false_lit,
                    m.false_shadow_core, m.false_lit_core, m.mae, m.p95_error, j.gpu_ms
                ),
                None => writeln!(
                    out,
                    "  {:16} light {} ({:11}) not supported",
                    j.technique,
                    s.light,
                    s.kind.name()
                ),
            }
            .expect("write to string");
        }
        if let Some(flip) = flip {
            writeln!(
                out,
                "  {:16} image FLIP mean {:.4}  p95 {:.4}",
                j.technique, flip.mean, flip.p95
            )
            .expect("write to string");
        }
        if j.masks_opaque {
            let note = zoo_host::MaskedCasters::Opaque.describe();
            writeln!(
                out,
                "  {:16} {note}: the mask's holes cast shadows",
                j.technique
            )
            .expect("write to string");
        }
        for warning in &j.warnings {
            writeln!(out, "  {:16} warning: {warning}", j.technique).expect("write to string");
        }
    }
    out
}

/// The report's list of what techniques could not meet (their
/// [`zoo_host::ShadowTechnique::warnings`]), each once over the views; `None` where none
/// warned.
pub fn warnings_md(views: &[JudgedView]) -> Option<String> {
    let mut seen: Vec<(&str, &str)> = Vec::new();
    for j in views.iter().flat_map(|v| &v.judged) {
        for warning in &j.warnings {
            if !seen.contains(&(&j.technique, warning)) {
                seen.push((&j.technique, warning));
            }
        }
    }
    if seen.is_empty() {
        return None;
    }
    let mut out = String::from(
        "- Warnings: what techniques could not meet here, so their results fall short of what they should be:\n",
    );
    for (technique, warning) in seen {
        let _ = writeln!(out, "  - `{technique}`: {warning}");
    }
    Some(out)
}

/// Scores the indirect light of the techniques that add light in `view` against the
/// one-bounce reference (traced once per view, with the area samples per pixel), writes an
/// error map and the indirect light (`.hdr`) per technique and the reference's, and returns
/// their scores (relative RMSE and leak).
fn judge_indirect(
    view: &mut JudgedView,
    renderer: &Renderer,
    args: &CompareArgs,
    several: bool,
) -> anyhow::Result<Vec<IndirectScore>> {
    let mut scores = Vec::new();
    let (scene, lights) = (renderer.scene(), renderer.lights());
    let reference = &mut view.reference;
    for j in &view.judged {
        let (Some(estimate), Some(rmse), Some(leak)) = (
            &j.indirect,
            j.indirect_rmse(reference, scene, lights, args.samples),
            j.indirect_leak(reference, scene, lights, args.samples),
        ) else {
            continue;
        };
        let (width, height) = reference.size();
        let expected = reference.indirect(scene, lights, args.samples);
        let map = image::RgbaImage::from_fn(width as u32, height as u32, |x, y| {
            let i = y as usize * width + x as usize;
            let error = (estimate[i] - expected[i]).length() / expected[i].length().max(1e-3);
            let v = (error.min(1.0) * 255.0) as u8;
            image::Rgba([v, v, v, 255])
        });
        let name = |rest: &str| output_name(&j.technique, view.view, several, rest);
        let path = args.out.join(name("indirect-error.png"));
        map.save(&path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        save_radiance(&args.out.join(name("indirect.hdr")), estimate, width)?;
        if scores.is_empty() {
            let path = output_name("reference", view.view, several, "indirect.hdr");
            save_radiance(&args.out.join(path), expected, width)?;
        }
        let unbounced = (j.unbounced.iter())
            .map(|(light, why)| (*light, lights[*light].kind, why.clone()))
            .collect();
        scores.push(IndirectScore {
            technique: j.technique.clone(),
            rmse,
            leak,
            unbounced,
        });
    }
    Ok(scores)
}

/// `indirect.csv`: the relative RMSE and the leak of each technique that adds light, per view
/// (`None` when no technique adds light).
fn indirect_csv(scene: &str, views: &[JudgedView]) -> Option<String> {
    let mut csv =
        String::from("scene,technique,view,indirect_rmse,leak,unlit_share,unbounced_lights\n");
    let mut any = false;
    for v in views {
        for score in &v.indirect {
            any = true;
            writeln!(
                csv,
                "{scene},{},{},{:.6},{:.6},{:.6},{}",
                score.technique,
                v.view,
                score.rmse,
                score.leak.leak,
                score.leak.unlit_share,
                score.unbounced_list(";")
            )
            .expect("write to string");
        }
    }
    any.then_some(csv)
}

/// Writes linear RGB values, row by row from the top, as a Radiance HDR image.
fn save_radiance(path: &Path, values: &[Vec3], width: usize) -> anyhow::Result<()> {
    let height = values.len() / width.max(1);
    let image = image::Rgb32FImage::from_fn(width as u32, height as u32, |x, y| {
        let v = values[y as usize * width + x as usize].max(Vec3::ZERO);
        image::Rgb([v.x, v.y, v.z])
    });
    image
        .save(path)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Where a reference was traced, as the report says it.
fn judge_name(judge: Judge) -> &'static str {
    match judge {
        Judge::Cpu => "CPU",
        Judge::Gpu => "GPU (rt-shadows)",
    }
}

struct ReportInputs<'a> {
    scene: &'a str,
    scene_path: &'a Path,
    /// [`zoo_host::Scene::triangle_summary`].
    triangles: String,
    lights: usize,
    size: (u32, u32),
    adapter: &'a str,
    judge: Judge,
    views: &'a [JudgedView],
    /// (view, technique, error) of the runs that failed.
    failures: &'a [Failure<'a>],
}

/// One row of the report's metrics table.
fn metrics_row(
    w: &mut String,
    technique: &str,
    view: &str,
    s: &LightScore,
    m: Option<&Metrics>,
    ms: f64,
) {
    let _ = match m {
        Some(m) => writeln!(
            w,
            "| {technique} | {view} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {ms:.3} |",
            s.light,
            s.kind.name(),
            m.pixels,
            m.false_shadow,
            m.false_lit,
            m.false_shadow_core,
            m.false_lit_core,
            m.mae,
            m.p95_error,
        ),
        None => writeln!(
            w,
            "| {technique} | {view} | {} | {} | not supported | | | | | | | {ms:.3} |",
            s.light,
            s.kind.name(),
        ),
    };
}

const METRICS_TABLE_HEAD: &str = "| technique | view | light | kind | pixels | false_shadow | false_lit | false_shadow_core | false_lit_core | mae | p95_error | gpu_ms |\n|---|---|---|---|---|---|---|---|---|---|---|---|";

fn report_md(r: &ReportInputs<'_>) -> String {
    let mut out = String::new();
    let w = &mut out;
    summary_md(w, r);
    metrics_md(w, r.views);
    final_images_md(w, r.views);
    if r.views.iter().any(|v| !v.indirect.is_empty()) {
        indirect_md(w, r.views);
    }
    let judged = r
        .views
        .first()
        .map(|v| v.judged.as_slice())
        .unwrap_or_default();
    parameters_md(w, judged);
    pass_timings_md(w, judged);
    if !r.failures.is_empty() {
        failures_md(w, r.failures);
    }
    out
}

/// The report's title and its bullet list: scene, resolution, adapter, views,
/// reference, the casters some techniques treat as opaque, and the warnings.
fn summary_md(w: &mut String, r: &ReportInputs<'_>) {
    let _ = writeln!(w, "# Shadow Zoo comparison: {}\n", r.scene);
    let _ = writeln!(
        w,
        "- Scene: `{}` ({}, {} lights)",
        r.scene_path.display(),
        r.triangles,
        r.lights
    );
    let _ = writeln!(w, "- Resolution: {}x{}", r.size.0, r.size.1);
    let _ = writeln!(w, "- Adapter: {}", r.adapter);
    if r.views.len() > 1 {
        let times: Vec<String> = r
            .views
            .iter()
            .map(|v| format!("{:.2}", v.time.unwrap_or(0.0)))
            .collect();
        let _ = writeln!(
            w,
            "- Views: {} along the scene's camera and light paths, at times {}",
            r.views.len(),
            times.join(", ")
        );
    }
    if let Some(v) = r.views.first() {
        let seconds: f64 = r.views.iter().map(|v| v.reference.seconds).sum();
        let _ = writeln!(
            w,
            "- Reference: {} occluder triangles, {} area samples per pixel, traced on the {} in {:.2} s",
            v.reference.occluder_triangles,
            v.reference.lights.first().map_or(0, |l| l.samples),
            judge_name(r.judge),
            seconds
        );
        opaque_casters_md(w, v);
    }
    if let Some(warnings) = warnings_md(r.views) {
        w.push_str(&warnings);
    }
}

/// The bullets naming the techniques that treat translucent or alpha-masked
/// casters as opaque, judged on the first view.
fn opaque_casters_md(w: &mut String, first: &JudgedView) {
    if first.reference.lights.iter().any(|l| l.color.is_some()) {
        let opaque = technique_list(
            first
                .judged
                .iter()
                .filter(|j| j.transmittance.iter().all(Option::is_none)),
        );
        let _ = writeln!(
            w,
            "- Translucent casters: the reference filters light through them by colour; {} treat them as opaque (their visibility is scored against the mean colour that passes)",
            if opaque.is_empty() {
                "no technique here".to_string()
            } else {
                opaque.join(", ")
            }
        );
    }
    let masks_opaque = technique_list(first.judged.iter().filter(|j| j.masks_opaque));
    if !masks_opaque.is_empty() {
        let _ = writeln!(
            w,
            "- Alpha-masked casters: the reference lets light through their holes; {} treat them as opaque (their registrations say so: shadow volumes cannot follow a texture)",
            masks_opaque.join(", ")
        );
    }
}

/// The techniques' names, each in backticks.
fn technique_list<'a>(judged: impl Iterator<Item = &'a Judged>) -> Vec<String> {
    judged.map(|j| format!("`{}`", j.technique)).collect()
}

/// The visibility metrics of every view, then (with several views) their
/// worst and mean over the views.
fn metrics_md(w: &mut String, views: &[JudgedView]) {
    let _ = writeln!(
        w,
        "\nFractions are of the pixels each light reaches. `core` leaves out the one-pixel band around reference shadow boundaries; `mae` and `p95` compare with the area-light reference. Error maps: red = false shadow, blue = false lit, grey = both shadowed.\n"
    );
    let _ = writeln!(w, "{METRICS_TABLE_HEAD}");
    for v in views {
        for j in &v.judged {
            for s in &j.scores {
                metrics_row(
                    w,
                    &j.technique,
                    &v.view.to_string(),
                    s,
                    s.metrics.as_ref(),
                    j.gpu_ms,
                );
            }
        }
    }
    if views.len() > 1 {
        let _ = writeln!(
            w,
            "\n## Over the views\n\nPer technique and light, the worst (largest) and the mean of each metric over the {} views.\n",
            views.len()
        );
        let _ = writeln!(w, "{METRICS_TABLE_HEAD}");
        for series in per_technique_and_light(views) {
            let score = &series.scores[0].0;
            let [(worst, worst_ms), (mean, mean_ms)] = series.worst_and_mean();
            metrics_row(
                w,
                series.technique,
                "worst",
                score,
                worst.as_ref(),
                worst_ms,
            );
            metrics_row(w, series.technique, "mean", score, mean.as_ref(), mean_ms);
        }
    }
}

/// The ꟻLIP table of the final images: one row per technique and view, then
/// (with several views) each technique's worst and mean.
fn final_images_md(w: &mut String, views: &[JudgedView]) {
    let _ = writeln!(
        w,
        "\n## Final images\n\nꟻLIP of each technique's final image against the reference image (the reference's area visibility shaded by the same lighting on the CPU, with the one-bounce indirect reference for techniques that add light), at 67 pixels per degree: 0 is identical, 1 the largest difference. Maps `<technique>-flip.png` (`<technique>-view<K>-flip.png` with several views; magma: black none, yellow large); values in `images.csv`.\n"
    );
    let _ = writeln!(w, "| technique | view | flip_mean | flip_p95 |");
    let _ = writeln!(w, "|---|---|---|---|");
    let mut per_technique: Vec<(&str, Vec<(f64, f64)>)> = Vec::new();
    for v in views {
        for (j, flip) in v.judged.iter().zip(&v.flip) {
            if let Some(flip) = flip {
                let _ = writeln!(
                    w,
                    "| {} | {} | {:.4} | {:.4} |",
                    j.technique, v.view, flip.mean, flip.p95
                );
                match per_technique.iter_mut().find(|(t, _)| *t == j.technique) {
                    Some((_, scores)) => scores.push((flip.mean, flip.p95)),
                    None => per_technique.push((&j.technique, vec![(flip.mean, flip.p95)])),
                }
            }
        }
    }
    if views.len() > 1 {
        for (technique, scores) in per_technique {
            let [worst, mean] = worst_and_mean_flip(&scores);
            let _ = writeln!(
                w,
                "| {technique} | worst | {:.4} | {:.4} |",
                worst.0, worst.1
            );
            let _ = writeln!(w, "| {technique} | mean | {:.4} | {:.4} |", mean.0, mean.1);
        }
    }
}

/// The indirect-light section: each technique's error and leak per view.
fn indirect_md(w: &mut String, views: &[JudgedView]) {
    let _ = writeln!(
        w,
        "\n## Indirect light\n\nRelative RMSE of each technique's indirect light (irradiance over π) against the one-bounce diffuse reference, over the pixels with a surface; error maps `<technique>-indirect-error.png` (black: exact, white: off by the reference's own value or more); the values themselves in `reference-indirect.hdr` and `<technique>-indirect.hdr` (linear Radiance HDR). Leak: the technique's mean indirect light on the surfaces that no directly lit surface sees (the reference is exactly 0 there: no cosine ray found light, and none of the points traced as lit from every light is in view), as a fraction of the reference's mean over every surface; `unlit` is those surfaces' share of the pixels.\n"
    );
    let _ = writeln!(
        w,
        "| technique | view | indirect_rmse | leak | unlit | lights not bounced |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|");
    let mut reasons = std::collections::BTreeSet::new();
    for v in views {
        for score in &v.indirect {
            let _ = writeln!(
                w,
                "| {} | {} | {:.4} | {:.4} | {:.3} | {} |",
                score.technique,
                v.view,
                score.rmse,
                score.leak.leak,
                score.leak.unlit_share,
                score.unbounced_list(", ")
            );
            for (light, kind, why) in &score.unbounced {
                let sentence = unbounced_sentence(*light, *kind, why);
                reasons.insert(format!("- `{}`: {sentence}", score.technique));
            }
        }
    }
    if !reasons.is_empty() {
        let _ = writeln!(
            w,
            "\nThe one-bounce reference bounces every light; a technique's error includes the \
             light of those it does not bounce:\n"
        );
        for reason in reasons {
            let _ = writeln!(w, "{reason}");
        }
    }
}

/// Each technique's parameter values.
fn parameters_md(w: &mut String, judged: &[Judged]) {
    let _ = writeln!(w, "\n## Parameters\n");
    for j in judged {
        let values: Vec<String> = j.params.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        let _ = writeln!(
            w,
            "- `{}`: {}",
            j.technique,
            if values.is_empty() {
                "none".to_string()
            } else {
                values.join(", ")
            }
        );
    }
}

/// Each technique's GPU pass timings on the first view.
fn pass_timings_md(w: &mut String, judged: &[Judged]) {
    let _ = writeln!(
        w,
        "\n## Pass timings ({}, view 0)\n",
        judged.first().map_or("", |j| j.timings.source.label())
    );
    for j in judged {
        let passes: Vec<String> = j
            .timings
            .passes
            .iter()
            .map(|p| format!("{} {:.3} ms", p.name, p.milliseconds))
            .collect();
        let _ = writeln!(w, "- `{}`: {}", j.technique, passes.join(", "));
    }
}

/// The runs that failed, by view and technique.
fn failures_md(w: &mut String, failures: &[Failure<'_>]) {
    let _ = writeln!(w, "\n## Failures\n");
    for (view, id, e) in failures {
        let _ = writeln!(w, "- `{id}` (view {view}): {e}");
    }
}
