//! Command-line arguments.

use std::path::PathBuf;

use clap::{Parser, Subcommand};
use glam::UVec2;
use serde::Deserialize;

/// Shadow Zoo: real-time shadow techniques side by side, judged against ray-traced visibility.
#[derive(Debug, Parser)]
#[command(name = "shadow-zoo", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// What to do.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// List the registered techniques: id, description and supported light kinds.
    List,
    /// Render off-screen and write a PNG: without `--technique`, a contact sheet of every
    /// available technique beside the ray-traced reference, each tile labelled with its frame
    /// time and judged error (also printed as a table); with `--technique`, that one frame.
    Render(RenderArgs),
    /// Render techniques, judge them against ray-traced visibility, and write results.csv,
    /// report.md and per-light error maps.
    Compare(CompareArgs),
    /// Benchmark techniques along the scene's camera and light paths: per-pass GPU times,
    /// CPU frame times, counters and flicker, as CSV, markdown and PNG plots.
    Bench(BenchArgs),
    /// Reproduce the sources' headline claims: one measurement per claim (a bench suite's
    /// ratio, or the judge for seed 000's claims without numbers), written as claims.md and
    /// claims.csv beside the sources' figures.
    Claims(ClaimsArgs),
}

/// Arguments of `shadow-zoo claims`.
#[derive(Debug, clap::Args)]
pub struct ClaimsArgs {
    /// Folder for claims.md, claims.csv and the benchmark's outputs (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Only the claims whose text or source contains this (any case), e.g. `seed 002`.
    #[arg(long)]
    pub only: Option<String>,
    /// Read WGSL from DIR first (laid out as `shaders/`).
    #[arg(long, value_name = "DIR")]
    pub shaders: Option<PathBuf>,
}

/// Arguments of `shadow-zoo bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Scene file (RON) with keyframed paths, or a model file staged in a scene (still).
    #[arg(long, required_unless_present = "suite")]
    pub scene: Option<PathBuf>,
    /// Run a suite from `scenes/bench/NAME.ron` instead (reproduces a seed's experiment).
    #[arg(long, conflicts_with = "scene")]
    pub suite: Option<String>,
    /// Comma-separated technique ids, or `all` (`unshadowed` is always added as the baseline).
    #[arg(long, default_value = "all")]
    pub techniques: String,
    /// Output size as WIDTHxHEIGHT.
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    pub size: UVec2,
    /// Measured frames per configuration (default 30; a suite's own count otherwise).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Frames rendered before measuring.
    #[arg(long, default_value_t = 3)]
    pub warmup: u32,
    /// What moves along the scene's paths.
    #[arg(long, value_enum, default_value = "camera")]
    pub path: PathMode,
    /// Sweep a quantity: `size=256x256,512x512`, `scene.tessellation=0.5,1,2` or
    /// `TECHNIQUE.PARAM=v1,v2` (repeatable; configurations are the cartesian product).
    #[arg(long = "sweep", value_name = "KEY=v1,v2,...", value_parser = parse_assignment)]
    pub sweep: Vec<(String, String)>,
    /// Fix a technique parameter, e.g. `--set sm-pcf.filter=Pcss` (repeatable).
    #[arg(long = "set", value_name = "ID.KEY=VALUE", value_parser = parse_assignment)]
    pub set: Vec<(String, String)>,
    /// Skip the flicker index (it traces the reference for every measured frame).
    #[arg(long)]
    pub no_flicker: bool,
    /// Time every pass on the CPU clock, submitted on its own, instead of with GPU timestamps
    /// (for CPU drivers such as lavapipe, whose timestamps miss compute work).
    #[arg(long)]
    pub cpu_timing: bool,
    /// Let techniques keep work whose inputs did not change between frames (shadow maps of
    /// lights that did not move), as the viewer does; by default every measured frame does
    /// all of its work.
    #[arg(long)]
    pub reuse_unchanged: bool,
    /// Read WGSL from DIR first (laid out as `shaders/`; files it lacks come from the
    /// copies built in), so edited shaders take effect without a rebuild.
    #[arg(long, value_name = "DIR")]
    pub shaders: Option<PathBuf>,
    /// Folder for bench.csv, summary.csv, bench.md and the plots.
    #[arg(long)]
    pub out: PathBuf,
}

