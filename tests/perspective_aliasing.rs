//! Perspective aliasing on `vista` (a view from 0.1 to 800 m): parallel-split shadow maps
//! against one fitted map at the same texel budget, and temporal stability along the scene's
//! camera path.

use shadow_zoo::bench::{self, BenchPlan, PathMode, parse_sweep, run_configuration};
use zoo_host::glam::UVec2;
use zoo_host::test_support::{gpu, judge, scene_path};

const SIZE: UVec2 = UVec2::new(256, 256);

#[test]
fn splits_halve_the_core_error_of_one_map_at_the_same_texel_budget() {
    // Four 1024² splits against one 2048² map: the same number of texels.
    let pssm = judge(
        "vista.ron",
        "pssm",
        &[("splits", "4"), ("map_size", "1024")],
        SIZE,
    );
    let single = judge("vista.ron", "sm-pcf", &[("map_size", "2048")], SIZE);
    let core = |m: zoo_host::judge::Metrics| m.false_shadow_core + m.false_lit_core;
    let (split, one) = (core(pssm.metrics(0)), core(single.metrics(0)));
    eprintln!(
        "vista core error (false shadow + false lit): pssm 4x1024 {split:.5}, sm-pcf 2048 {one:.5}"
    );
    assert!(split <= 0.5 * one, "pssm {split} against one map {one}");
}

#[test]
fn stabilised_splits_flicker_less_along_the_vista_walk() {
    let scene = scene_path("vista.ron");
    let plan = BenchPlan {
        run: "vista-walk".into(),
        description: zoo_host::scene::read_description(&scene).unwrap(),
        scene_path: scene,
        techniques: ["pssm", "sm-pcf"]
            .iter()
            .map(|t| zoo_host::find_technique(t).unwrap())
            .collect(),
        size: UVec2::new(160, 120),
        frames: 96,
        warmup: 0,
        path: PathMode::Camera,
        sweeps: vec![parse_sweep("pssm.stabilise", &["true".into(), "false".into()]).unwrap()],
        set: vec![("pssm".into(), "map_size".into(), "1024".into())],
        flicker: true,
    };
    let gpu = gpu();
    let mut flicker = std::collections::HashMap::new();
    for config in bench::expand(&plan).unwrap() {
        let result = run_configuration(&gpu, &plan, &config, || {}).unwrap();
        eprintln!("{}: flicker {:?}", config.label(), result.flicker);
        flicker.insert(config.label(), result.flicker.unwrap());
    }
    let stable = flicker["pssm [pssm.stabilise=true]"];
    let unstable = flicker["pssm [pssm.stabilise=false]"];
    let single = flicker["sm-pcf"];
    assert!(
        stable < unstable,
        "stable {stable} against unstable {unstable}"
    );
    assert!(stable < single, "stable {stable} against one map {single}");
}
