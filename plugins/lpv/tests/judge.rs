//! Light propagation volumes against the judge's one-bounce reference on `atrium`: the amount
//! of indirect light, its relative error, colour bleeding from the cloths, the coarser grids'
//! far light, a lit plane that must not light itself, a smaller court, occlusion, and rooms
//! lit through openings (relative error and the leak through walls).

use zoo_plugin_lpv as _;

use zoo_host::glam::{UVec2, Vec3};
use zoo_host::judging::{SceneReference, judge_technique};
use zoo_host::params::{ParamValues, apply_assignments, defaults};
use zoo_host::test_support::{gpu, scene_from_ron, scene_path};
use zoo_host::{Renderer, Scene};

const SIZE: UVec2 = UVec2::new(160, 120);

/// The settings README recommends indoors: occluders per face, thickened to close seams, and
/// lookups that leave out the light of cells across a wall.
const INDOORS: [(&str, &str); 3] = [
    ("occlusion", "Faces"),
    ("coverage_gain", "2"),
    ("lookup_blocking", "true"),
];

fn params(assignments: &[(&str, &str)]) -> ParamValues {
    let registration = zoo_host::find_technique("lpv").unwrap();
    let schema = (registration.params)();
    let mut values = defaults(&schema);
    let pairs: Vec<(String, String)> = assignments
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    apply_assignments(&schema, &mut values, &pairs).unwrap();
    values
}

/// Sum of `light` over the pixels `keep` accepts.
fn total(light: &[Vec3], keep: impl Fn(usize) -> bool) -> Vec3 {
    (0..light.len())
        .filter(|&i| keep(i))
        .fold(Vec3::ZERO, |sum, i| sum + light[i])
}

/// How red (or blue) a colour is against the other two channels.
fn share(c: Vec3, channel: usize) -> f32 {
    c[channel] / (c.x + c.y + c.z).max(1e-9)
}

/// lpv says which lights it does not bounce (and the judge, `compare` and the viewer pass it
/// on) instead of leaving their missing light a bare error: on `planar-room` the point light
/// never, the spot light only with `spot_lights`; the sun always bounces.
#[test]
fn the_lights_lpv_does_not_bounce_are_named() {
    let scene = Scene::load(&scene_path("planar-room.ron")).unwrap();
    let kinds: Vec<&str> = scene.lights.iter().map(|l| l.kind.name()).collect();
    assert_eq!(kinds, ["point", "spot", "directional"]);
    let mut renderer = Renderer::new(gpu(), scene, UVec2::new(32, 32)).unwrap();
    let reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
    for (spot_lights, unbounced) in [("false", vec![0, 1]), ("true", vec![0])] {
        let values = params(&[("spot_lights", spot_lights)]);
        let judged = judge_technique(&mut renderer, &reference, "lpv", &values).unwrap();
        let lights: Vec<usize> = judged.unbounced.iter().map(|(l, _)| *l).collect();
        assert_eq!(
            lights, unbounced,
            "spot_lights {spot_lights}: {:?}",
            judged.unbounced
        );
        assert!(
            judged
                .unbounced
                .iter()
                .all(|(_, why)| why.contains("does not bounce"))
        );
    }
}