/// Arguments of `shadow-zoo compare`.
#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// Scene file (RON), or a model file (`.obj`, `.gltf`, `.glb`) staged in a scene.
    #[arg(long)]
    pub scene: PathBuf,
    /// Comma-separated technique ids, or `all`.
    #[arg(long, default_value = "all")]
    pub techniques: String,
    /// Output size as WIDTHxHEIGHT.
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    pub size: UVec2,
    /// Folder for results.csv, report.md and the error maps (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Set a technique parameter, e.g. `--set sm-pcf.map_size=4096` (repeatable).
    #[arg(long = "set", value_name = "ID.KEY=VALUE", value_parser = parse_assignment)]
    pub set: Vec<(String, String)>,
    /// Judge a technique at several values of a parameter in one run, against one reference:
    /// `--sweep sm-pcf.map_size=512,1024,2048` (repeatable; one technique's sweeps multiply).
    /// Each configuration is a row `ID@KEY=VALUE@...` of the results.
    #[arg(long = "sweep", value_name = "ID.KEY=v1,v2,...", value_parser = parse_assignment)]
    pub sweep: Vec<(String, String)>,
    /// Area-light samples per pixel for the soft reference (rounded up to a square).
    #[arg(long, default_value_t = zoo_host::judging::DEFAULT_SAMPLES,
          value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub samples: u32,
    /// Judge N views spread evenly over the scene's camera and light paths (both ends
    /// included) instead of the scene's camera alone; results get per-view rows and the worst
    /// and mean over views (every view's frames stay in memory until the report: at most 64).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub views: u32,
    /// Read WGSL from DIR first (laid out as `shaders/`; files it lacks come from the
    /// copies built in), so edited shaders take effect without a rebuild.
    #[arg(long, value_name = "DIR")]
    pub shaders: Option<PathBuf>,
    /// Where the reference visibility is traced: `cpu` (the arbiter) or `gpu` (the ray-tracing
    /// library through rt-shadows, at most 64 area samples; scenes without translucent
    /// casters).
    #[arg(long, value_enum, default_value_t = Judge::Cpu)]
    pub judge: Judge,
}

/// Where `compare` traces its reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Judge {
    /// The CPU judge (exact surfaces and error bounds): the arbiter.
    Cpu,
    /// The GPU ray tracer.
    Gpu,
}

/// Arguments of `shadow-zoo render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// Scene file (RON), or a model file (`.obj`, `.gltf`, `.glb`) staged in a scene. Defaults
    /// to the built-in planar-room scene.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Technique id (see `shadow-zoo list`). Without it, a contact sheet of `--techniques`.
    #[arg(long)]
    pub technique: Option<String>,
    /// The contact sheet's techniques: comma-separated ids, or `all`.
    #[arg(long, default_value = "all", conflicts_with = "technique")]
    pub techniques: String,
    /// Output size as WIDTHxHEIGHT (of each tile on a contact sheet).
    #[arg(long, default_value = "512x512", value_parser = parse_size)]
    pub size: UVec2,
    /// PNG file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Set a technique parameter: `KEY=VALUE` with `--technique`, `ID.KEY=VALUE` on a contact
    /// sheet (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_assignment)]
    pub set: Vec<(String, String)>,
    /// What to show: final, visibility[:LIGHT], normals, depth, albedo, or a technique resource
    /// (needs `--technique`).
    #[arg(long, default_value = "final")]
    pub view: String,
    /// Area-light samples per pixel for the contact sheet's reference (rounded up to a square).
    #[arg(long, default_value_t = zoo_host::judging::DEFAULT_SAMPLES,
          value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub samples: u32,
    /// Frames to render with `--technique`; the last is written (techniques that accumulate
    /// over frames, or read a frame's results back later, settle over them).
    #[arg(long, default_value_t = 1, requires = "technique",
          value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub frames: u32,
    /// Print per-pass GPU times.
    #[arg(long)]
    pub timings: bool,
    /// Read WGSL from DIR first (laid out as `shaders/`; files it lacks come from the
    /// copies built in), so edited shaders take effect without a rebuild.
    #[arg(long, value_name = "DIR")]
    pub shaders: Option<PathBuf>,
}

/// What moves during a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, clap::ValueEnum)]
pub enum PathMode {
    /// Nothing moves.
    Static,
    /// The camera follows the scene's camera path.
    #[default]
    Camera,
    /// The lights follow their paths.
    Light,
    /// Both.
    Both,
}

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(text: &str) -> Result<UVec2, String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{text}`"))?;
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|v| (1..=zoo_host::render::MAX_OUTPUT_SIDE).contains(v))
            .ok_or_else(|| {
                format!(
                    "`{s}` is not a size in 1..={}",
                    zoo_host::render::MAX_OUTPUT_SIDE
                )
            })
    };
    Ok(UVec2::new(side(w)?, side(h)?))
}

/// Parses `KEY=VALUE`.
pub fn parse_assignment(text: &str) -> Result<(String, String), String> {
    let (key, value) = text
        .split_once('=')
        .ok_or_else(|| format!("expected KEY=VALUE, got `{text}`"))?;
    if key.trim().is_empty() {
        return Err(format!("missing key in `{text}`"));
    }
    Ok((key.trim().to_string(), value.trim().to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_reject_bad_input() {
        assert_eq!(parse_size("256x128"), Ok(UVec2::new(256, 128)));
        assert!(parse_size("256").unwrap_err().contains("WIDTHxHEIGHT"));
        assert!(parse_size("0x5").unwrap_err().contains("`0` is not a size"));
        assert!(parse_size("99999x5").is_err());
    }

    #[test]
    fn assignments_parse() {
        assert_eq!(
            parse_assignment("map_size=2048"),
            Ok(("map_size".into(), "2048".into()))
        );
        assert!(parse_assignment("novalue").is_err());
        assert!(parse_assignment("=3").is_err());
    }
}
