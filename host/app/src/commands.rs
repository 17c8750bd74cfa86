//! The commands behind the CLI.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use zoo_host::gpu::{FrameTimings, PassOwner};
use zoo_host::{GpuContext, Renderer, Scene, View, params};

use crate::cli::{Cli, Command, RenderArgs};
use crate::contact_sheet;
use crate::setup::{headless_gpu, load_scene};

/// Runs a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        None => crate::viewer::run(),
        Some(Command::List) => {
            list();
            Ok(())
        }
        Some(Command::Render(args)) => render(&args),
        Some(Command::Compare(args)) => crate::compare::run(&args),
        Some(Command::Bench(args)) => crate::bench::run(&args),
        Some(Command::Claims(args)) => crate::claims::run(&args),
    }
}

/// One line per registered technique: id, description, supported light kinds, how it treats
/// masked casters when not alpha-tested, and, when `gpu` is given, why a technique cannot
/// run on it.
pub fn list_techniques(gpu: Option<&GpuContext>) -> String {
    let all = zoo_host::registry();
    let width = all.iter().map(|r| r.id.len()).max().unwrap_or(0);
    all.iter()
        .map(|r| {
            let unavailable = gpu
                .and_then(|gpu| r.unavailable_reason(gpu))
                .map(|reason| format!("  unavailable here: {reason}"))
                .unwrap_or_default();
            let masks = match r.masked_casters {
                zoo_host::MaskedCasters::AlphaTested => String::new(),
                other => format!("  ({})", other.describe()),
            };
            format!(
                "{:width$}  {}  [{}]{masks}{unavailable}\n",
                r.id,
                r.description,
                r.light_kind_names()
            )
        })
        .collect()
}

/// `list`: the techniques, checked against the adapter when there is one.
fn list() {
    match GpuContext::new_headless() {
        Ok(gpu) => {
            println!("adapter: {}", gpu.describe());
            print!("{}", list_techniques(Some(&gpu)));
        }
        Err(e) => {
            print!("{}", list_techniques(None));
            println!("(availability not checked: {e})");
        }
    }
}

fn render(args: &RenderArgs) -> anyhow::Result<()> {
    match &args.technique {
        Some(id) => render_one(args, id),
        None => render_sheet(args),
    }
}

/// Checks that `--out`'s folder exists before any work is done.
fn check_out_folder(out: &Path) -> anyhow::Result<()> {
    let out_dir = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    if !out_dir.is_dir() {
        bail!(
            "--out {}: folder {} does not exist",
            out.display(),
            out_dir.display()
        );
    }
    Ok(())
}

/// The scene's size and how long loading it took.
fn print_scene(scene: &Scene, load_time: std::time::Duration) {
    println!(
        "scene: {} ({}, {} lights, {} objects, {} texture layers; loaded in {:.2} s)",
        scene.name,
        scene.triangle_summary(),
        scene.lights.len(),
        scene.objects.len(),
        scene.textures.layers.len(),
        load_time.as_secs_f64()
    );
}

