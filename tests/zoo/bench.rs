//! The benchmark harness: well-formed outputs, the flicker index, and every suite resolves.

use std::path::{Path, PathBuf};

use shadow_zoo::bench::{self, BenchPlan, PathMode, parse_sweep, run_configuration};
use zoo_host::ShaderLibrary;
use zoo_host::glam::UVec2;
use zoo_host::test_support::{gpu, scene_path, workspace_root};

fn plan(techniques: &[&str], path: PathMode, frames: u32, set: &[(&str, &str, &str)]) -> BenchPlan {
    let scene = scene_path("planar-room.ron");
    BenchPlan {
        run: "planar-room".into(),
        description: zoo_host::scene::read_description(&scene).unwrap(),
        scene_path: scene,
        techniques: techniques
            .iter()
            .map(|t| zoo_host::find_technique(t).unwrap())
            .collect(),
        size: UVec2::new(96, 96),
        frames,
        warmup: 1,
        path,
        sweeps: Vec::new(),
        set: set
            .iter()
            .map(|(a, b, c)| (a.to_string(), b.to_string(), c.to_string()))
            .collect(),
        flicker: true,
        cpu_timing: false,
        reuse_unchanged: false,
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("zoo-bench-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_tiny_run_writes_well_formed_csv_markdown_and_plots() {
    let mut p = plan(&["unshadowed", "planar"], PathMode::Camera, 3, &[]);
    p.sweeps = vec![parse_sweep("size", &["64x64".into(), "96x96".into()]).unwrap()];
    let out = temp_dir("tiny");
    let results = bench::run_plans(&[p], &ShaderLibrary::embedded(), &out, None, Vec::new())
        .unwrap()
        .results;
    assert_eq!(results.len(), 4, "2 techniques x 2 sizes");
    assert_tiny_csv(&out);
    assert_tiny_summary_report_and_plots(&out);
}

/// bench.csv of the tiny run: the header, ordered statistics, three frames, the lighting
/// pass's invocations and samples passed, and a row per pass and total.
fn assert_tiny_csv(out: &std::path::Path) {
    let csv = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        [
            "run",
            "configuration",
            "technique",
            "size",
            "tessellation",
            "pass",
            "owner",
            "median_ms",
            "mean_ms",
            "p95_ms",
            "p99_ms",
            "min_ms",
            "max_ms",
            "frames",
            "vertex_invocations",
            "fragment_invocations",
            "compute_invocations",
            "samples_passed"
        ]
    );
    let mut rows = 0;
    for line in lines {
        // Quoted fields hold no commas here; every row has the header's width.
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), header.len(), "{line}");
        let numbers: Vec<f64> = fields[7..13].iter().map(|v| v.parse().unwrap()).collect();
        let [median, mean, p95, p99, min, max] = numbers[..] else {
            unreachable!()
        };
        assert!(
            min <= median && median <= max && p95 <= p99 && p99 <= max,
            "{line}"
        );
        assert!(min <= mean && mean <= max, "{line}");
        assert_eq!(fields[13], "3");
        // The lighting pass shades every pixel once; invocations count whole 2x2 quads, so
        // helper lanes along the triangle's edge add a few percent.
        if fields[5] == "\"Lighting\"" && !fields[15].is_empty() {
            let fragments: u64 = fields[15].parse().unwrap();
            let pixels: u64 = if fields[3] == "96x96" {
                96 * 96
            } else {
                64 * 64
            };
            assert!(
                fragments >= pixels && fragments <= pixels * 11 / 10,
                "{line}"
            );
            assert_eq!(fields[14], "3", "a full-screen triangle: {line}");
            // Every pixel's one sample passes (no depth or stencil test): exactly the pixels.
            assert_eq!(fields[17], pixels.to_string(), "samples passed: {line}");
        }
        rows += 1;
    }
    // Planar has one pass per light (3) beyond the host's three; plus three totals each.
    assert_eq!(rows, 2 * (3 + 3) + 2 * (6 + 3), "{csv}");
}