/// With `point_lights` a point light renders a reflective shadow map per cube face and its
/// light bounces: `planar-room` lit by its point light alone goes from nothing (relative RMSE
/// 1.0) to within 0.5 of the one-bounce reference (measured 0.46). Its amount of light is 0.58
/// of the reference's, as a spot light's is through its one map in the same room (0.58;
/// directional maps carry 0.99 on `atrium`): a shortfall of lpv's perspective maps, not of
/// the faces.
#[test]
fn point_lights_bounce_through_six_faces() {
    let text = std::fs::read_to_string(scene_path("planar-room.ron")).unwrap();
    let start = text.find("        Spot(position").unwrap();
    let end = start + text[start..].find("    ],").unwrap();
    let scene = scene_from_ron(
        "planar-room-point",
        &format!("{}{}", &text[..start], &text[end..]),
    );
    assert_eq!(scene.lights.len(), 1);
    let mut renderer = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    let mut reference = SceneReference::compute(&mut renderer, 16, |_| {}).unwrap();
    let rays = 256;
    let expected = reference.indirect(&scene, &scene.lights, rays).to_vec();
    let mask = reference.surface_mask();
    let mut score = |point_lights: &str| {
        let values = params(&[("point_lights", point_lights)]);
        let judged = judge_technique(&mut renderer, &reference, "lpv", &values).unwrap();
        let got = judged.indirect.clone().expect("lpv adds light");
        let rmse = (judged.indirect_rmse(&mut reference, &scene, &scene.lights, rays)).unwrap();
        (
            rmse,
            total(&got, |i| mask[i]) / total(&expected, |i| mask[i]),
        )
    };
    let (off, _) = score("false");
    let (on, ratio) = score("true");
    eprintln!("point light: relative RMSE {off:.3} without, {on:.3} with (amount {ratio})");
    assert!((off - 1.0).abs() < 1e-6, "{off}");
    assert!(on <= 0.5, "{on}");
    assert!(
        ratio.min_element() > 0.5 && ratio.max_element() < 1.25,
        "{ratio}"
    );
}

#[test]
fn atrium_against_the_one_bounce_reference() {
    let scene = Scene::load(&scene_path("atrium.ron")).unwrap();
    let mut renderer = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    let mut reference = SceneReference::compute(&mut renderer, 16, |_| {}).unwrap();
    // 256 rays a pixel: the reference's own noise is then 0.06 in relative RMSE (0.12 at 64
    // rays, which would add about 0.02 to the score below).
    let rays = 256;
    let expected = reference.indirect(&scene, &scene.lights, rays).to_vec();
    let mask = reference.surface_mask();
    let judged = judge_technique(&mut renderer, &reference, "lpv", &params(&[])).unwrap();
    let got = judged.indirect.clone().expect("lpv adds light");
    let rmse = judged
        .indirect_rmse(&mut reference, &scene, &scene.lights, rays)
        .unwrap();
    // The amount of light: VPL intensities and the lookup follow from the renderer's units
    // with no tuning; measured 0.99 of the reference per channel.
    let (g, e) = (total(&got, |i| mask[i]), total(&expected, |i| mask[i]));
    let ratio = g / e;
    eprintln!("atrium: indirect {g} against {e} (ratio {ratio}), relative RMSE {rmse:.3}");
    assert!(
        ratio.min_element() > 0.85 && ratio.max_element() < 1.15,
        "{ratio}"
    );
    // The bound. Measured 0.289 (0.82 before lookups restored the emitters'
    // orientation, coarser grids added the light beyond the finer grids' reach and the cells
    // were sized for reach).
    assert!(rmse <= 0.3, "relative RMSE {rmse}");
}