/// `render` without `--technique`: the contact sheet.
fn render_sheet(args: &RenderArgs) -> anyhow::Result<()> {
    if args.view != "final" {
        bail!(
            "--view {}: views other than `final` need --technique",
            args.view
        );
    }
    let registry = crate::compare::select_techniques(&args.techniques)?;
    let params = crate::compare::technique_params(&registry, &args.set)?;
    let started = std::time::Instant::now();
    let scene = load_scene(args.scene.as_deref())?;
    let load_time = started.elapsed();
    check_out_folder(&args.out)?;
    let gpu = headless_gpu()?;
    let shaders = crate::setup::shader_library(args.shaders.as_deref())?;
    print_scene(&scene, load_time);
    let (available, unavailable) = contact_sheet::available_techniques(&gpu);
    for (id, reason) in &unavailable {
        println!("note: {id} is unavailable on this adapter: {reason}");
    }
    let techniques: Vec<_> = registry
        .into_iter()
        .zip(params)
        .filter(|(r, _)| available.iter().any(|a| a.id == r.id))
        .collect();
    let mut renderer = Renderer::with_shaders(gpu, scene, args.size, shaders)?;
    let sheet = contact_sheet::build(&mut renderer, &techniques, args.samples, |step| {
        println!("rendering {step}...");
    })?;
    let image = contact_sheet::draw(&sheet)?;
    image
        .save(&args.out)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    print!("{}", contact_sheet::table(&sheet));
    if args.timings {
        for row in &sheet.rows {
            if let Some(timings) = &row.timings {
                print!("{}: {}", row.id, format_timings(timings));
            }
        }
    }
    println!(
        "false shadow / false lit: fractions of the pixels each light reaches, leaving out the \
         one-pixel band at reference shadow edges; mae: against the area-light reference; \
         weighted over the lights each technique supports"
    );
    println!(
        "wrote {} ({}x{}, {} tiles of {}x{})",
        args.out.display(),
        image.width(),
        image.height(),
        sheet.rows.len(),
        args.size.x,
        args.size.y
    );
    Ok(())
}

/// `render --technique ID`: one frame.
fn render_one(args: &RenderArgs, id: &str) -> anyhow::Result<()> {
    let technique = zoo_host::find_technique(id)?;
    let schema = (technique.params)();
    let mut values = params::defaults(&schema);
    params::apply_assignments(&schema, &mut values, &args.set)
        .with_context(|| format!("technique `{}`", technique.id))?;
    let started = std::time::Instant::now();
    let scene = load_scene(args.scene.as_deref())?;
    let load_time = started.elapsed();
    let view: View = args.view.parse().expect("infallible");
    if let View::Visibility { light } = view
        && light >= scene.lights.len()
    {
        bail!(
            "--view visibility:{light}: the scene has {} lights",
            scene.lights.len()
        );
    }
    check_out_folder(&args.out)?;

    let gpu = headless_gpu()?;
    let shaders = crate::setup::shader_library(args.shaders.as_deref())?;
    print_scene(&scene, load_time);
    let unsupported: Vec<String> = scene
        .lights
        .iter()
        .enumerate()
        .filter(|(_, l)| !technique.supports(l.kind))
        .map(|(i, l)| format!("{i} ({})", l.kind.name()))
        .collect();
    let mut renderer = Renderer::with_shaders(gpu, scene, args.size, shaders)?;
    renderer.set_technique(technique.id, &values)?;
    println!("technique: {} ({})", technique.id, technique.name);
    if !unsupported.is_empty() {
        println!(
            "note: {} does not support lights {}; they are rendered unshadowed",
            technique.id,
            unsupported.join(", ")
        );
    }
    for _ in 1..args.frames {
        renderer.render(&view)?;
    }
    let timings = renderer.render(&view)?;
    let image = renderer.read_output();
    image
        .save(&args.out)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    println!(
        "wrote {} ({}x{}, view {})",
        args.out.display(),
        args.size.x,
        args.size.y,
        args.view
    );
    if args.timings {
        print!("{}", format_timings(&timings));
        for (name, value) in renderer.wait_for_counters() {
            println!("  counter {name}: {value}");
        }
    }
    Ok(())
}

/// A table of pass times.
pub fn format_timings(timings: &FrameTimings) -> String {
    let width = timings
        .passes
        .iter()
        .map(|p| p.name.len())
        .max()
        .unwrap_or(4)
        .max(5);
    let mut out = format!("pass timings ({}):\n", timings.source.label());
    for p in &timings.passes {
        let owner = match p.owner {
            PassOwner::Host => "host",
            PassOwner::Technique => "technique",
        };
        out += &format!(
            "  {:width$}  {:>9}  {:8.3} ms\n",
            p.name, owner, p.milliseconds
        );
    }
    out += &format!(
        "  {:width$}  {:>9}  {:8.3} ms\n  {:width$}  {:>9}  {:8.3} ms\n",
        "technique total",
        "",
        timings.total(PassOwner::Technique),
        "frame total",
        "",
        timings.frame_total()
    );
    out
}