/// summary.csv (the baseline's ratio 1), bench.md and the plots of the tiny run.
fn assert_tiny_summary_report_and_plots(out: &std::path::Path) {
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 5);
    for line in summary.lines().skip(1).filter(|l| l.contains("unshadowed")) {
        assert!(
            line.contains(",1.0000,"),
            "the baseline's ratio is 1: {line}"
        );
    }
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    for needle in [
        "Adapter: ",
        "OS: ",
        "Date: ",
        "| run | configuration |",
        "planar [size=96x96]",
        "Run `planar-room`: scene",
    ] {
        assert!(md.contains(needle), "bench.md lacks `{needle}`:\n{md}");
    }
    for plot in ["passes.png", "sweep-planar-room-size.png"] {
        let image = image::open(out.join(plot)).unwrap_or_else(|e| panic!("{plot}: {e}"));
        assert!(image.width() >= 800, "{plot}");
    }
}

#[test]
fn flicker_is_zero_for_a_static_camera_and_positive_for_an_unstable_configuration() {
    let gpu = gpu();
    // A coarse, unfiltered map with a moving camera: edges shimmer.
    let unstable = plan(
        &["sm-pcf"],
        PathMode::Camera,
        6,
        &[("sm-pcf", "map_size", "256"), ("sm-pcf", "filter", "None")],
    );
    let config = bench::expand(&unstable).unwrap().remove(0);
    let moving =
        run_configuration(&gpu, &ShaderLibrary::embedded(), &unstable, &config, || {}).unwrap();
    let static_plan = BenchPlan {
        path: PathMode::Static,
        ..plan(
            &["sm-pcf"],
            PathMode::Static,
            4,
            &[("sm-pcf", "map_size", "256"), ("sm-pcf", "filter", "None")],
        )
    };
    let config = bench::expand(&static_plan).unwrap().remove(0);
    let still = run_configuration(
        &gpu,
        &ShaderLibrary::embedded(),
        &static_plan,
        &config,
        || {},
    )
    .unwrap();
    eprintln!(
        "flicker: moving {:?}, static {:?}",
        moving.flicker, still.flicker
    );
    assert_eq!(still.flicker, Some(0.0));
    assert!(moving.flicker.unwrap() > 0.0, "{:?}", moving.flicker);
}

#[test]
fn bad_sweeps_are_rejected() {
    let err = parse_sweep("sm-pcf.map_size", &["99999".into()]).unwrap_err();
    assert!(format!("{err:#}").contains("out of range"), "{err:#}");
    assert!(parse_sweep("bogus", &["1".into()]).is_err());
    assert!(parse_sweep("size", &["12".into()]).is_err());
    assert!(parse_sweep("scene.tessellation", &["0".into()]).is_err());
    assert!(parse_sweep("no-such.key", &["1".into()]).is_err());
}

#[test]
fn every_suite_resolves() {
    let dir = workspace_root().join("scenes/bench");
    let mut suites = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let Ok(suite) = bench::suite::load(&path) else {
            // Scene files live beside the suites.
            assert!(
                zoo_host::scene::read_description(&path).is_ok(),
                "{} is neither a suite nor a scene",
                path.display()
            );
            continue;
        };
        suites += 1;
        assert_eq!(suite.name, path.file_stem().unwrap().to_string_lossy());
        assert!(
            !suite.seed_figures.is_empty(),
            "{}: no seed figures",
            suite.name
        );
        for run in &suite.runs {
            let dir = path.parent().unwrap_or(Path::new("."));
            if let Some(reason) = run.missing(dir) {
                eprintln!("SKIPPED: {} run {}: {reason}", suite.name, run.name);
                continue;
            }
            let scene = dir.join(&run.scene);
            zoo_host::Scene::load(&scene).unwrap_or_else(|e| panic!("{}: {e}", suite.name));
            for t in &run.techniques {
                zoo_host::find_technique(t).unwrap();
            }
            for (key, values) in &run.sweeps {
                parse_sweep(key, values).unwrap_or_else(|e| panic!("{}: {e:#}", suite.name));
            }
        }
        for ratio in &suite.ratios {
            for m in [&ratio.numerator, &ratio.denominator] {
                assert!(
                    suite.runs.iter().any(|r| r.name == m.run),
                    "{}: no run {}",
                    suite.name,
                    m.run
                );
            }
        }
    }
    assert!(suites >= 4, "only {suites} suites");
}