#[test]
fn a_smaller_court_keeps_the_light_in_place() {
    // The defaults were chosen on `atrium` and two other scenes; this is one of them, an 8 m
    // court a tenth of `atrium`'s size with a red wall, a block and a ball, the sun from
    // behind the camera's left.
    let scene = scene_from_ron(
        "court.ron",
        "(camera: (position: (0.0, 2.0, 5.5), target: (0.0, 1.2, 0.0), near: 0.05, far: 60),
          lights: [Directional(direction: (-0.4, -0.8, 0.45), intensity: 2.0)],
          objects: [
            (mesh: Plane(size: 12, subdivisions: 2), color: (0.7, 0.7, 0.7)),
            (mesh: Box(size: (0.2, 4.0, 8.0)), color: (0.8, 0.15, 0.1), transform: (translation: (-4.0, 2.0, 0.0))),
            (mesh: Box(size: (0.2, 4.0, 8.0)), color: (0.8, 0.8, 0.8), transform: (translation: (4.0, 2.0, 0.0))),
            (mesh: Box(size: (8.2, 4.0, 0.2)), color: (0.75, 0.75, 0.8), transform: (translation: (0.0, 2.0, -4.0))),
            (mesh: Box(size: (1.2, 1.6, 1.2)), color: (0.8, 0.8, 0.7), transform: (translation: (0.8, 0.8, -0.5), rotation_degrees: (0, 30, 0))),
            (mesh: Sphere(radius: 0.5, segments: 32, rings: 16), color: (0.3, 0.4, 0.9), transform: (translation: (-1.5, 0.5, 1.0))),
          ])",
    );
    let mut renderer = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    let mut reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
    let mut score = |orientation: &str| {
        let values = params(&[("emitter_orientation", orientation)]);
        let judged = judge_technique(&mut renderer, &reference, "lpv", &values).unwrap();
        judged
            .indirect_rmse(&mut reference, &scene, &scene.lights, 64)
            .unwrap()
    };
    let (restored, isotropic) = (score("true"), score("false"));
    eprintln!("court: relative RMSE {restored:.3}, {isotropic:.3} without the orientation");
    // Measured 0.41 and 1.66.
    assert!(restored < 0.45, "{restored}");
    assert!(isotropic > 2.0 * restored, "{isotropic}");
}

#[test]
fn the_lit_cloth_colours_the_light_around_it() {
    // The sun of `atrium` lights the blue cloth (east wall) at the start of its path and the
    // red one (west wall) at its end.
    let scene = Scene::load(&scene_path("atrium.ron")).unwrap();
    let mut renderer = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    for (name, centre, channel, sun) in [
        (
            "blue cloth",
            Vec3::new(8.6, 4.5, 2.0),
            2,
            Vec3::new(0.55, -0.75, -0.35),
        ),
        (
            "red cloth",
            Vec3::new(-8.6, 4.5, -2.0),
            0,
            Vec3::new(-0.45, -0.8, -0.25),
        ),
    ] {
        let mut lights = scene.lights.clone();
        lights[0].direction = sun.normalize();
        renderer.set_lights(lights.clone());
        let mut reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
        let expected = reference.indirect(&scene, &lights, 64).to_vec();
        let mask = reference.surface_mask();
        let judged = judge_technique(&mut renderer, &reference, "lpv", &params(&[])).unwrap();
        let got = judged.indirect.unwrap();
        let positions = &reference.gbuffer.positions;
        let everywhere = |i: usize| mask[i];
        // Within 3 m of the cloth (a 4 x 3 m hanging 2.5 to 6.5 m up): the wall around it.
        let half = Vec3::new(0.05, 2.0, 1.5);
        let around = |i: usize| {
            let outside = (positions[i].truncate() - centre).abs() - half;
            mask[i] && outside.max(Vec3::ZERO).length() < 3.0
        };
        // The floor in front of and below it.
        let below = |i: usize| {
            let p = positions[i].truncate();
            mask[i] && p.y < 0.05 && (p.x - centre.x).abs() < 3.0 && (p.z - centre.z).abs() < 2.5
        };
        let hue = |light: &[Vec3], keep: &dyn Fn(usize) -> bool| share(total(light, keep), channel);
        let scene_hue = hue(&got, &everywhere);
        eprintln!(
            "{name}: lpv share {:.3} around it, {:.3} on the floor below, {scene_hue:.3} in the scene; reference {:.3} around, {:.3} below, {:.3} in the scene",
            hue(&got, &around),
            hue(&got, &below),
            hue(&expected, &around),
            hue(&expected, &below),
            hue(&expected, &everywhere),
        );
        assert!(
            (0..mask.len()).filter(|&i| around(i)).count() > 100,
            "{name} is in view"
        );
        // The reference bleeds the cloth's hue onto the floor below it.
        assert!(
            hue(&expected, &below) > hue(&expected, &everywhere) + 0.015,
            "{name}"
        );
        // So does the volume: blue +0.012 below the cloth (the reference +0.023), red +0.020
        // (+0.026). It also tints the wall around the cloth (blue +0.037, red +0.013), where
        // the reference has none: the cloth's own light, spread sideways.
        assert!(
            hue(&got, &below) > scene_hue + 0.005,
            "{name}: no colour on the floor below"
        );
    }
}

