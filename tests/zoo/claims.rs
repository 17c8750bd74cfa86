//! `shadow-zoo claims`: every claim resolves to a suite's ratio and its runs (or to a judged
//! scene), bad claims say which and why, and seed 000's claims reproduce through the command.

use std::process::Command;

use shadow_zoo::claims::{self, CLAIM_FRAMES, ClaimList};

fn list() -> (ClaimList, std::path::PathBuf) {
    let path = zoo_host::test_support::workspace_root().join("scenes/claims/claims.ron");
    let list = claims::load(&path).unwrap();
    (list, path.parent().unwrap().to_path_buf())
}

#[test]
fn every_claim_resolves_to_a_measurement_of_a_few_frames() {
    let (list, dir) = list();
    let plans = claims::check(&list, &dir).unwrap();
    assert_eq!(plans.ratios.len(), list.ratios.len());
    for seed in ["seed 000", "seed 001", "seed 002", "seed 003", "seed 004"] {
        let sources = list.ratios.iter().map(|c| &c.source);
        let judged = list.judged.iter().map(|c| &c.source);
        assert!(
            sources.chain(judged).any(|s| s.contains(seed)),
            "no claim of {seed}"
        );
    }
    for plan in &plans.plans {
        assert!(
            plan.frames <= CLAIM_FRAMES && plan.warmup <= 2,
            "{}",
            plan.run
        );
        assert!(!plan.flicker, "{}: flicker is not a claim", plan.run);
    }
    // Each claim's runs measure only their configurations: ssss's kernels of 5, 11 and 23 taps
    // with the blocker search (not the minimum filter), at 720p and 1080p, beside sm-pcf's
    // PCSS.
    let ssss = (plans.plans.iter())
        .find(|p| p.run == "ssss-vs-pcss: 16 lights")
        .expect("the ssss claims' run");
    let configurations = shadow_zoo::bench::expand(ssss).unwrap();
    let labels: Vec<String> = configurations.iter().map(|c| c.label()).collect();
    assert_eq!(
        labels.iter().filter(|l| l.starts_with("ssss")).count(),
        6,
        "{labels:?}"
    );
}

#[test]
fn bad_claims_say_which_and_why() {
    let (_, dir) = list();
    let error = |text: &str| {
        let list: ClaimList = ron::from_str(text).unwrap();
        match claims::check(&list, &dir) {
            Ok(_) => panic!("{text}: accepted"),
            Err(e) => format!("{e:#}"),
        }
    };
    let ratio = |name: &str, at: &str| {
        format!(
            r#"(ratios: [(claim: "c", source: "s", suite: "sv-vs-sm", ratio: "{name}",
                at: [{at}], skew: "")])"#
        )
    };
    let e = error(&ratio("no such ratio", ""));
    assert!(
        e.contains("claim `c` (s)") && e.contains("no ratio labelled `no such ratio`"),
        "{e}"
    );
    let e = error(&ratio(
        "sv-zfail frame / sm-pcf frame",
        r#"("sm-pcf.map_size", "512")"#,
    ));
    assert!(e.contains("`at` names sm-pcf.map_size"), "{e}");
    let e = error(&ratio(
        "sv-zfail frame / sm-pcf frame",
        r#"("size", "100x100")"#,
    ));
    assert!(
        e.contains("`at` size=100x100") && e.contains("256x256"),
        "{e}"
    );
    let judged = |metric: &str, scene: &str| {
        format!(
            r#"(ratios: [], judged: [(claim: "j", source: "s", figure: "f", scene: "{scene}",
                technique: "sv-zfail", metric: "{metric}")])"#
        )
    };
    let e = error(&judged("nope", "../planar-room.ron"));
    assert!(
        e.contains("no metric `nope`") && e.contains("false_lit_core"),
        "{e}"
    );
    let e = error(&judged("mae", "../missing.ron"));
    assert!(e.contains("missing.ron"), "{e}");
}

/// The command reproduces seed 000's judged claims: shadow volumes exact, one map over a
/// kilometre losing near shadows where splitting the view keeps them.
#[test]
fn seed_000_claims_reproduce() {
    let out = std::env::temp_dir().join(format!("zoo-claims-{}", std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_shadow-zoo"))
        .args(["claims", "--only", "seed 000, section", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{text}");
    let csv = std::fs::read_to_string(out.join("claims.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("claim,source,source_figure,measured,configuration,adapter,skew")
    );
    let measured = |claim: &str| -> f64 {
        let line = csv.lines().find(|l| l.starts_with(claim)).expect(claim);
        csv_fields(line)[3].parse().unwrap()
    };
    assert_eq!(measured("Shadow volumes are exact: no pixel lit"), 0.0);
    assert_eq!(measured("Shadow volumes are exact: no pixel shadowed"), 0.0);
    let one_map = measured("Shadow maps alias");
    let split = measured("Splitting the view");
    assert!(one_map > 0.02 && split < one_map / 4.0, "{one_map} {split}");
    let md = std::fs::read_to_string(out.join("claims.md")).unwrap();
    assert!(md.contains("| Shadow maps alias"), "{md}");
    assert_eq!(lines.count(), 4);
}

/// The fields of a CSV line, quoted fields unquoted.
fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            (c, _) => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

/// The whole report from a clean clone: every claim has a measured figure on this adapter.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn every_claim_is_measured() {
    let (list, _) = list();
    let out = std::env::temp_dir().join(format!("zoo-claims-all-{}", std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_shadow-zoo"))
        .args(["claims", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let csv = std::fs::read_to_string(out.join("claims.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv.lines().skip(1).map(csv_fields).collect();
    let claims = list.ratios.iter().map(|c| &c.claim);
    for claim in claims.chain(list.judged.iter().map(|c| &c.claim)) {
        let measured: Vec<&Vec<String>> = rows.iter().filter(|r| &r[0] == claim).collect();
        assert!(!measured.is_empty(), "{claim}: no row");
        for row in measured {
            assert!(
                row[3].parse::<f64>().is_ok(),
                "{claim}: not measured: {row:?}"
            );
        }
    }
    println!(
        "{}",
        std::fs::read_to_string(out.join("claims.md")).unwrap()
    );
}
