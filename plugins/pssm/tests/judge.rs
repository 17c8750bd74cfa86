//! Parallel-split shadow maps against the reference judge, with the bounds of the PSSM issue.

// Link the plugin so its technique registers.
use zoo_plugin_pssm as _;

use zoo_host::glam::UVec2;
use zoo_host::test_support::{assert_soft_near_walls, judge};

const SIZE: UVec2 = UVec2::new(256, 256);

const FOUR_BY_2048: [(&str, &str); 2] = [("splits", "4"), ("map_size", "2048")];

#[test]
fn vista_within_bounds_with_four_2048_splits() {
    judge("vista.ron", "pssm", &FOUR_BY_2048, SIZE).assert_core_bounds(0.005, 0.01);
}

#[test]
fn atrium_within_bounds_with_four_2048_splits() {
    judge("atrium.ron", "pssm", &FOUR_BY_2048, SIZE).assert_core_bounds(0.005, 0.01);
}

#[test]
fn more_splits_lower_the_core_error_on_vista() {
    let core_error = |splits: &str, lambda: &str| {
        let params = [("splits", splits), ("lambda", lambda), ("map_size", "2048")];
        let run = judge("vista.ron", "pssm", &params, SIZE);
        let m = run.metrics(0);
        eprintln!("vista, {splits} splits, lambda {lambda}: {m:?}");
        (run, m.false_shadow_core + m.false_lit_core)
    };
    let errors: Vec<f64> = ["1", "2", "4"].map(|m| core_error(m, "0.5").1).to_vec();
    assert!(
        errors[0] > errors[1] && errors[1] > errors[2],
        "core error not falling with the split count: {errors:?}"
    );
    // Eight logarithmic splits hold the bounds too.
    let (run, _) = core_error("8", "1");
    run.assert_core_bounds(0.005, 0.01);
}

#[test]
fn spot_and_point_lights_are_declared_unsupported() {
    let registration = zoo_host::find_technique("pssm").unwrap();
    assert!(registration.supports(zoo_host::LightKind::Directional));
    assert!(!registration.supports(zoo_host::LightKind::Spot));
    assert!(!registration.supports(zoo_host::LightKind::Point));
    // planar-room has all three kinds: the directional light is scored, the others are not.
    let run = judge("planar-room.ron", "pssm", &[], SIZE);
    let scored: Vec<bool> = run
        .judged
        .scores
        .iter()
        .map(|s| s.metrics.is_some())
        .collect();
    assert_eq!(scored, [false, false, true]);
    run.assert_core_bounds(0.005, 0.01);
}

#[test]
fn lispsm_within_bounds_on_vista_atrium_and_planar_room() {
    for scene in ["vista.ron", "atrium.ron", "planar-room.ron"] {
        judge(scene, "lispsm", &[("map_size", "2048")], SIZE).assert_core_bounds(0.005, 0.01);
    }
}

#[test]
fn psm_within_bounds_on_atrium_and_planar_room_spot_included() {
    for scene in ["atrium.ron", "planar-room.ron"] {
        let run = judge(scene, "psm", &[("map_size", "2048")], SIZE);
        run.assert_core_bounds(0.005, 0.01);
    }
    let registration = zoo_host::find_technique("psm").unwrap();
    assert!(registration.supports(zoo_host::LightKind::Spot));
    assert!(!registration.supports(zoo_host::LightKind::Point));
}

#[test]
fn warped_maps_beat_one_uniform_map_on_vista() {
    let core = |id: &str| {
        let run = judge("vista.ron", id, &[("map_size", "2048")], SIZE);
        let m = run.metrics(0);
        m.false_shadow_core + m.false_lit_core
    };
    let uniform = {
        // The uniform map of a warped technique: LiSPSM with its warp off.
        let run = judge(
            "vista.ron",
            "lispsm",
            &[("map_size", "2048"), ("strength", "0")],
            SIZE,
        );
        let m = run.metrics(0);
        m.false_shadow_core + m.false_lit_core
    };
    let (lispsm, psm) = (core("lispsm"), core("psm"));
    eprintln!("vista core error at 2048: lispsm {lispsm:.5}, psm {psm:.5}, uniform {uniform:.5}");
    assert!(
        lispsm < 0.5 * uniform && psm < uniform,
        "lispsm {lispsm}, psm {psm}, uniform {uniform}"
    );
}

#[test]
fn pcss_near_walls_matches_the_area_reference() {
    // pssm and lispsm shadow the scenes' suns (grazing the walls); psm their spots as well.
    let mut lights = 0;
    for technique in ["pssm", "lispsm", "psm"] {
        lights += assert_soft_near_walls(technique, &[("filter", "Pcss")], 0.03, &[]);
    }
    assert_eq!(lights, 2 + 2 + 6);
}
