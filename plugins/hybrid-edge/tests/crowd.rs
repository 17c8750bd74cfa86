//! Crowds of instanced real meshes: more volume geometry than one buffer holds, drawn in
//! pieces whose stencil counts add up.

// Link the plugin so its technique registers.
use zoo_plugin_hybrid_edge as _;

use zoo_host::LightKind;
use zoo_host::glam::UVec2;
use zoo_host::test_support::{CrowdRun, assert_crowds_in_pieces_match_one_piece, crowd_scene};

const TECHNIQUE: &str = "hybrid-edge";

/// Crowds whose volumes fit one buffer, drawn again in pieces of a small budget: exact, and
/// the same to the bit as in one piece (see the helper).
///
/// A long check here: sv-zfail's suite runs the same crowds through the same generator, and
/// the tiled test below keeps hybrid-edge's own drawing of pieces in the suite.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
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

/// The tile restriction draws each piece into the listed edge tiles with that piece's vertex
/// count: the same shadows as in one piece.
#[test]
fn tiled_crowds_in_pieces_match_one_piece() {
    let Some(scene) = crowd_scene("teapot", 16, &[LightKind::Spot, LightKind::Point]) else {
        return;
    };
    let name = scene.name.clone();
    let mut crowd = CrowdRun::new(TECHNIQUE, scene, UVec2::new(160, 160));
    let tiles = ("restriction", "Tiles");
    let (whole, _) = crowd.judge(&[tiles]);
    let (pieced, pieces) = crowd.judge(&[tiles, ("volume_buffer_mib", "1")]);
    eprintln!("{name}: {pieces:?} pieces of 1 MiB");
    assert!(pieces.iter().all(|&n| n > 2.0), "{pieces:?}");
    crowd.assert_exact(&name, &pieced, 0.02);
    for light in 0..2 {
        assert!(
            whole.visibility[light] == pieced.visibility[light],
            "{name}, light {light}: pieces change the shadows"
        );
    }
}
