//! The moment family against the reference judge, with vsm's bounds on planar-room (point,
//! spot and sun) and curved. Their light bleeding beside VSM is measured in the workspace's
//! `tests/zoo/filtered_shadow_maps.rs`, which links every plugin.

// Link the plugin so its techniques register.
use zoo_plugin_moments as _;

use zoo_host::glam::UVec2;
use zoo_host::test_support::{JudgeRun, Metric, judge};

const SIZE: UVec2 = UVec2::new(256, 256);
const METHODS: [&str; 4] = ["esm", "evsm2", "evsm4", "msm"];

fn assert_core_bounds(run: &JudgeRun) {
    for light in 0..run.loaded.lights.len() {
        let m = run.metrics(light);
        let kind = run.loaded.lights[light].kind.name();
        eprintln!(
            "{} {} light {light} ({kind}): {m:?}",
            run.judged.technique, run.scene
        );
        run.assert_bounds(
            light,
            &m,
            &[
                (Metric::FalseShadowCore, 0.005),
                (Metric::FalseLitCore, 0.01),
            ],
        );
    }
}

#[test]
fn planar_room_within_bounds_with_2048_maps() {
    for method in METHODS {
        assert_core_bounds(&judge(
            "planar-room.ron",
            method,
            &[("map_size", "2048")],
            SIZE,
        ));
    }
}

#[test]
fn curved_within_bounds_with_2048_maps() {
    for method in METHODS {
        assert_core_bounds(&judge("curved.ron", method, &[("map_size", "2048")], SIZE));
    }
}
