//! The exact methods against each other: where each tests the same rays against the same
//! blocking triangles, they shadow the same pixels.

use glam::UVec2;
use zoo_host::judge::edge_band;
use zoo_host::test_support::judge;

const SIZE: UVec2 = UVec2::new(128, 128);

/// The same hard visibility as rt-shadows' one ray to each light's centre (as the judge scores
/// it) on all but 0.02 % of the pixels off the reference's shadow edges, on scenes with alpha
/// masks and instances: both test the same rays against the same blocking triangles, instances
/// reached through the same placement. (Translucent casters block per-triangle volumes
/// outright; rt-shadows' light through forest's panes is filtered to under half, shadowed to
/// the judge as well.)
#[test]
fn agrees_with_one_ray_per_light() {
    for scene in ["foliage.ron", "forest.ron"] {
        let volumes = judge(scene, "per-triangle-volumes", &[], SIZE);
        let rays = judge(scene, "rt-shadows", &[("rays_per_pixel", "1")], SIZE);
        for light in 0..volumes.judged.visibility.len() {
            let reference = &volumes.reference.lights[light];
            let band = edge_band(reference, SIZE.x as usize, SIZE.y as usize);
            let (a, b) = (
                &volumes.judged.visibility[light],
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
            eprintln!("{scene} light {light}: {differ} of {pixels} pixels differ off edges");
            assert!(share <= 0.0002, "{scene} light {light}: {share} differ");
        }
    }
}
