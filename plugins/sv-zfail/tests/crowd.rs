//! Crowds of instanced real meshes: more volume geometry than one buffer holds, drawn in
//! pieces whose stencil counts add up.

// Link the plugin so its technique registers.
use zoo_plugin_sv_zfail as _;

use zoo_host::LightKind;
use zoo_host::glam::UVec2;
use zoo_host::test_support::{CrowdRun, crowd_scene};

const TECHNIQUE: &str = "sv-zfail";

/// Crowds whose volumes fit one buffer, drawn again in pieces of a small budget: a teapot's
/// volume may need about 150 thousand vertices (2.4 MiB), so in pieces of 1 MiB each teapot
/// is cut into stretches of triangles and of edges; in pieces of 8 MiB, three cows share a
/// piece. Every light's shadows are exact, and the same to the bit as in one piece.
#[test]
fn crowds_in_pieces_are_exact_and_match_one_piece() {
    let all = [LightKind::Spot, LightKind::Directional, LightKind::Point];
    for (model, count, lights, mib) in [("teapot", 24, &all[..], "1"), ("cow", 30, &all[..1], "8")]
    {
        let Some(scene) = crowd_scene(model, count, lights) else {
            return;
        };
        let name = scene.name.clone();
        let mut crowd = CrowdRun::new(TECHNIQUE, scene, UVec2::new(192, 192));
        let (whole, one) = crowd.judge(&[]);
        let (pieced, several) = crowd.judge(&[("volume_buffer_mib", mib)]);
        eprintln!("{name}: pieces {one:?}, then {several:?} of {mib} MiB");
        assert!(one.iter().all(|&n| n == 1.0), "{one:?}");
        assert!(several.iter().all(|&n| n > 2.0), "{several:?}");
        crowd.assert_exact(&name, &pieced, 0.02);
        for light in 0..lights.len() {
            assert!(
                whole.visibility[light] == pieced.visibility[light],
                "{name}, light {light}: pieces change the shadows"
            );
        }
    }
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
