//! The moment family against the reference judge, with vsm's bounds on planar-room (point,
//! spot and sun) and curved. Their light bleeding beside VSM is measured in the workspace's
//! `tests/zoo/filtered_shadow_maps.rs`, which links every plugin.

// Link the plugin so its techniques register.
use zoo_plugin_moments as _;

use zoo_host::glam::UVec2;
use zoo_host::test_support::judge;

const SIZE: UVec2 = UVec2::new(256, 256);
const METHODS: [&str; 4] = ["esm", "evsm2", "evsm4", "msm"];

#[test]
fn planar_room_within_bounds_with_2048_maps() {
    for method in METHODS {
        judge("planar-room.ron", method, &[("map_size", "2048")], SIZE)
            .assert_core_bounds(0.005, 0.01);
    }
}

#[test]
fn curved_within_bounds_with_2048_maps() {
    for method in METHODS {
        judge("curved.ron", method, &[("map_size", "2048")], SIZE).assert_core_bounds(0.005, 0.01);
    }
}
