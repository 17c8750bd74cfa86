//! `shadow-zoo compare`: render techniques, judge them, write CSV, markdown and error maps.

use std::fmt::Write as _;
use std::fs::File;
use std::io::Write as _;
use std::path::Path;

use anyhow::{Context, bail};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use zoo_host::judging::{Judged, SceneReference, error_map, judge_technique};
use zoo_host::params::{self, ParamValues};
use zoo_host::{Renderer, Scene, TechniqueRegistration};

use crate::cli::CompareArgs;
use crate::setup::headless_gpu;

/// The exact header of `results.csv`.
pub const CSV_HEADER: &str = "scene,technique,light,light_kind,pixels,false_shadow,false_lit,\
false_shadow_core,false_lit_core,mae,p95_error,gpu_ms";

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

/// Runs `shadow-zoo compare`.
pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    let techniques = select_techniques(&args.techniques)?;
    let params = technique_params(&techniques, &args.set)?;
    let scene = Scene::load(&args.scene)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output folder {}", args.out.display()))?;
    let csv_path = args.out.join("results.csv");
    let mut csv = File::create(&csv_path)
        .with_context(|| format!("output folder {} is not writable", args.out.display()))?;

    let gpu = headless_gpu()?;
    let adapter = gpu.describe();
    println!(
        "scene: {} ({} triangles, {} lights); {} techniques at {}x{}",
        scene.name,
        scene.triangle_count(),
        scene.lights.len(),
        techniques.len(),
        args.size.x,
        args.size.y
    );
    let light_count = scene.lights.len();
    let scene_name = scene.name.clone();
    let triangles = scene.triangle_count();
    let mut renderer = Renderer::new(gpu, scene, args.size)?;

    let bar = ProgressBar::new((light_count + techniques.len()) as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed}]")
            .expect("valid template"),
    );
    bar.set_message("reference");
    let mut reference = SceneReference::compute(&mut renderer, args.samples, |_| bar.inc(1))?;
    let mut judged = Vec::new();
    let mut failures = Vec::new();
    for (technique, values) in techniques.iter().zip(&params) {
        bar.set_message(technique.id);
        match judge_technique(&mut renderer, &reference, technique.id, values) {
            Ok(j) => judged.push(j),
            Err(e) => failures.push((technique.id, e.to_string())),
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    println!(
        "reference: {} occluder triangles, {} area samples, traced in {:.2} s",
        reference.occluder_triangles,
        reference.lights.first().map_or(0, |l| l.samples),
        reference.seconds
    );

    csv.write_all(results_csv(&scene_name, &judged).as_bytes())
        .with_context(|| format!("cannot write {}", csv_path.display()))?;
    for j in &judged {
        for score in j.scores.iter().filter(|s| s.metrics.is_some()) {
            let path = args
                .out
                .join(format!("{}-light{}-error.png", j.technique, score.light));
            error_map(
                &reference.lights[score.light],
                &j.visibility[score.light],
                &j.image,
            )
            .save(&path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        }
    }
    let indirect = judge_indirect(&judged, &mut reference, &renderer, args)?;
    let report = report_md(&ReportInputs {
        scene: &scene_name,
        scene_path: &args.scene,
        triangles,
        lights: light_count,
        size: (args.size.x, args.size.y),
        adapter: &adapter,
        reference: &reference,
        judged: &judged,
        indirect: &indirect,
        failures: &failures,
    });
    let report_path = args.out.join("report.md");
    std::fs::write(&report_path, &report)
        .with_context(|| format!("cannot write {}", report_path.display()))?;
    print!("{}", summary_table(&judged));
    println!(
        "wrote {}, {} and the error maps",
        csv_path.display(),
        report_path.display()
    );
    if !failures.is_empty() {
        for (id, e) in &failures {
            eprintln!("{id} failed: {e}");
        }
        bail!(
            "{} of {} techniques failed",
            failures.len(),
            techniques.len()
        );
    }
    Ok(())
}

/// `results.csv`: one row per technique and light; unsupported lights have empty metrics.
pub fn results_csv(scene: &str, judged: &[Judged]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for j in judged {
        for s in &j.scores {
            let metrics = match &s.metrics {
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
                "{scene},{},{},{},{metrics},{:.4}",
                j.technique,
                s.light,
                s.kind.name(),
                j.gpu_ms
            )
            .expect("write to string");
        }
    }
    out
}

fn summary_table(judged: &[Judged]) -> String {
    let mut out = String::new();
    for j in judged {
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
    }
    out
}

/// Scores the indirect light of the techniques that add light against the one-bounce
/// reference (traced once, with the area samples per pixel), writes `indirect.csv`, an error
/// map and the indirect light (`.hdr`) per technique and the reference's, and returns
/// (technique, relative RMSE).
fn judge_indirect(
    judged: &[Judged],
    reference: &mut SceneReference,
    renderer: &Renderer,
    args: &CompareArgs,
) -> anyhow::Result<Vec<(String, f64)>> {
    let mut scores = Vec::new();
    let (scene, lights) = (renderer.scene(), renderer.lights());
    for j in judged {
        let (Some(estimate), Some(rmse)) = (
            &j.indirect,
            j.indirect_rmse(reference, scene, lights, args.samples),
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
        let path = args.out.join(format!("{}-indirect-error.png", j.technique));
        map.save(&path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        save_radiance(
            &args.out.join(format!("{}-indirect.hdr", j.technique)),
            estimate,
            width,
        )?;
        if scores.is_empty() {
            save_radiance(&args.out.join("reference-indirect.hdr"), expected, width)?;
        }
        scores.push((j.technique.clone(), rmse));
    }
    if !scores.is_empty() {
        let mut csv = String::from("scene,technique,indirect_rmse\n");
        for (technique, rmse) in &scores {
            writeln!(csv, "{},{technique},{rmse:.6}", scene.name).expect("write to string");
        }
        let path = args.out.join("indirect.csv");
        std::fs::write(&path, csv).with_context(|| format!("cannot write {}", path.display()))?;
        for (technique, rmse) in &scores {
            println!("  {technique:16} indirect_rmse {rmse:.4}");
        }
    }
    Ok(scores)
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

struct ReportInputs<'a> {
    scene: &'a str,
    scene_path: &'a Path,
    triangles: usize,
    lights: usize,
    size: (u32, u32),
    adapter: &'a str,
    reference: &'a SceneReference,
    judged: &'a [Judged],
    /// (technique, relative RMSE) of the techniques that add light.
    indirect: &'a [(String, f64)],
    failures: &'a [(&'static str, String)],
}

fn report_md(r: &ReportInputs<'_>) -> String {
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "# Shadow Zoo comparison: {}\n", r.scene);
    let _ = writeln!(
        w,
        "- Scene: `{}` ({} triangles, {} lights)",
        r.scene_path.display(),
        r.triangles,
        r.lights
    );
    let _ = writeln!(w, "- Resolution: {}x{}", r.size.0, r.size.1);
    let _ = writeln!(w, "- Adapter: {}", r.adapter);
    let _ = writeln!(
        w,
        "- Reference: {} occluder triangles, {} area samples per pixel, traced in {:.2} s",
        r.reference.occluder_triangles,
        r.reference.lights.first().map_or(0, |l| l.samples),
        r.reference.seconds
    );
    if r.reference.lights.iter().any(|l| l.color.is_some()) {
        let opaque: Vec<String> = r
            .judged
            .iter()
            .filter(|j| j.transmittance.iter().all(Option::is_none))
            .map(|j| format!("`{}`", j.technique))
            .collect();
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
    let _ = writeln!(
        w,
        "\nFractions are of the pixels each light reaches. `core` leaves out the one-pixel band around reference shadow boundaries; `mae` and `p95` compare with the area-light reference. Error maps: red = false shadow, blue = false lit, grey = both shadowed.\n"
    );
    let _ = writeln!(
        w,
        "| technique | light | kind | pixels | false_shadow | false_lit | false_shadow_core | false_lit_core | mae | p95_error | gpu_ms |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|---|");
    for j in r.judged {
        for s in &j.scores {
            match &s.metrics {
                Some(m) => {
                    let _ = writeln!(
                        w,
                        "| {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.3} |",
                        j.technique,
                        s.light,
                        s.kind.name(),
                        m.pixels,
                        m.false_shadow,
                        m.false_lit,
                        m.false_shadow_core,
                        m.false_lit_core,
                        m.mae,
                        m.p95_error,
                        j.gpu_ms
                    );
                }
                None => {
                    let _ = writeln!(
                        w,
                        "| {} | {} | {} | not supported | | | | | | | {:.3} |",
                        j.technique,
                        s.light,
                        s.kind.name(),
                        j.gpu_ms
                    );
                }
            }
        }
    }
    if !r.indirect.is_empty() {
        let _ = writeln!(
            w,
            "\n## Indirect light\n\nRelative RMSE of each technique's indirect light (irradiance over π) against the one-bounce diffuse reference, over the pixels with a surface; error maps `<technique>-indirect-error.png` (black: exact, white: off by the reference's own value or more); the values themselves in `reference-indirect.hdr` and `<technique>-indirect.hdr` (linear Radiance HDR).\n"
        );
        let _ = writeln!(w, "| technique | indirect_rmse |");
        let _ = writeln!(w, "|---|---|");
        for (technique, rmse) in r.indirect {
            let _ = writeln!(w, "| {technique} | {rmse:.4} |");
        }
    }
    let _ = writeln!(w, "\n## Parameters\n");
    for j in r.judged {
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
    let _ = writeln!(
        w,
        "\n## Pass timings ({})\n",
        r.judged.first().map_or("", |j| j.timings.source.label())
    );
    for j in r.judged {
        let passes: Vec<String> = j
            .timings
            .passes
            .iter()
            .map(|p| format!("{} {:.3} ms", p.name, p.milliseconds))
            .collect();
        let _ = writeln!(w, "- `{}`: {}", j.technique, passes.join(", "));
    }
    if !r.failures.is_empty() {
        let _ = writeln!(w, "\n## Failures\n");
        for (id, e) in r.failures {
            let _ = writeln!(w, "- `{id}`: {e}");
        }
    }
    out
}
