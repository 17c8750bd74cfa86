//! The reference judge on rendered frames, and the plugin-test helper built on it.

use glam::UVec2;
use zoo_host::LightKind;
use zoo_host::test_support::{Inert, Metric, judge};

// A test-only technique that supports point lights only (and shadows nothing).
zoo_host::register_technique! {
    id: "test-point-only",
    name: "Test: point lights only",
    description: "Supports point lights only (test only)",
    source: "test",
    light_kinds: &[LightKind::Point],
    create: |_, _| Ok(Box::new(Inert)),
}

/// A test-only technique that shadows nothing and says it cannot meet something.
struct Warns;

impl zoo_host::ShadowTechnique for Warns {
    fn prepare(
        &mut self,
        _: &zoo_host::RenderContext<'_>,
        _: zoo_host::Changes,
    ) -> zoo_host::TechniqueResult {
        Ok(())
    }
    fn record(
        &mut self,
        _: &zoo_host::RenderContext<'_>,
        _: &mut zoo_host::PassRecorder<'_>,
    ) -> zoo_host::TechniqueResult {
        Ok(())
    }
    fn warnings(&self) -> Vec<String> {
        vec!["test-warns: half the shadows are dropped".to_string()]
    }
}

zoo_host::register_technique! {
    id: "test-warns",
    name: "Test: warns",
    description: "Shadows nothing and says so (test only)",
    source: "test",
    light_kinds: &[LightKind::Point, LightKind::Spot, LightKind::Directional],
    create: |_, _| Ok(Box::new(Warns)),
}

#[test]
fn warnings_reach_the_judged_results_and_the_compare_report() {
    let run = judge("planar-room.ron", "test-warns", &[], UVec2::new(64, 64));
    let warning = "test-warns: half the shadows are dropped";
    assert_eq!(run.judged.warnings, [warning]);
    let view = shadow_zoo::compare::JudgedView {
        view: 0,
        time: None,
        reference: run.reference,
        judged: vec![run.judged],
        flip: vec![None],
        indirect: Vec::new(),
    };
    let summary = shadow_zoo::compare::summary_table(&view);
    assert!(
        summary.contains(&format!("warning: {warning}")),
        "{summary}"
    );
    let views = [view];
    let report = shadow_zoo::compare::warnings_md(&views).unwrap();
    assert!(
        report.contains(&format!("`test-warns`: {warning}")),
        "{report}"
    );
    // Techniques that meet everything add no line.
    let quiet = judge("planar-room.ron", "unshadowed", &[], UVec2::new(64, 64));
    assert!(quiet.judged.warnings.is_empty());
}

#[test]
fn unsupported_light_kinds_are_reported_not_scored() {
    let run = judge(
        "planar-room.ron",
        "test-point-only",
        &[],
        UVec2::new(96, 96),
    );
    let kinds: Vec<(LightKind, bool)> = run
        .judged
        .scores
        .iter()
        .map(|s| (s.kind, s.metrics.is_some()))
        .collect();
    assert_eq!(
        kinds,
        vec![
            (LightKind::Point, true),
            (LightKind::Spot, false),
            (LightKind::Directional, false)
        ]
    );
    let view = shadow_zoo::compare::JudgedView {
        view: 0,
        time: None,
        reference: run.reference,
        judged: vec![run.judged],
        flip: vec![None],
        indirect: Vec::new(),
    };
    let csv = shadow_zoo::compare::results_csv("planar-room", std::slice::from_ref(&view));
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert!(
        rows[0].starts_with("planar-room,test-point-only,0,0,point,") && !rows[0].contains(",,")
    );
    assert!(
        rows[1].starts_with("planar-room,test-point-only,0,1,spot,,,,,,,,"),
        "{}",
        rows[1]
    );
}

#[test]
fn unshadowed_misses_exactly_the_reference_shadows() {
    let run = judge("planar-room.ron", "unshadowed", &[], UVec2::new(192, 160));
    for (light, reference) in run.reference.lights.iter().enumerate() {
        let m = run.metrics(light);
        assert!(
            m.pixels > 1000,
            "light {light} reaches only {} pixels",
            m.pixels
        );
        assert_eq!(m.false_shadow, 0.0, "light {light}");
        assert_eq!(m.false_lit, reference.shadowed_fraction(), "light {light}");
        assert!(
            m.false_lit > 0.02,
            "light {light}: planar-room has shadows ({})",
            m.false_lit
        );
        // The soft error of v = 1 is the mean occluded fraction of the area light.
        assert!(
            m.mae >= m.false_lit * 0.5,
            "light {light}: mae {} false_lit {}",
            m.mae,
            m.false_lit
        );
    }
}

#[test]
fn failed_bounds_name_metric_value_bound_and_error_map() {
    let run = judge("contact.ron", "unshadowed", &[], UVec2::new(128, 96));
    let metrics = run.metrics(0);
    run.assert_bounds(0, &metrics, &[(Metric::FalseShadow, 0.0)]);
    let failure = std::panic::catch_unwind(|| {
        run.assert_bounds(
            0,
            &metrics,
            &[(Metric::FalseLit, 0.0), (Metric::FalseShadow, 0.0)],
        )
    })
    .expect_err("unshadowed leaves shadows out");
    let message = failure
        .downcast_ref::<String>()
        .cloned()
        .unwrap_or_default();
    let expected = format!("false_lit = {:.5} exceeds 0", metrics.false_lit);
    assert!(message.contains(&expected), "{message}");
    assert!(!message.contains("false_shadow ="), "{message}");
    let path = message.rsplit("error map: ").next().unwrap();
    let map = image::open(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    assert_eq!((map.width(), map.height()), (128, 96));
}