#[test]
fn coarser_grids_carry_the_light_the_finest_grid_cannot_reach() {
    // With `coarse_far_light` off a finer grid replaces the coarser ones, and light there
    // travels 8 steps of the finest cell (4.3 m in `atrium`): much of the west wall, 6 m from
    // the lit floor, stays dark. On, the coarser grids add their light from beyond that reach.
    let scene = Scene::load(&scene_path("atrium.ron")).unwrap();
    let mut renderer = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    let mut reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
    let expected = reference.indirect(&scene, &scene.lights, 64).to_vec();
    let mask = reference.surface_mask();
    let mut indirect = |far: &str| {
        let values = params(&[("coarse_far_light", far)]);
        let judged = judge_technique(&mut renderer, &reference, "lpv", &values).unwrap();
        judged.indirect.unwrap()
    };
    let (replaced, added) = (indirect("false"), indirect("true"));
    // Pixels with light in the reference that the replacing lookup leaves under a quarter of
    // it.
    let dark = |i: usize| {
        let e = expected[i].element_sum();
        mask[i] && e > 0.3 && replaced[i].element_sum() < 0.25 * e
    };
    let count = (0..mask.len()).filter(|&i| dark(i)).count();
    let reached =
        |light: &[Vec3]| total(light, dark).element_sum() / total(&expected, dark).element_sum();
    let (before, after) = (reached(&replaced), reached(&added));
    eprintln!(
        "{count} out-of-reach pixels: {before:.3} of the reference replaced, {after:.3} added"
    );
    assert!(count > 1000, "{count}");
    // Measured 0.16 and 0.79.
    assert!(after > 2.5 * before, "{before} -> {after}");
}

#[test]
fn a_lit_plane_does_not_light_itself() {
    // A sunlit floor and nothing else: it has no light to receive. Propagation alone turns
    // its light nearly isotropic and the floor reads it back; restoring the emitters'
    // orientation at the lookup leaves next to nothing.
    let scene = scene_from_ron(
        "lit-plane.ron",
        "(camera: (position: (0, 6, 12), target: (0, 0, 0)),
          lights: [Directional(direction: (0.3, -0.9, -0.2), intensity: 3.0)],
          objects: [(mesh: Plane(size: 24), color: (0.8, 0.8, 0.8))])",
    );
    let mut renderer = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    let reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
    let mask = reference.surface_mask();
    let mut floor_light = |orientation: &str| {
        let values = params(&[("emitter_orientation", orientation)]);
        let judged = judge_technique(&mut renderer, &reference, "lpv", &values).unwrap();
        total(&judged.indirect.unwrap(), |i| mask[i]).element_sum()
    };
    let (isotropic, restored) = (floor_light("false"), floor_light("true"));
    // For scale: without the orientation the floor reads light of the order of its own
    // reflected light (0.8 x 3 x 0.9 / pi, about 0.7 per channel); at least 0.05 per pixel.
    let pixels = mask.iter().filter(|m| **m).count() as f32;
    eprintln!("lit plane: {isotropic:.2} without, {restored:.4} with, over {pixels} pixels");
    assert!(isotropic > 0.05 * pixels, "{isotropic}");
    // Measured 1e-4 against 5e4.
    assert!(
        restored < 1e-6 * isotropic,
        "{restored} against {isotropic}"
    );
}

