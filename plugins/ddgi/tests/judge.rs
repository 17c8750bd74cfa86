//! ddgi against the judge's one-bounce reference: closed rooms lit by a point light and by a
//! spot light (the light kinds lpv does not bounce by default), further bounces, and how fast
//! the light follows a moving lamp. (The rooms and open scenes beside lpv:
//! `tests/zoo/indirect_scenes.rs`, which links both.)

use zoo_host::glam::{UVec2, Vec3};
use zoo_host::test_support::{IndirectRun, gpu, judge, scene_path, technique_params};
use zoo_host::{Renderer, Scene, View};

const SIZE: UVec2 = UVec2::new(128, 96);
/// Cosine rays a pixel of the one-bounce reference.
const RAYS: u32 = 256;

const ONE_BOUNCE: [(&str, &str); 1] = [("bounces", "One")];

/// A coarse, quickly converging grid for the tests that run with every test run: 8 probes
/// along the longest side, 64 rays each, hysteresis 0.9 (15 frames to converge, not 21).
const QUICK: [(&str, &str); 3] = [
    ("probes", "8"),
    ("rays_per_probe", "64"),
    ("hysteresis", "0.9"),
];

/// The point and spot bounds in closed rooms, on the coarse quick grid: relative
/// RMSE at most 0.5 and leak at most 0.05. Measured at 128 x 96: point-room 0.12, spot-room
/// 0.18; leak 0 (every surface sees a lit one); the light's amount 1.07 and 1.04 of the
/// reference's. The default grid's scores are in the long check below.
#[test]
fn point_and_spot_lights_bounce_in_closed_rooms() {
    for scene in ["gi/point-room.ron", "gi/spot-room.ron"] {
        let mut run = IndirectRun::new(scene, SIZE);
        let kind = run.scene.lights[0].kind;
        let settings: Vec<_> = ONE_BOUNCE.iter().chain(&QUICK).copied().collect();
        let got = run.score("ddgi", &settings, RAYS);
        eprintln!(
            "{scene} ({}): relative RMSE {:.3}, leak {:.4}, amount {:.3}",
            kind.name(),
            got.rmse,
            got.leak,
            got.amount
        );
        assert!(got.rmse <= 0.5, "{scene}: {}", got.rmse);
        assert!(got.leak <= 0.05, "{scene}: {}", got.leak);
        assert!((0.8..1.2).contains(&got.amount), "{scene}: {}", got.amount);
    }
}

/// Direct shadows are the judge's hard visibility (the ray-tracing library's ray to each
/// light's centre, as rt-shadows traces it): core error at most 0.0005 of the pixels each
/// light reaches, alpha masks and coloured glass included (the glass's colour through the
/// transmittance slots: a light through it arrives tinted, not white).
#[test]
fn direct_shadows_are_the_judge_s_hard_visibility() {
    let coarse: Vec<_> = QUICK.iter().chain(&[("probes", "4")]).copied().collect();
    for scene in ["planar-room.ron", "foliage.ron", "translucent.ron"] {
        let run = judge(scene, "ddgi", &coarse, UVec2::new(64, 48));
        for score in &run.judged.scores {
            let m = score.metrics.expect("every light kind is supported");
            let core = m.false_shadow_core + m.false_lit_core;
            assert!(core <= 0.0005, "{scene} light {}: {m:?}", score.light);
        }
        let tinted =
            (run.judged.transmittance.iter().flatten().flatten()).any(|t| (t.x - t.z).abs() > 0.05);
        assert_eq!(tinted, scene == "translucent.ron", "{scene}");
    }
}

/// With `bounces = Multi` the probes gather their own indirect light at each hit, one more
/// bounce each frame: in the closed point-lit room (albedo about 0.8) the light grows well
/// past one bounce's (a geometric series toward 1 / (1 - 0.8)), and one bounce is the
/// reference's amount.
#[test]
fn more_bounces_add_light() {
    let mut run = IndirectRun::new("gi/point-room.ron", UVec2::new(64, 48));
    let mut with = |bounces| {
        let settings: Vec<_> = QUICK
            .iter()
            .chain(&[("bounces", bounces)])
            .copied()
            .collect();
        run.score("ddgi", &settings, RAYS).amount
    };
    let one = with("One");
    let multi = with("Multi");
    eprintln!("point-room: amount {one:.3} with one bounce, {multi:.3} with more");
    assert!((0.8..1.2).contains(&one), "{one}");
    assert!(
        multi > 1.5 * one && multi < 6.0 * one,
        "{multi} against {one}"
    );
}

/// After the lamp of the point-lit room moves, the indirect light follows: the frames until
/// its mean difference from the light converged for the new place is within 10 % of that
/// light, at the default hysteresis 0.97 and at 0.9 (a frame counting 0.03 or 0.1 closes the
/// gap by that share: about 76 and 22 frames from a full gap).
#[test]
#[ignore = "long check: about 200 frames"]
fn the_light_follows_a_moving_lamp() {
    let scene = Scene::load(&scene_path("gi/point-room.ron")).unwrap();
    let size = UVec2::new(64, 48);
    let mut moved = scene.lights.clone();
    moved[0].position = Vec3::new(-1.6, 1.2, 1.2);
    let frames_for = |hysteresis: &str| {
        let values = technique_params("ddgi", &[("bounces", "One"), ("hysteresis", hysteresis)]);
        // Frames until a frame counts for 1 - hysteresis: the steady state a lamp moves in.
        let steady = 1.0 / (1.0 - hysteresis.parse::<f32>().unwrap());
        let settle = zoo_plugin_ddgi::RELOCATION_FRAMES + steady.ceil() as u32 + 1;
        let mut renderer = Renderer::new(gpu(), scene.clone(), size).unwrap();
        renderer.set_lights(moved.clone());
        renderer.set_technique("ddgi", &values).unwrap();
        for _ in 0..settle {
            renderer.render(&View::Final).unwrap();
        }
        let target = renderer.read_indirect();
        let mut renderer = Renderer::new(gpu(), scene.clone(), size).unwrap();
        renderer.set_technique("ddgi", &values).unwrap();
        for _ in 0..settle {
            renderer.render(&View::Final).unwrap();
        }
        renderer.set_lights(moved.clone());
        let norm: f32 = target.iter().map(|c| c.element_sum()).sum();
        (1..=200)
            .find(|_| {
                renderer.render(&View::Final).unwrap();
                let now = renderer.read_indirect();
                let gap: f32 = (now.iter().zip(&target))
                    .map(|(a, b)| (*a - *b).abs().element_sum())
                    .sum();
                gap <= 0.1 * norm
            })
            .expect("within 10 % in 200 frames")
    };
    let (slow, fast) = (frames_for("0.97"), frames_for("0.9"));
    eprintln!("frames to within 10 %: {slow} at hysteresis 0.97, {fast} at 0.9");
    assert!(slow <= 80 && fast <= 25, "{slow}, {fast}");
    assert!(slow > 2 * fast, "{slow}, {fast}");
}
