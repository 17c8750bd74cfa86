//! Crowds of instanced real meshes: more volume geometry than one buffer holds, drawn in
//! pieces whose stencil counts add up.

// Link the plugin so its technique registers.
use zoo_plugin_sv_zfail as _;

use zoo_host::LightKind;
use zoo_host::glam::UVec2;
use zoo_host::test_support::{CrowdRun, assert_crowds_in_pieces_match_one_piece, crowd_scene};

const TECHNIQUE: &str = "sv-zfail";

/// Crowds whose volumes fit one buffer, drawn again in pieces of a small budget: exact, and
/// the same to the bit as in one piece (see the helper).
#[test]
fn crowds_in_pieces_are_exact_and_match_one_piece() {
    assert_crowds_in_pieces_match_one_piece(TECHNIQUE);
}

/// Crowds of 150 to 300 fandisks (13 thousand triangles each, 4 million at 300) whose volumes
/// may need more vertices than the device binds in one buffer.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn crowds_of_fandisks_are_exact() {
    let spot = [LightKind::Spot];
    let others = [LightKind::Directional, LightKind::Point];
    for (count, lights) in [(150, &spot[..]), (200, &spot), (300, &spot), (300, &others)] {
        let Some(scene) = crowd_scene("fandisk", count, lights) else {
            return;
        };
        let name = scene.name.clone();
        eprintln!("{name}: {}", scene.triangle_summary());
        let mut crowd = CrowdRun::new(TECHNIQUE, scene, UVec2::new(256, 256));
        let (judged, pieces) = crowd.judge(&[]);
        eprintln!("{name}: pieces {pieces:?}");
        crowd.assert_exact(&name, &judged, 0.015);
    }
}
