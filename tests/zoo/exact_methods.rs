//! The exact methods against each other: where each tests the same rays against the same
//! blocking triangles, they shadow the same pixels.

use glam::UVec2;
use zoo_host::judge::edge_band;
use zoo_host::test_support::{JudgeRun, judge};

const SIZE: UVec2 = UVec2::new(128, 128);

/// The per-triangle methods: each tests every pixel's shadow ray against the caster triangles
/// that may cross it.
const PER_TRIANGLE: [&str; 2] = ["per-triangle-volumes", "frustum-traced"];

/// The same hard visibility as rt-shadows' one ray to each light's centre (as the judge scores
/// it) on all but 0.02 % of the pixels off the reference's shadow edges, on scenes with alpha
/// masks and instances, for each per-triangle method: they test the same rays against the
/// same blocking triangles, instances reached through the same placement. (Translucent casters
/// block the per-triangle methods outright; rt-shadows' light through forest's panes is
/// filtered to under half, shadowed to the judge as well.)
#[test]
fn agrees_with_one_ray_per_light() {
    for scene in ["foliage.ron", "forest.ron"] {
        let rays = judge(scene, "rt-shadows", &[("rays_per_pixel", "1")], SIZE);
        for id in PER_TRIANGLE {
            agrees_off_edges(scene, id, &judge(scene, id, &[], SIZE), &rays);
        }
    }
}

/// Asserts that `exact` (technique `id`) and `rays` shadow the same pixels off the reference's
/// shadow edges, on all but 0.02 % of them.
fn agrees_off_edges(scene: &str, id: &str, exact: &JudgeRun, rays: &JudgeRun) {
    for light in 0..exact.judged.visibility.len() {
        let reference = &exact.reference.lights[light];
        let band = edge_band(reference, SIZE.x as usize, SIZE.y as usize);
        let (a, b) = (
            &exact.judged.visibility[light],
            &rays.judged.visibility[light],
        );
        let off_edges = (0..a.len()).filter(|&i| !band[i] && reference.contributing[i]);
        let (mut pixels, mut differ) = (0usize, 0usize);
        for i in off_edges {
            pixels += 1;
            differ += usize::from((a[i] < 0.5) != (b[i] < 0.5));
        }
        assert!(pixels > 0, "{scene} light {light} reaches pixels off edges");
        let share = differ as f64 / pixels as f64;
        eprintln!("{id} on {scene} light {light}: {differ} of {pixels} pixels differ off edges");
        assert!(
            share <= 0.0002,
            "{id} on {scene} light {light}: {share} differ"
        );
    }
}
