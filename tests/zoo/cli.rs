//! The `shadow-zoo` command line: output and clear errors with a non-zero exit.

use std::process::{Command, Output};

use zoo_host::ShaderLibrary;

fn shadow_zoo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shadow-zoo"))
        .args(args)
        .current_dir(zoo_host::test_support::workspace_root())
        .output()
        .expect("run shadow-zoo")
}

fn text(output: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

#[test]
fn list_shows_every_technique_with_light_kinds() {
    let out = shadow_zoo(&["list"]);
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    for r in crate::shipped_techniques() {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(r.id))
            .unwrap_or_else(|| panic!("{} missing", r.id));
        assert!(
            line.contains(r.description) && line.contains(&r.light_kind_names()),
            "{line}"
        );
        let opaque = zoo_host::MaskedCasters::Opaque;
        assert_eq!(
            line.contains(opaque.describe()),
            r.masked_casters == opaque,
            "{line}"
        );
    }
}

#[test]
fn render_writes_a_png_and_prints_the_adapter_and_timings() {
    let dir = std::env::temp_dir().join(format!("zoo-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("frame.png");
    let out = shadow_zoo(&[
        "render",
        "--scene",
        "scenes/planar-room.ron",
        "--technique",
        "unshadowed",
        "--size",
        "96x64",
        "--out",
        png.to_str().unwrap(),
        "--timings",
    ]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert!(
        all.contains("adapter: ") && all.contains("backend, driver"),
        "{all}"
    );
    assert!(
        all.contains("pass timings (") && all.contains("G-buffer") && all.contains("Lighting"),
        "{all}"
    );
    let image = image::open(&png).unwrap();
    assert_eq!((image.width(), image.height()), (96, 64));
}

/// `--shaders DIR` reads edited WGSL without a rebuild: a lookup edited to shadow everything
/// darkens the frame; files DIR lacks come from the built-in copies; a missing DIR is an
/// error naming it.
#[test]
fn render_takes_edited_shaders_from_a_folder() {
    let dir = std::env::temp_dir().join(format!("zoo-cli-shaders-{}", std::process::id()));
    let lookup = dir.join("shaders/sm-pcf/lookup.wgsl");
    std::fs::create_dir_all(lookup.parent().unwrap()).unwrap();
    let original = ShaderLibrary::embedded()
        .source("sm-pcf/lookup.wgsl")
        .unwrap();
    let visibility = "out.visibility = vec4<f32>(visibility);";
    assert!(
        original.contains(visibility),
        "the lookup's visibility line moved"
    );
    let edited = original.replace(visibility, "out.visibility = vec4<f32>(0.0 * visibility);");
    std::fs::write(&lookup, edited).unwrap();
    let render = |png: &str, shaders: Option<&std::path::Path>| {
        let png = dir.join(png);
        let mut args = vec!["render", "--technique", "sm-pcf", "--size", "64x48"];
        args.extend(["--out", png.to_str().unwrap()]);
        if let Some(shaders) = shaders {
            args.extend(["--shaders", shaders.to_str().unwrap()]);
        }
        let out = shadow_zoo(&args);
        assert!(out.status.success(), "{}", text(&out));
        let image = image::open(&png).unwrap().to_luma8();
        let sum: u64 = image.pixels().map(|p| p.0[0] as u64).sum();
        (text(&out), sum)
    };
    let (_, built_in) = render("built-in.png", None);
    let (log, edited) = render("edited.png", Some(&dir.join("shaders")));
    assert!(log.contains("shaders: "), "{log}");
    assert!(
        (edited as f64) < 0.9 * built_in as f64,
        "the edited lookup was not used: brightness {edited} against {built_in}"
    );
    let missing = dir.join("no-such-folder");
    let out = shadow_zoo(&[
        "render",
        "--out",
        dir.join("x.png").to_str().unwrap(),
        "--shaders",
        missing.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(
        text(&out).contains("no-such-folder: no such folder"),
        "{}",
        text(&out)
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_input_exits_non_zero_with_a_message_and_no_panic() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["render", "--technique", "nope", "--out", "x.png"],
            "unknown technique `nope`",
        ),
        (
            &["render", "--scene", "missing.ron", "--out", "x.png"],
            "missing.ron: cannot read scene",
        ),
        (
            &[
                "render",
                "--technique",
                "unshadowed",
                "--set",
                "bias=1",
                "--out",
                "x.png",
            ],
            "unknown parameter `bias`",
        ),
        (
            &["render", "--set", "bias=1", "--out", "x.png"],
            "--set bias: expected ID.KEY=VALUE",
        ),
        (
            &["render", "--set", "sm-pcf.nope=1", "--out", "x.png"],
            "unknown parameter `nope`",
        ),
        (
            &["render", "--view", "normals", "--out", "x.png"],
            "views other than `final` need --technique",
        ),
        (
            &["render", "--size", "12", "--out", "x.png"],
            "expected WIDTHxHEIGHT",
        ),
        (
            &["render", "--out", "no/such/dir/x.png"],
            "folder no/such/dir does not exist",
        ),
        (
            &[
                "render",
                "--technique",
                "unshadowed",
                "--view",
                "visibility:7",
                "--out",
                "x.png",
            ],
            "the scene has 3 lights",
        ),
    ];
    for (args, expected) in cases {
        let out = shadow_zoo(args);
        let all = text(&out);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(
            all.contains(expected),
            "{args:?}: expected `{expected}` in:\n{all}"
        );
        assert!(!all.contains("panicked"), "{args:?} panicked:\n{all}");
    }
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("zoo-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `compare` of one technique on `scene` at 64x48 with 4 samples, into `out_dir`.
fn compare_small(scene: &str, technique: &str, out_dir: &std::path::Path) -> Output {
    shadow_zoo(&[
        "compare",
        "--scene",
        scene,
        "--techniques",
        technique,
        "--size",
        "64x48",
        "--samples",
        "4",
        "--out",
        out_dir.to_str().unwrap(),
    ])
}

#[test]
fn compare_writes_csv_report_and_error_maps() {
    let out_dir = temp_dir("compare").join("results");
    let out = compare_small("scenes/planar-room.ron", "unshadowed", &out_dir);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some(
            "scene,technique,view,light,light_kind,pixels,false_shadow,false_lit,false_shadow_core,false_lit_core,mae,p95_error,gpu_ms"
        )
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3, "{csv}");
    for (light, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), 13);
        assert_eq!(
            (row[0], row[1], row[2], row[3]),
            ("planar-room", "unshadowed", "0", light.to_string().as_str())
        );
        for value in &row[6..12] {
            let v: f64 = value.parse().unwrap();
            assert!((0.0..=1.0).contains(&v), "{value}");
        }
        assert_eq!(row[6], "0.000000", "unshadowed never shadows");
        assert!(
            out_dir
                .join(format!("unshadowed-light{light}-error.png"))
                .is_file()
        );
    }
    assert_eq!(rows[0][4], "point");
    assert_eq!(rows[2][4], "directional");
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(
        report.contains("Adapter: ") && report.contains("3890 triangles, 3 lights"),
        "{report}"
    );
    assert!(
        report.contains("| unshadowed | 0 | 0 | point |"),
        "{report}"
    );
}

/// `--sweep` judges each value of a parameter against one reference, as its own row.
#[test]
fn compare_sweeps_a_parameter_in_one_run() {
    let out_dir = temp_dir("compare-sweep").join("results");
    let out = shadow_zoo(&[
        "compare",
        "--scene",
        "scenes/contact.ron",
        "--techniques",
        "unshadowed,sm-pcf",
        "--sweep",
        "sm-pcf.map_size=256,1024",
        "--sweep",
        "sm-pcf.filter=None,Pcss",
        "--size",
        "64x48",
        "--samples",
        "4",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert!(all.contains("5 configurations"), "{all}");
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let labels: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    let mut distinct = labels.clone();
    distinct.dedup();
    assert_eq!(
        distinct,
        [
            "unshadowed",
            "sm-pcf@map_size=256@filter=None",
            "sm-pcf@map_size=256@filter=Pcss",
            "sm-pcf@map_size=1024@filter=None",
            "sm-pcf@map_size=1024@filter=Pcss",
        ],
        "{csv}"
    );
    let lights = labels.iter().filter(|l| **l == "unshadowed").count();
    assert_eq!(labels.len(), 5 * lights, "{csv}");
    assert!(
        out_dir
            .join("sm-pcf@map_size=1024@filter=Pcss-light0-error.png")
            .is_file()
    );
}

#[test]
fn compare_judges_views_along_the_paths_and_scores_final_images() {
    let out_dir = temp_dir("compare-views").join("results");
    let out = shadow_zoo(&[
        "compare",
        "--scene",
        "scenes/planar-room.ron",
        "--techniques",
        "unshadowed,sm-pcf",
        "--size",
        "64x48",
        "--samples",
        "4",
        "--views",
        "3",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert_view_rows(&out_dir);
    assert_final_images(&out_dir);
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(report.contains("## Over the views") && report.contains("| sm-pcf | worst |"));
    assert!(report.contains("## Final images"), "{report}");
}

/// results.csv of the three-view compare: a row per view, technique and light, then the
/// worst and the mean of the views.
fn assert_view_rows(out_dir: &std::path::Path) {
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // 3 views x 2 techniques x 3 lights, then a worst and a mean row per technique and light.
    assert_eq!(rows.len(), 3 * 2 * 3 + 2 * 2 * 3, "{csv}");
    let views: Vec<&str> = rows.iter().map(|r| r[2]).collect();
    for view in ["0", "1", "2", "worst", "mean"] {
        assert!(views.contains(&view), "no rows for view {view}");
    }
    // The worst row of a metric is the largest of its views, the mean their mean.
    let of = |view: &str, column: usize| -> Vec<f64> {
        rows.iter()
            .filter(|r| r[1] == "unshadowed" && r[3] == "0" && r[2] == view)
            .map(|r| r[column].parse().unwrap())
            .collect()
    };
    let per_view: Vec<f64> = ["0", "1", "2"].iter().flat_map(|v| of(v, 7)).collect();
    let worst = of("worst", 7)[0];
    let mean = of("mean", 7)[0];
    assert!((worst - per_view.iter().copied().fold(0.0, f64::max)).abs() < 2e-6);
    assert!((mean - per_view.iter().sum::<f64>() / 3.0).abs() < 2e-6);
    assert!(
        per_view.iter().any(|v| (v - per_view[0]).abs() > 1e-4),
        "the views differ along the path: {per_view:?}"
    );
}

/// images.csv of the three-view compare: one FLIP score per technique and view, then worst
/// and mean; maps per view.
fn assert_final_images(out_dir: &std::path::Path) {
    let images = std::fs::read_to_string(out_dir.join("images.csv")).unwrap();
    let mut lines = images.lines();
    assert_eq!(
        lines.next(),
        Some("scene,technique,view,flip_mean,flip_p95")
    );
    let image_rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(image_rows.len(), 2 * 3 + 2 * 2, "{images}");
    let flip = |technique: &str, view: &str| -> f64 {
        image_rows
            .iter()
            .find(|r| r[1] == technique && r[2] == view)
            .map(|r| r[3].parse().unwrap())
            .unwrap()
    };
    // Without shadows the image is further from the reference than with shadow maps.
    assert!(
        flip("unshadowed", "mean") > flip("sm-pcf", "mean"),
        "{images}"
    );
    assert!(flip("sm-pcf", "0") >= 0.0 && flip("unshadowed", "0") < 1.0);
    for view in 0..3 {
        assert!(
            out_dir
                .join(format!("sm-pcf-view{view}-flip.png"))
                .is_file()
        );
        assert!(
            out_dir
                .join(format!("sm-pcf-view{view}-light0-error.png"))
                .is_file()
        );
    }
}

#[test]
fn compare_cannot_spread_views_over_a_scene_without_paths() {
    let out_dir = temp_dir("compare-no-paths").join("results");
    let out = shadow_zoo(&[
        "compare",
        "--scene",
        "scenes/curved.ron",
        "--views",
        "4",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(
        text(&out).contains("has no camera or light path"),
        "{}",
        text(&out)
    );
}

#[test]
fn compare_writes_the_indirect_light_it_scores() {
    let out_dir = temp_dir("compare-indirect").join("results");
    let out = compare_small("scenes/atrium.ron", "lpv", &out_dir);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    let csv = std::fs::read_to_string(out_dir.join("indirect.csv")).unwrap();
    let header = "scene,technique,view,indirect_rmse,leak,unlit_share,unbounced_lights";
    assert_eq!(csv.lines().next(), Some(header), "{csv}");
    let row = csv.lines().nth(1).expect("a row for lpv");
    let fields: Vec<&str> = row.split(',').collect();
    assert_eq!(fields[..3], ["atrium", "lpv", "0"], "{csv}");
    let scored: f64 = fields[3].parse().unwrap();
    let (leak, unlit): (f64, f64) = (fields[4].parse().unwrap(), fields[5].parse().unwrap());
    assert!(
        leak >= 0.0 && leak.is_finite() && (0.0..=1.0).contains(&unlit),
        "{csv}"
    );
    // The written values give back the score (Radiance HDR keeps about 1 % per value).
    let read = |name: &str| {
        let image = image::open(out_dir.join(name)).unwrap().into_rgb32f();
        assert_eq!(image.dimensions(), (64, 48), "{name}");
        image.into_raw()
    };
    let (reference, estimate) = (read("reference-indirect.hdr"), read("lpv-indirect.hdr"));
    // Over every pixel: the score's mask drops the sky, where both are exactly 0.
    let (mut error, mut norm) = (0.0f64, 0.0f64);
    for (r, e) in reference.iter().zip(&estimate) {
        error += f64::from(e - r).powi(2);
        norm += f64::from(*r).powi(2);
    }
    let recomputed = (error / norm).sqrt();
    assert!(norm > 0.0 && scored > 0.0);
    assert!(
        (recomputed / scored - 1.0).abs() < 0.05,
        "{recomputed} against {scored}"
    );
}

#[test]
fn compare_reports_light_through_walls_as_leak() {
    // The east room of `doorway-rooms` sees the lit west room only through its doorway; with
    // no occlusion the volumes carry the sunlit roof's and the west room's light through the
    // 0.2 m walls onto it.
    let out_dir = temp_dir("compare-leak").join("results");
    let out = shadow_zoo(&[
        "compare",
        "--scene",
        "scenes/doorway-rooms.ron",
        "--techniques",
        "lpv",
        "--set",
        "lpv.occlusion=Off",
        "--size",
        "64x48",
        "--samples",
        "16",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let csv = std::fs::read_to_string(out_dir.join("indirect.csv")).unwrap();
    let fields: Vec<&str> = csv
        .lines()
        .nth(1)
        .expect("a row for lpv")
        .split(',')
        .collect();
    let (leak, unlit): (f64, f64) = (fields[4].parse().unwrap(), fields[5].parse().unwrap());
    // Measured at 160x120: unlit 0.80 of the pixels, leak 63 (the unlit pixels get far more
    // light than the reference's mean).
    assert!(unlit > 0.5, "{csv}");
    assert!(leak > 1.0, "{csv}");
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(
        report.contains("| technique | view | indirect_rmse | leak | unlit |"),
        "{report}"
    );
}

#[test]
fn compare_rejects_bad_input_clearly() {
    let dir = temp_dir("compare-bad");
    let no_lights = dir.join("dark.ron");
    std::fs::write(
        &no_lights,
        "(camera: (position: (0, 2, 5), target: (0, 0, 0)), lights: [], objects: [(mesh: Plane(size: 4))])",
    )
    .unwrap();
    let file = dir.join("a-file");
    std::fs::write(&file, "not a folder").unwrap();
    let unwritable = file.join("results");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "--scene",
                "scenes/contact.ron",
                "--techniques",
                "unshadowed,bogus",
            ],
            "unknown technique `bogus`",
        ),
        (
            vec!["--scene", no_lights.to_str().unwrap()],
            "lights: a scene needs at least one light",
        ),
        (
            vec!["--scene", "scenes/contact.ron", "--set", "bogus.size=3"],
            "technique `bogus` is not being compared",
        ),
        (
            vec![
                "--scene",
                "scenes/contact.ron",
                "--set",
                "unshadowed.size=3",
            ],
            "unknown parameter `size`",
        ),
        (
            vec![
                "--scene",
                "scenes/contact.ron",
                "--sweep",
                "size=64x48,32x32",
            ],
            "compare sweeps technique parameters",
        ),
        (
            vec![
                "--scene",
                "scenes/contact.ron",
                "--techniques",
                "unshadowed",
                "--sweep",
                "sm-pcf.map_size=256,512",
            ],
            "technique `sm-pcf` is not being compared",
        ),
        (
            vec![
                "--scene",
                "scenes/contact.ron",
                "--sweep",
                "sm-pcf.map_size=256,7",
            ],
            "--sweep sm-pcf.map_size",
        ),
    ];
    for (args, expected) in cases {
        let mut full = vec!["compare", "--out", dir.to_str().unwrap()];
        full.extend(args.iter().copied());
        let out = shadow_zoo(&full);
        let all = text(&out);
        assert!(!out.status.success(), "{full:?} succeeded");
        assert!(
            all.contains(expected),
            "{full:?}: expected `{expected}` in:\n{all}"
        );
    }
    let out = shadow_zoo(&[
        "compare",
        "--scene",
        "scenes/contact.ron",
        "--out",
        unwritable.to_str().unwrap(),
    ]);
    let all = text(&out);
    assert!(!out.status.success());
    assert!(all.contains("cannot create output folder"), "{all}");
}

#[test]
fn render_without_a_technique_writes_the_contact_sheet_and_its_table() {
    let dir = std::env::temp_dir().join(format!("zoo-cli-sheet-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("sheet.png");
    // One sun, so each technique renders one map, and two techniques (the default scene's
    // sheet of every technique, rendered and judged in-process, is `contact_sheet`'s).
    let techniques = ["sm-pcf", "rt-shadows"];
    let out = shadow_zoo(&[
        "render",
        "--scene",
        "scenes/skylight-room.ron",
        "--techniques",
        &techniques.join(","),
        "--size",
        "96x64",
        "--out",
        png.to_str().unwrap(),
    ]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert!(
        all.contains("false shadow core") && all.contains("mae"),
        "{all}"
    );
    let table_rows: Vec<&str> = all
        .lines()
        .filter(|l| {
            l.starts_with("reference (")
                || crate::shipped_techniques()
                    .iter()
                    .any(|r| l.starts_with(&format!("{} ", r.id)))
        })
        .collect();
    assert_eq!(table_rows.len(), techniques.len() + 2, "{all}");
    for id in techniques {
        assert!(table_rows.iter().any(|l| l.starts_with(id)), "{id}: {all}");
    }
    let layout = shadow_zoo::contact_sheet::Layout::new((96, 64), techniques.len() + 2);
    let image = image::open(&png).unwrap();
    assert_eq!((image.width(), image.height()), layout.size());
    // An unknown id is named, and nothing written; a sheet of one technique cannot take
    // `--set` for another.
    let none = dir.join("none.png");
    for (list, set, expected) in [
        ("sm-pcf,nope", "sm-pcf.map_size=512", "nope"),
        ("sm-pcf", "vsm.map_size=512", "vsm"),
    ] {
        let out = shadow_zoo(&[
            "render",
            "--techniques",
            list,
            "--set",
            set,
            "--out",
            none.to_str().unwrap(),
        ]);
        let all = text(&out);
        assert!(!out.status.success() && all.contains(expected), "{all}");
        assert!(!all.contains("panicked") && !none.exists(), "{all}");
    }
}

/// Without a usable adapter the first command prints one clear message with the fix for the
/// platform and exits non-zero; no validation errors, no panic.
#[test]
fn no_usable_adapter_gives_one_clear_message() {
    let run = |env: &[(&str, &str)]| {
        let mut command = Command::new(env!("CARGO_BIN_EXE_shadow-zoo"));
        command
            .args(["render", "--size", "32x32", "--out"])
            .arg(std::env::temp_dir().join("zoo-no-adapter.png"))
            .current_dir(zoo_host::test_support::workspace_root());
        for (key, value) in env {
            command.env(key, value);
        }
        command.output().unwrap()
    };
    // A backend this platform does not have: no adapter at all.
    #[cfg(target_os = "linux")]
    {
        let out = run(&[("WGPU_BACKEND", "metal")]);
        let all = text(&out);
        assert!(!out.status.success(), "{all}");
        assert!(all.contains("error: no graphics adapter found"), "{all}");
        assert!(
            all.contains("Shadow Zoo needs a Vulkan, Metal, DX12 or OpenGL adapter")
                && all.contains("sudo apt-get install -y mesa-vulkan-drivers"),
            "{all}"
        );
        assert!(
            !all.to_lowercase().contains("validation") && !all.contains("panicked"),
            "{all}"
        );
        assert!(all.lines().count() < 6, "{all}");
    }
    // An adapter name that matches nothing: the adapters found are listed.
    let out = run(&[("WGPU_ADAPTER_NAME", "no-such-adapter")]);
    let all = text(&out);
    assert!(!out.status.success(), "{all}");
    assert!(
        all.contains("WGPU_ADAPTER_NAME=no-such-adapter matches no adapter; available: "),
        "{all}"
    );
    assert!(!all.to_lowercase().contains("validation"), "{all}");
}
