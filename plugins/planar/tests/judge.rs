//! Planar shadows against the reference judge, and each classic failure case on a small scene.

// Link the plugin so its technique registers.
use zoo_plugin_planar as _;

use zoo_host::glam::UVec2;
use zoo_host::test_support::{JudgeRun, Metric, judge, judge_scene, scene_from_ron};

const SIZE: UVec2 = UVec2::new(256, 256);

/// A floor receiver under a point light with the given casters.
fn floor_scene(name: &str, light: &str, casters: &str) -> zoo_host::Scene {
    scene_from_ron(
        name,
        &format!(
            "(camera: (position: (0, 7, 7), target: (0, 0, 0), fov_y_degrees: 55),
              lights: [{light}],
              objects: [(name: \"floor\", mesh: Plane(size: 10), receiver: true), {casters}])"
        ),
    )
}

fn receiver_values(run: &JudgeRun, light: usize) -> Vec<f32> {
    let mask = run.receiver_mask();
    run.judged.visibility[light]
        .iter()
        .zip(&mask)
        .filter(|(_, m)| **m)
        .map(|(v, _)| *v)
        .collect()
}

#[test]
fn planar_room_receivers_match_the_reference() {
    let run = judge("planar-room.ron", "planar", &[], SIZE);
    let mask = run.receiver_mask();
    assert!(
        mask.iter().filter(|m| **m).count() > 20_000,
        "receiver planes cover the view"
    );
    for light in 0..run.loaded.lights.len() {
        let on_planes = run.metrics_masked(light, &mask);
        let full = run.metrics(light);
        eprintln!(
            "light {light} ({}): receivers {:?}\n  full image {:?}",
            run.loaded.lights[light].kind.name(),
            on_planes,
            full
        );
        assert!(
            on_planes.false_shadow_core + on_planes.false_lit_core <= 0.005,
            "light {light}: core errors on receivers {} + {}",
            on_planes.false_shadow_core,
            on_planes.false_lit_core
        );
        run.assert_bounds(
            light,
            &on_planes,
            &[
                (Metric::FalseShadowCore, 0.005),
                (Metric::FalseLitCore, 0.005),
            ],
        );
        // The honest limit: no self-shadowing and nothing on the casters, so shadows the
        // reference puts on the casters themselves are missed; nothing is falsely darkened.
        assert!(full.false_lit >= on_planes.false_lit, "light {light}");
        // False shadows can only be on the planes: the same pixels in both counts.
        let count = |m: &zoo_host::judge::Metrics| (m.false_shadow * m.pixels as f64).round();
        assert_eq!(count(&full), count(&on_planes), "light {light}");
    }
    // Shadows stay on the planes: every other pixel keeps visibility 1.
    for light in 0..run.loaded.lights.len() {
        let leaked = run.judged.visibility[light]
            .iter()
            .zip(&mask)
            .filter(|(v, m)| !**m && **v < 1.0)
            .count();
        assert_eq!(
            leaked, 0,
            "light {light}: shadow outside the receiver planes"
        );
    }
}

#[test]
fn overlapping_casters_darken_once() {
    let scene = floor_scene(
        "overlap",
        "Point(position: (0, 6, 0), range: 50)",
        "(mesh: Box(size: (1.5, 0.4, 1.5)), transform: (translation: (-0.4, 2, 0))),
         (mesh: Box(size: (1.5, 0.4, 1.5)), transform: (translation: (0.4, 3, 0)))",
    );
    let run = judge_scene(scene, "planar", &[("opacity", "0.5")], SIZE);
    let values = receiver_values(&run, 0);
    let half = values
        .iter()
        .filter(|v| (**v - 0.5).abs() <= 1.0 / 255.0)
        .count();
    let darker = values.iter().filter(|v| **v < 0.5 - 1.0 / 255.0).count();
    assert!(half > 2000, "only {half} shadowed pixels");
    assert_eq!(darker, 0, "{darker} pixels darkened more than once");
    assert!(
        values
            .iter()
            .all(|v| *v == 1.0 || (*v - 0.5).abs() <= 1.0 / 255.0)
    );
    // With full opacity it agrees with the reference on the floor.
    let full = judge_scene(run.loaded.clone(), "planar", &[], SIZE);
    let m = full.metrics_masked(0, &full.receiver_mask());
    assert!(m.false_shadow_core + m.false_lit_core <= 0.005, "{m:?}");
}

#[test]
fn a_caster_beyond_the_light_casts_no_anti_shadow() {
    let scene = floor_scene(
        "anti-shadow",
        "Point(position: (0, 3, 0), range: 50)",
        "(mesh: Box(size: (1, 1, 1)), transform: (translation: (0.5, 5, 0)))",
    );
    let run = judge_scene(scene, "planar", &[], SIZE);
    assert!(
        receiver_values(&run, 0).iter().all(|v| *v == 1.0),
        "an anti-shadow was drawn"
    );
    assert_eq!(run.metrics(0).false_shadow, 0.0);
}

#[test]
fn a_caster_partly_below_the_plane_casts_only_its_upper_part() {
    // One box half sunk into the floor, one entirely below it: projecting the hidden parts
    // would draw false shadows on the far side of the light.
    let scene = floor_scene(
        "below-plane",
        "Point(position: (0, 4, 0), range: 50)",
        "(mesh: Box(size: (1, 2, 1)), transform: (translation: (-1.5, 0, 0.5))),
         (mesh: Box(size: (1, 1, 1)), transform: (translation: (2.5, -1, 0)))",
    );
    let run = judge_scene(scene, "planar", &[], SIZE);
    let m = run.metrics_masked(0, &run.receiver_mask());
    eprintln!("{m:?}");
    assert!(m.false_shadow_core <= 0.001, "false shadows: {m:?}");
    assert!(m.false_shadow_core + m.false_lit_core <= 0.005, "{m:?}");
    let shadowed = run.reference.lights[0].shadowed_fraction();
    assert!(shadowed > 0.005, "the sunk box casts a shadow ({shadowed})");
}

#[test]
fn a_light_behind_a_plane_casts_nothing_onto_it() {
    // The wall faces +z; the light stands behind it (z < -1), so the wall's front gets nothing.
    let scene = scene_from_ron(
        "behind",
        "(camera: (position: (0, 3, 8), target: (0, 1.5, 0)),
          lights: [Point(position: (0, 3, -4), range: 50)],
          objects: [
            (name: \"wall\", mesh: Plane(size: 6), receiver: true,
             transform: (translation: (0, 3, -1), rotation_degrees: (90, 0, 0))),
            (mesh: Sphere(radius: 0.5), transform: (translation: (0, 2, -2.5))),
          ])",
    );
    let run = judge_scene(scene, "planar", &[], UVec2::new(128, 128));
    assert!(run.judged.visibility[0].iter().all(|v| *v == 1.0));
    assert_eq!(
        run.judged.scores[0].metrics.unwrap().pixels,
        0,
        "the light does not reach the wall's front"
    );
}

#[test]
fn disabled_receivers_get_no_shadow() {
    let run = judge(
        "planar-room.ron",
        "planar",
        &[("receivers", "1")],
        UVec2::new(128, 128),
    );
    let floor = &run.loaded.receivers[0];
    for light in 0..run.loaded.lights.len() {
        for (i, v) in run.judged.visibility[light].iter().enumerate() {
            let p = run.reference.gbuffer.positions[i];
            let on_floor = (floor.plane.truncate().dot(p.truncate()) + floor.plane.w).abs() < 1e-3;
            assert!(
                on_floor || *v == 1.0,
                "light {light}: shadow on a disabled plane"
            );
        }
    }
}

/// A fence of masked planks and a chain-link panel over the floor: their holes cast no shadow,
/// so the flattened casters agree with the judge's exact alpha test on the floor.
#[test]
fn masked_casters_shadow_only_where_their_masks_cover() {
    let scene = floor_scene(
        "masked",
        "Directional(direction: (-0.3, -1, -0.2))",
        r#"(mesh: Plane(size: 3), alpha_mask: Some("textures/fence.png"),
            transform: (translation: (-1, 1.5, 0), rotation_degrees: (0, 0, 15))),
           (mesh: Plane(size: 2.5), alpha_mask: Some("textures/chain-link.png"),
            transform: (translation: (1.5, 1, 1), rotation_degrees: (20, 30, 0)))"#,
    );
    let run = judge_scene(scene, "planar", &[], SIZE);
    let mask = run.receiver_mask();
    let on_floor = run.metrics_masked(0, &mask);
    eprintln!("masked casters on the floor: {on_floor:?}");
    assert!(
        on_floor.false_shadow_core + on_floor.false_lit_core <= 0.005,
        "{on_floor:?}"
    );
    // The holes matter: a good share of the floor under the casters is lit through them.
    let values = receiver_values(&run, 0);
    let shadowed = values.iter().filter(|v| **v < 0.5).count();
    assert!(shadowed > 1000, "{shadowed} shadowed floor pixels");
    let mut opaque = run.loaded.clone();
    for object in &mut opaque.objects {
        object.alpha_mask = None;
    }
    let whole = judge_scene(opaque, "planar", &[], SIZE);
    let whole_shadowed = receiver_values(&whole, 0)
        .iter()
        .filter(|v| **v < 0.5)
        .count();
    eprintln!("shadowed floor pixels: {shadowed} masked, {whole_shadowed} with the masks ignored");
    assert!(
        (shadowed as f64) < 0.8 * whole_shadowed as f64,
        "masked {shadowed} against whole {whole_shadowed} shadowed pixels"
    );
}
