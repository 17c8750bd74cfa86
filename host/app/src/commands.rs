//! The commands behind the CLI.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, bail};
use zoo_host::gpu::{FrameTimings, PassOwner};
use zoo_host::{GpuContext, Renderer, Scene, View, params};

use crate::cli::{Cli, Command, RenderArgs};

/// Runs a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        None => crate::viewer::run(),
        Some(Command::List) => {
            print!("{}", list_techniques());
            Ok(())
        }
        Some(Command::Render(args)) => render(&args),
        Some(Command::Compare(args)) => crate::compare::run(&args),
        Some(Command::Bench(args)) => crate::bench::run(&args),
    }
}

/// One line per registered technique: id, description, supported light kinds.
pub fn list_techniques() -> String {
    let all = zoo_host::registry();
    let width = all.iter().map(|r| r.id.len()).max().unwrap_or(0);
    all.iter()
        .map(|r| {
            format!(
                "{:width$}  {}  [{}]\n",
                r.id,
                r.description,
                r.light_kind_names()
            )
        })
        .collect()
}

/// Loads `path`, or the built-in default scene when `None`.
pub fn load_scene(path: Option<&Path>) -> anyhow::Result<Scene> {
    Ok(match path {
        Some(path) => Scene::load(path)?,
        None => Scene::from_ron(
            crate::DEFAULT_SCENE,
            Path::new(crate::DEFAULT_SCENE_NAME),
            Path::new("scenes"),
        )?,
    })
}

/// Creates the headless GPU context and prints what it runs on.
pub fn headless_gpu() -> anyhow::Result<Arc<GpuContext>> {
    let gpu = GpuContext::new_headless()?;
    println!("adapter: {}", gpu.describe());
    Ok(Arc::new(gpu))
}

fn render(args: &RenderArgs) -> anyhow::Result<()> {
    let technique = zoo_host::find_technique(&args.technique)?;
    let schema = (technique.params)();
    let mut values = params::defaults(&schema);
    params::apply_assignments(&schema, &mut values, &args.set)
        .with_context(|| format!("technique `{}`", technique.id))?;
    let scene = load_scene(args.scene.as_deref())?;
    let view: View = args.view.parse().expect("infallible");
    if let View::Visibility { light } = view
        && light >= scene.lights.len()
    {
        bail!(
            "--view visibility:{light}: the scene has {} lights",
            scene.lights.len()
        );
    }
    let out_dir = args
        .out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    if !out_dir.is_dir() {
        bail!(
            "--out {}: folder {} does not exist",
            args.out.display(),
            out_dir.display()
        );
    }

    let gpu = headless_gpu()?;
    println!(
        "scene: {} ({} triangles, {} lights, {} objects)",
        scene.name,
        scene.triangle_count(),
        scene.lights.len(),
        scene.objects.len()
    );
    let unsupported: Vec<String> = scene
        .lights
        .iter()
        .enumerate()
        .filter(|(_, l)| !technique.supports(l.kind))
        .map(|(i, l)| format!("{i} ({})", l.kind.name()))
        .collect();
    let mut renderer = Renderer::new(gpu, scene, args.size)?;
    renderer.set_technique(technique.id, &values)?;
    println!("technique: {} ({})", technique.id, technique.name);
    if !unsupported.is_empty() {
        println!(
            "note: {} does not support lights {}; they are rendered unshadowed",
            technique.id,
            unsupported.join(", ")
        );
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
        for (name, value) in renderer.technique_instance().counters() {
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
