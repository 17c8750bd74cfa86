//! Ray-traced shadows against the reference judge: exact hard shadows, and soft shadows that
//! approach the area reference as rays are added.

// Link the plugin so its technique registers.
use zoo_plugin_rt_shadows as _;

use zoo_host::glam::UVec2;
use zoo_host::test_support::judge;

const SIZE: UVec2 = UVec2::new(192, 144);

/// One ray to each light's centre agrees with the judge's hard visibility: the core error (the
/// one-pixel band around the reference's shadow edges left out) is at most 0.0005 of the
/// pixels each light reaches, on scenes of every kind (curved receivers, thin casters,
/// contact, alpha-masked foliage, lamps close to walls, kilometre scale).
#[test]
fn one_ray_per_light_is_exact() {
    for scene in [
        "planar-room.ron",
        "curved.ron",
        "thin-casters.ron",
        "contact.ron",
        "foliage.ron",
        "wall-lamps.ron",
        "kilometre.ron",
    ] {
        let run = judge(scene, "rt-shadows", &[("rays_per_pixel", "1")], SIZE);
        for score in &run.judged.scores {
            let m = score.metrics.expect("every light kind is supported");
            eprintln!(
                "{scene} light {}: core {:.5}/{:.5} mae {:.4}",
                score.light, m.false_shadow_core, m.false_lit_core, m.mae
            );
            assert!(
                m.false_shadow_core + m.false_lit_core <= 0.0005,
                "{scene} light {}: {m:?}",
                score.light
            );
        }
    }
}

/// Soft shadows from rays to the light's disk: the mean error against the area reference
/// falls as rays are added, and the edge-aware filter lowers it further at a few rays.
#[test]
fn soft_shadows_approach_the_area_reference_with_more_rays_and_the_filter() {
    let mae = |rays: &str, radius: &str| {
        let params = [("rays_per_pixel", rays), ("denoise_radius", radius)];
        let run = judge("soft.ron", "rt-shadows", &params, SIZE);
        let scores: Vec<_> = run.judged.scores.iter().filter_map(|s| s.metrics).collect();
        scores.iter().map(|m| m.mae).sum::<f64>() / scores.len() as f64
    };
    let (one, four, sixteen) = (mae("1", "0"), mae("4", "0"), mae("16", "0"));
    let filtered = mae("4", "2");
    eprintln!(
        "soft: mae {one:.4} (1 ray), {four:.4} (4), {sixteen:.4} (16); 4 rays filtered {filtered:.4}"
    );
    assert!(four < one && sixteen < 0.8 * four, "{one} {four} {sixteen}");
    assert!(filtered < 0.8 * four, "filtered {filtered} against {four}");
}
