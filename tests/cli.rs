//! The `shadow-zoo` command line: output and clear errors with a non-zero exit.

use std::process::{Command, Output};

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
    for r in zoo_host::registry() {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(r.id))
            .unwrap_or_else(|| panic!("{} missing", r.id));
        assert!(
            line.contains(r.description) && line.contains(&r.light_kind_names()),
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
            &["render", "--set", "bias=1", "--out", "x.png"],
            "unknown parameter `bias`",
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
            &["render", "--view", "visibility:7", "--out", "x.png"],
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
