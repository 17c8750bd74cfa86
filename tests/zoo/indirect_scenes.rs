//! Indirect light on the enclosed rooms and open scenes of issue 48, ddgi beside lpv's best
//! setting, in one table (this binary links both plugins).

use glam::UVec2;
use zoo_host::test_support::IndirectRun;

/// Cosine rays a pixel of the one-bounce reference.
const RAYS: u32 = 256;

/// The lpv settings to beat on a scene: the published defaults and the indoor setting of its
/// README (occluders per face, thickened, lookups blocked), both with spot and point lights
/// bouncing (lpv's defaults bounce only the sun).
fn lpv_settings() -> [Vec<(&'static str, &'static str)>; 2] {
    let bounce_all = [("spot_lights", "true"), ("point_lights", "true")];
    let indoors = [
        ("occlusion", "Faces"),
        ("coverage_gain", "2"),
        ("lookup_blocking", "true"),
    ];
    [
        bounce_all.to_vec(),
        bounce_all.iter().chain(&indoors).copied().collect(),
    ]
}

/// The issue's table at 192 x 192 with 256 reference rays: every enclosed room (relative RMSE
/// at most 0.5, leak at most 0.05) and open scene (atrium 0.3, court 0.4, foliage 0.3) within
/// its bound, and below lpv's best setting on each. doorway-rooms' sunlit wall and the red
/// hanging on it take their bounce from a 0.4 m strip of sunlit floor at their foot, which
/// probes resolve only at a spacing near that: its two rooms (10.6 m long) get 48 probes along
/// their length (0.22 m) of 64 rays (measured at 128 x 128 with 128 reference rays: 0.91,
/// 0.51, 0.40 and 0.26 at 16, 32, 40 and 48 probes).
#[test]
#[ignore = "long check: nine scenes, three techniques' settings each"]
fn the_issue_s_scenes_beside_lpv_s_best_setting() {
    let rooms: [(&str, &[(&str, &str)]); 6] = [
        ("skylight-room.ron", &[]),
        ("window-room.ron", &[]),
        (
            "doorway-rooms.ron",
            &[("probes", "48"), ("rays_per_probe", "64")],
        ),
        ("gi/point-room.ron", &[]),
        ("gi/spot-room.ron", &[]),
        ("gi/thin-wall-rooms.ron", &[]),
    ];
    let open = [
        ("atrium.ron", 0.3),
        ("gi/court.ron", 0.4),
        ("foliage.ron", 0.3),
    ];
    let scenes = (rooms
        .iter()
        .map(|(scene, set)| (*scene, *set, 0.5, Some(0.05))))
    .chain(
        open.iter()
            .map(|(scene, bound)| (*scene, &[][..], *bound, None)),
    );
    let mut failures = Vec::new();
    eprintln!("scene                   ddgi rmse  leak     lpv best rmse  leak");
    for (scene, set, bound, leak_bound) in scenes {
        let mut run = IndirectRun::new(scene, UVec2::splat(192));
        let settings: Vec<(&str, &str)> = [("bounces", "One")].iter().chain(set).copied().collect();
        let ddgi = run.score("ddgi", &settings, RAYS);
        let lpv = (lpv_settings().iter())
            .map(|s| run.score("lpv", s, RAYS))
            .min_by(|a, b| a.rmse.total_cmp(&b.rmse))
            .unwrap();
        eprintln!(
            "{scene:22} {:9.3} {:7.4} {:14.3} {:7.4}",
            ddgi.rmse, ddgi.leak, lpv.rmse, lpv.leak
        );
        if ddgi.rmse > bound || leak_bound.is_some_and(|b| ddgi.leak > b) {
            failures.push(format!("{scene}: rmse {} leak {}", ddgi.rmse, ddgi.leak));
        }
        if ddgi.rmse >= lpv.rmse {
            failures.push(format!("{scene}: lpv {} <= ddgi {}", lpv.rmse, ddgi.rmse));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
