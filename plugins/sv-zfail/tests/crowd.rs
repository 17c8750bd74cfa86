//! Crowds of instanced real meshes: more volume geometry than one buffer holds, drawn in
//! pieces whose stencil counts add up.

// Link the plugin so its technique registers.
use zoo_plugin_sv_zfail as _;

use zoo_host::glam::UVec2;
use zoo_host::judging::{DEFAULT_SAMPLES, Judged, SceneReference, judge_technique};
use zoo_host::test_support::{counter, crowd_scene, gpu};
use zoo_host::{LightKind, Renderer, Scene};

const TECHNIQUE: &str = "sv-zfail";

/// A crowd's reference and renderer: the technique judged with parameters `params`, and the
/// number of pieces each light's volumes took.
struct Crowd {
    renderer: Renderer,
    reference: SceneReference,
}

impl Crowd {
    fn new(scene: Scene, size: UVec2) -> Crowd {
        let mut renderer = Renderer::new(gpu(), scene, size).unwrap();
        let reference = SceneReference::compute(&mut renderer, DEFAULT_SAMPLES, |_| {}).unwrap();
        Crowd {
            renderer,
            reference,
        }
    }

    fn judge(&mut self, params: &[(&str, &str)]) -> (Judged, Vec<f64>) {
        let registration = zoo_host::find_technique(TECHNIQUE).unwrap();
        let schema = (registration.params)();
        let mut values = zoo_host::params::defaults(&schema);
        let params: Vec<(String, String)> = (params.iter())
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        zoo_host::params::apply_assignments(&schema, &mut values, &params).unwrap();
        let judged = judge_technique(&mut self.renderer, &self.reference, TECHNIQUE, &values);
        let judged = judged.unwrap();
        let counters = self.renderer.technique_instance().counters();
        let pieces = (0..self.renderer.lights().len())
            .map(|l| counter(&counters, &format!("light {l} volume pieces")).unwrap())
            .collect();
        (judged, pieces)
    }
}

/// Asserts the judge's bounds of an exact method on every light: core errors at most 0.001,
/// and all errors (raster edges) at most `edges`; and that nothing was left out.
fn assert_exact(scene: &str, judged: &Judged, edges: f64) {
    for score in &judged.scores {
        let m = score.metrics.unwrap();
        eprintln!("{TECHNIQUE}, {scene}, {}: {m:?}", score.kind.name());
        assert!(
            m.false_lit_core + m.false_shadow_core <= 0.001
                && m.false_lit + m.false_shadow <= edges,
            "{scene}, light {}: {m:?}",
            score.light
        );
    }
    assert!(judged.warnings.is_empty(), "{:?}", judged.warnings);
}

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
        let mut crowd = Crowd::new(scene, UVec2::new(192, 192));
        let (whole, one) = crowd.judge(&[]);
        let (pieced, several) = crowd.judge(&[("volume_buffer_mib", mib)]);
        eprintln!("{name}: pieces {one:?}, then {several:?} of {mib} MiB");
        assert!(one.iter().all(|&n| n == 1.0), "{one:?}");
        assert!(several.iter().all(|&n| n > 2.0), "{several:?}");
        assert_exact(&name, &pieced, 0.02);
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
        let (judged, pieces) = Crowd::new(scene, UVec2::new(256, 256)).judge(&[]);
        eprintln!("{name}: pieces {pieces:?}");
        assert_exact(&name, &judged, 0.015);
    }
}