#[test]
fn occlusion_stops_light_behind_a_wall() {
    // A sunlit floor on the left of a tall wall; the right side is in the wall's shadow and
    // sees the lit floor only through the wall.
    let scene = scene_from_ron(
        "behind-wall.ron",
        "(camera: (position: (6, 5, 9), target: (2, 0, 0)),
          lights: [Directional(direction: (0.6, -0.8, 0.0), intensity: 3.0)],
          objects: [
            (mesh: Plane(size: 16), color: (0.8, 0.8, 0.8)),
            (mesh: Box(size: (0.4, 6.0, 16.0)), transform: (translation: (0.0, 3.0, 0.0)), color: (0.8, 0.8, 0.8)),
          ])",
    );
    let mut renderer = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
    let reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
    let positions = reference.gbuffer.positions.clone();
    let behind = |i: usize| {
        let p = positions[i];
        p.w > 0.5 && p.y < 0.05 && p.x > 1.0 && p.x < 3.0
    };
    let settings: [&[(&str, &str)]; 3] = [&[("occlusion", "Off")], &[], &INDOORS];
    let mut light_behind = Vec::new();
    for set in settings {
        let judged = judge_technique(&mut renderer, &reference, "lpv", &params(set)).unwrap();
        let got = judged.indirect.unwrap();
        let count = (0..got.len()).filter(|&i| behind(i)).count();
        assert!(count > 200, "the floor behind the wall is in view");
        light_behind.push(total(&got, behind).x / count as f32);
    }
    let [off, volume, indoors] = light_behind[..] else {
        unreachable!()
    };
    eprintln!("light behind the wall: off {off}, geometry volume {volume}, indoors {indoors}");
    // Some of it comes over the wall's top (6 m, within the coarsest grid's reach); measured
    // 0.063, 0.019 and 0.018.
    assert!(off > 0.0, "light leaks through without occlusion");
    assert!(volume < 0.5 * off, "{light_behind:?}");
    assert!(indoors < 0.5 * off, "{light_behind:?}");
}

#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn rooms_lit_through_openings() {
    // The enclosed scenes: 0.2 m slabs under a skylight and in two rooms joined by a
    // doorway (thinner than the coarser cells), 0.7 m walls around a window (thicker than
    // every cell). Measured at 256 rays a pixel (README, `lpv`): the published geometry volume
    // scores 1.19, 0.84 and 2.05 (worse than no indirect light on two), leak 0.07, 0.19 and
    // 8.9; indoors 0.77, 0.81 and 0.90, leak 0.08, 0.20 and 0.09. The window room's leak is
    // light diffused around the window's reveal by the two-band directions, not through its
    // walls (no setting brought it under 0.14), so its bound is 0.25, not the 0.1.
    let rays = 256;
    for (name, leak_bound) in [
        ("skylight-room.ron", 0.1),
        ("window-room.ron", 0.25),
        ("doorway-rooms.ron", 0.1),
    ] {
        let scene = Scene::load(&scene_path(name)).unwrap();
        let mut renderer = Renderer::new(gpu(), scene.clone(), SIZE).unwrap();
        let mut reference = SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
        let mut score = |set: &[(&str, &str)]| {
            let judged = judge_technique(&mut renderer, &reference, "lpv", &params(set)).unwrap();
            let rmse = judged.indirect_rmse(&mut reference, &scene, &scene.lights, rays);
            let leak = judged.indirect_leak(&mut reference, &scene, &scene.lights, rays);
            (rmse.unwrap(), leak.unwrap())
        };
        let (published, published_leak) = score(&[]);
        let (indoors, leak) = score(&INDOORS);
        eprintln!(
            "{name}: relative RMSE {indoors:.3} indoors, {published:.3} published; leak {:.3} \
             and {:.3} (unlit {:.3} of the pixels)",
            leak.leak, published_leak.leak, leak.unlit_share
        );
        assert!(
            leak.unlit_share > 0.05,
            "{name}: the scene has surfaces no lit one sees"
        );
        // Never worse than no indirect light (1.0); the 0.6 is out of reach (README).
        assert!(indoors < 0.95, "{name}: relative RMSE {indoors}");
        assert!(leak.leak <= leak_bound, "{name}: leak {}", leak.leak);
    }
}
