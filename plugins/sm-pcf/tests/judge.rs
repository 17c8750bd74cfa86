//! Shadow maps against the reference judge, with the bounds of the sm-pcf issue.

// Link the plugin so its technique registers.
use zoo_plugin_sm_pcf as _;

use zoo_host::glam::UVec2;
use zoo_host::test_support::{
    JudgeRun, Metric, assert_soft_near_walls, judge, judge_scene, scene_from_ron, scene_path,
};

const SIZE: UVec2 = UVec2::new(256, 256);

fn assert_default_bounds(run: &JudgeRun) {
    for light in 0..run.loaded.lights.len() {
        let m = run.metrics(light);
        eprintln!(
            "{} light {light} ({}): {m:?}",
            run.scene,
            run.loaded.lights[light].kind.name()
        );
        run.assert_bounds(
            light,
            &m,
            &[
                (Metric::FalseShadowCore, 0.005),
                (Metric::FalseLitCore, 0.01),
            ],
        );
    }
}

#[test]
fn planar_room_within_bounds_with_a_2048_map() {
    assert_default_bounds(&judge(
        "planar-room.ron",
        "sm-pcf",
        &[("map_size", "2048")],
        SIZE,
    ));
}

#[test]
fn curved_within_bounds_with_a_2048_map() {
    assert_default_bounds(&judge(
        "curved.ron",
        "sm-pcf",
        &[("map_size", "2048")],
        SIZE,
    ));
}

/// planar-room with its lights replaced by `lights`.
fn planar_room_with(name: &str, lights: &str) -> zoo_host::Scene {
    let text = std::fs::read_to_string(scene_path("planar-room.ron")).unwrap();
    let start = text.find("    lights: [").unwrap();
    let end = start + text[start..].find("    ],\n").unwrap() + "    ],\n".len();
    let replaced = format!(
        "{}    lights: [{lights}],\n{}",
        &text[..start],
        &text[end..]
    );
    scene_from_ron(name, &replaced)
}

#[test]
fn point_light_in_the_middle_of_planar_room_uses_a_seamless_cube_map() {
    let scene = planar_room_with(
        "planar-room-centre",
        "Point(position: (0.0, 3.4, 0.3), intensity: 30, range: 30)",
    );
    let run = judge_scene(scene, "sm-pcf", &[("map_size", "2048")], SIZE);
    // The light sees every wall and the floor: all six faces are in use.
    assert!(run.metrics(0).pixels > 40_000);
    assert_default_bounds(&run);
}

/// The bias's two artifacts on `contact`, where objects rest on the floor: shadow acne without
/// any bias (false shadow on more than 5 % of some light's pixels; measured 0.47 and 0.37), and
/// peter-panning with far too much constant bias (the point light's shadows pulled off their
/// casters: false lit on more than 5 % of its pixels off the edges; measured 0.19); the
/// defaults keep both within bounds.
#[test]
fn bias_shows_acne_when_missing_and_peter_panning_when_excessive() {
    let unbiased = [
        ("slope_bias", "0"),
        ("normal_offset", "0"),
        ("constant_bias", "0"),
    ];
    let run = judge("contact.ron", "sm-pcf", &unbiased, SIZE);
    let worst = (0..run.loaded.lights.len())
        .map(|l| run.metrics(l).false_shadow)
        .fold(0.0, f64::max);
    eprintln!("contact without bias: worst false_shadow {worst}");
    assert!(worst > 0.05, "no acne without bias ({worst})");
    let run = judge(
        "contact.ron",
        "sm-pcf",
        &[("constant_bias", "100000")],
        SIZE,
    );
    let point = (0..run.loaded.lights.len())
        .find(|&l| run.loaded.lights[l].kind == zoo_host::LightKind::Point)
        .expect("contact has a point light");
    let panning = run.metrics(point).false_lit_core;
    eprintln!("contact with far too much bias: point light false_lit_core {panning}");
    assert!(
        panning > 0.05,
        "no peter-panning with too much bias ({panning})"
    );
    // And the defaults remove both.
    let run = judge("contact.ron", "sm-pcf", &[], SIZE);
    for light in 0..run.loaded.lights.len() {
        let m = run.metrics(light);
        run.assert_bounds(
            light,
            &m,
            &[(Metric::FalseShadow, 0.005), (Metric::FalseLitCore, 0.002)],
        );
    }
}

#[test]
fn error_falls_as_the_map_grows() {
    // Hard filtering so resolution alone decides the edges.
    let errors: Vec<f64> = [512, 1024, 2048]
        .iter()
        .map(|size| {
            let s = size.to_string();
            let run = judge(
                "planar-room.ron",
                "sm-pcf",
                &[("map_size", &s), ("filter", "None")],
                SIZE,
            );
            (0..run.loaded.lights.len())
                .map(|l| {
                    let m = run.metrics(l);
                    m.false_shadow + m.false_lit
                })
                .sum()
        })
        .collect();
    eprintln!("false_shadow + false_lit at 512, 1024, 2048: {errors:?}");
    assert!(
        errors[0] > errors[1] && errors[1] > errors[2],
        "not monotone: {errors:?}"
    );
}

#[test]
fn pcss_matches_the_area_reference() {
    // planar-room's lights have radii 0.25, 0.2 and a 0.27-degree sun.
    let run = judge("planar-room.ron", "sm-pcf", &[("filter", "Pcss")], SIZE);
    let hard = judge("planar-room.ron", "sm-pcf", &[("filter", "None")], SIZE);
    for light in 0..run.loaded.lights.len() {
        let m = run.metrics(light);
        eprintln!(
            "PCSS light {light}: mae {} (hard filtering: {})",
            m.mae,
            hard.metrics(light).mae
        );
        run.assert_bounds(light, &m, &[(Metric::Mae, 0.08)]);
    }
}

#[test]
fn pcss_follows_a_large_light_better_than_hard_shadows() {
    let scene = planar_room_with(
        "planar-room-large-light",
        "Point(position: (2.5, 6.5, 3.0), intensity: 40, range: 30, radius: 0.8)",
    );
    let pcss = judge_scene(scene.clone(), "sm-pcf", &[("filter", "Pcss")], SIZE);
    let hard = judge_scene(scene, "sm-pcf", &[("filter", "None")], SIZE);
    let (soft, sharp) = (pcss.metrics(0), hard.metrics(0));
    eprintln!(
        "radius 0.8: PCSS mae {} p95 {}, hard mae {} p95 {}",
        soft.mae, soft.p95_error, sharp.mae, sharp.p95_error
    );
    pcss.assert_bounds(0, &soft, &[(Metric::Mae, 0.08)]);
    assert!(
        soft.mae < sharp.mae,
        "PCSS {} is no closer to the area light than hard {}",
        soft.mae,
        sharp.mae
    );
}

/// Shadow-map ray tracing against PCSS on the same map: on `soft` (a large light over casters
/// from contact to two metres up) and `wall-lamps` (four lamps on a room's walls) its error is
/// at most 0.8 of PCSS's, the bound of the virtual-maps issue (measured 0.0054 against 0.0104
/// and 0.0055 against 0.0093).
#[test]
fn smrt_follows_area_lights_closer_than_pcss() {
    for scene in ["soft.ron", "wall-lamps.ron"] {
        let smrt = judge(scene, "sm-pcf", &[("filter", "Smrt")], SIZE).mean_mae();
        let pcss = judge(scene, "sm-pcf", &[("filter", "Pcss")], SIZE).mean_mae();
        eprintln!("{scene}: SMRT mae {smrt:.5}, PCSS {pcss:.5}");
        assert!(
            smrt <= 0.8 * pcss,
            "{scene}: SMRT mae {smrt} is not within 0.8 of PCSS's {pcss}"
        );
    }
}

#[test]
fn every_filter_mode_renders_within_bounds() {
    for filter in [
        "None",
        "Hardware2x2",
        "Pcf3x3",
        "Pcf5x5",
        "Pcf7x7",
        "Pcf9x9",
        "Poisson",
        "Pcss",
        "Stochastic",
        "Smrt",
    ] {
        let run = judge(
            "curved.ron",
            "sm-pcf",
            &[("filter", filter)],
            UVec2::new(128, 128),
        );
        for light in 0..run.loaded.lights.len() {
            let m = run.metrics(light);
            assert!(
                m.false_shadow_core <= 0.01 && m.false_lit_core <= 0.02,
                "{filter}, light {light}: {m:?}"
            );
        }
    }
}

#[test]
fn many_lights_share_slots_without_clobbering_each_other() {
    let run = judge("many-lights.ron", "sm-pcf", &[], UVec2::new(128, 128));
    assert_eq!(run.loaded.lights.len(), 64);
    let slots = run.judged.slot_count;
    assert!(slots < 64, "lights were not packed ({slots} slots)");
    eprintln!("64 lights in {slots} visibility slots");
    for light in 0..64 {
        let m = run.metrics(light);
        run.assert_bounds(
            light,
            &m,
            &[
                (Metric::FalseShadowCore, 0.01),
                (Metric::FalseLitCore, 0.01),
            ],
        );
    }
}

/// sconce-corridor's lamp 2 (radius 0.2 m, 0.4 m from the wall) has a floor-to-ceiling pillar
/// 0.35 m from it: rays from metres of wall graze the pillar, so it hides part of the lamp from
/// a long strip of wall at grazing incidence. One average blocker depth cannot describe that
/// penumbra (it is wider than any search the map can afford: larger searches measured worse
/// everywhere, 0.052 here at 20 times the radius): measured 0.069, where hard shadows score
/// 0.073. The bound holds PCSS below hard shadows there.
const PILLAR_BESIDE_A_LAMP: (&str, usize, f64) = ("sconce-corridor.ron", 2, 0.072);

#[test]
fn pcss_near_walls_matches_the_area_reference() {
    // The blocker search and the kernel's taps lie on the receiver's plane: a wall right
    // behind a light (0.2 to 0.5 m) is never its own blocker.
    let lights = assert_soft_near_walls(
        "sm-pcf",
        &[("filter", "Pcss")],
        0.03,
        &[PILLAR_BESIDE_A_LAMP],
    );
    assert_eq!(lights, 13);
}

/// Contact shadows where the map loses thin shadows (256² maps, normal offset 4 texels, on
/// `thin-casters`: wires whose shadows on the ground are one or two pixels wide): the march
/// finds the wires in the depth buffer and closes false-lit pixels sm-pcf leaves, and adds
/// little false shadow off the edges there or on `contact` (measured at 256²: sun false_lit
/// 0.0199 -> 0.0130; false_shadow_core at most +0.0003 on either scene).
#[test]
fn contact_shadows_close_thin_shadows_small_maps_miss() {
    let settings = [("map_size", "256"), ("normal_offset", "4")];
    for scene in ["thin-casters.ron", "contact.ron"] {
        let maps = judge(scene, "sm-pcf", &settings, SIZE);
        let contact = judge(scene, "contact-shadows", &settings, SIZE);
        for light in 0..maps.loaded.lights.len() {
            let (m, c) = (maps.metrics(light), contact.metrics(light));
            eprintln!("{scene} light {light}: sm-pcf {m:?}\n  contact-shadows {c:?}");
            assert!(c.false_lit <= m.false_lit + 1e-4, "{scene} light {light}");
            assert!(c.false_shadow_core <= m.false_shadow_core + 0.0005);
        }
        if scene == "thin-casters.ron" {
            let sun = 1;
            assert_eq!(
                maps.loaded.lights[sun].kind,
                zoo_host::LightKind::Directional
            );
            assert!(contact.metrics(sun).false_lit <= 0.75 * maps.metrics(sun).false_lit);
        }
    }
}

/// Stochastic PCF: four taps a pixel on the Poisson disc's area, moved every frame, judged
/// beside the 32-tap Poisson disc of the same radius and the 5x5 grid (1024² maps, a disc of 4
/// texels, so the kernels shape the penumbrae). One frame keeps sm-pcf's core bounds and the
/// Poisson kernel's mae within 0.005; the mean of 16 frames converges on the Poisson kernel
/// (the disc both estimate: its gap at most half of one frame's) with its mae.
#[test]
fn stochastic_pcf_averages_to_the_poisson_kernel() {
    let size = UVec2::new(128, 128);
    let with = |filter| {
        [
            ("map_size", "1024"),
            ("kernel_radius", "4"),
            ("filter", filter),
        ]
    };
    for scene in ["soft.ron", "planar-room.ron"] {
        let grid = judge(scene, "sm-pcf", &with("Pcf5x5"), size);
        let poisson = judge(scene, "sm-pcf", &with("Poisson"), size);
        let one = judge(scene, "sm-pcf", &with("Stochastic"), size);
        let frames = mean_visibility(&one.loaded, &with("Stochastic"), size, 16);
        for light in 0..one.loaded.lights.len() {
            let (g, p, s) = (
                grid.metrics(light),
                poisson.metrics(light),
                one.metrics(light),
            );
            let reference = &one.reference.lights[light];
            let mean = zoo_host::judge::Metrics::compute(
                reference,
                &frames.mean[light],
                size.x as usize,
                size.y as usize,
                None,
            );
            let poisson_visibility = &poisson.judged.visibility[light];
            let single_gap = mean_gap(&one.judged.visibility[light], poisson_visibility);
            let mean_gap = mean_gap(&frames.mean[light], poisson_visibility);
            eprintln!(
                "{scene} light {light}: mae 5x5 {:.4}, Poisson {:.4}, stochastic one frame {:.4} (core {:.4}/{:.4}), mean of 16 {:.4}; gap to Poisson {single_gap:.4} -> {mean_gap:.4}; {} pixels change between frames",
                g.mae,
                p.mae,
                s.mae,
                s.false_shadow_core,
                s.false_lit_core,
                mean.mae,
                frames.changed[light]
            );
            one.assert_bounds(
                light,
                &s,
                &[
                    (Metric::FalseShadowCore, 0.005),
                    (Metric::FalseLitCore, 0.01),
                    (Metric::Mae, p.mae + 0.005),
                ],
            );
            assert!(
                frames.changed[light] > 0,
                "{scene} light {light}: no tap moved"
            );
            assert!(
                mean_gap <= 0.5 * single_gap,
                "{scene} light {light}: the mean of frames does not converge"
            );
            assert!(
                mean.mae <= p.mae + 0.001,
                "{scene} light {light}: mean mae {}",
                mean.mae
            );
        }
    }
}

/// Per light: the mean visibility of `count` consecutive frames and the pixels whose
/// visibility differs between the first two.
struct Frames {
    mean: Vec<Vec<f32>>,
    changed: Vec<usize>,
}

/// Renders `count` frames of sm-pcf with `params` on `scene` and averages each light's
/// visibility.
fn mean_visibility(
    scene: &zoo_host::Scene,
    params: &[(&str, &str)],
    size: UVec2,
    count: usize,
) -> Frames {
    let schema = (zoo_host::find_technique("sm-pcf").unwrap().params)();
    let mut values = zoo_host::params::defaults(&schema);
    let assignments: Vec<_> = (params.iter())
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    zoo_host::params::apply_assignments(&schema, &mut values, &assignments).unwrap();
    let mut renderer =
        zoo_host::Renderer::new(zoo_host::test_support::gpu(), scene.clone(), size).unwrap();
    renderer.set_technique("sm-pcf", &values).unwrap();
    let lights = scene.lights.len();
    let mut mean = vec![vec![0.0; (size.x * size.y) as usize]; lights];
    let mut first = Vec::new();
    let mut changed = vec![0; lights];
    for frame in 0..count {
        renderer.render(&zoo_host::View::Final).unwrap();
        for (light, sum) in mean.iter_mut().enumerate() {
            let visibility = renderer.read_visibility(light);
            match frame {
                0 => first.push(visibility.clone()),
                1 => {
                    changed[light] = (visibility.iter().zip(&first[light]))
                        .filter(|(a, b)| a != b)
                        .count()
                }
                _ => {}
            }
            for (s, v) in sum.iter_mut().zip(visibility) {
                *s += v / count as f32;
            }
        }
    }
    Frames { mean, changed }
}

/// Mean absolute difference of two visibility images.
fn mean_gap(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| f64::from((x - y).abs()))
        .sum::<f64>()
        / a.len() as f64
}

/// Grid kernels odd and even (seed 000's 4x4, 8x8 and 16x16; seed 001's 11x11 and 23x23, its
/// Table 1; 5x5 to 9x9 are judged elsewhere), on planar-room with 512² maps: each keeps
/// sm-pcf's core bounds, and the penumbra (the light's pixels neither wholly lit nor wholly
/// shadowed) widens with the kernel, 23x23's several times 3x3's (measured: 0.019, 0.026, 0.054,
/// 0.076, 0.109, 0.158).
#[test]
fn grid_kernels_of_every_size_widen_the_penumbra_within_bounds() {
    let kernels = [3, 4, 8, 11, 16, 23];
    let mut penumbrae = Vec::new();
    for n in kernels {
        let filter = format!("Pcf{n}x{n}");
        let settings = [("filter", filter.as_str()), ("map_size", "512")];
        let run = judge("planar-room.ron", "sm-pcf", &settings, UVec2::new(128, 128));
        run.assert_core_bounds(0.01, 0.02);
        let (mut partial, mut pixels) = (0usize, 0usize);
        for (light, visibility) in run.judged.visibility.iter().enumerate() {
            let reaches = &run.reference.lights[light].contributing;
            for (v, _) in visibility.iter().zip(reaches).filter(|(_, c)| **c) {
                pixels += 1;
                partial += usize::from(*v > 0.02 && *v < 0.98);
            }
        }
        penumbrae.push(partial as f64 / pixels as f64);
    }
    eprintln!("penumbra fractions for {kernels:?}: {penumbrae:.4?}");
    assert!(
        penumbrae.windows(2).all(|w| w[1] >= w[0]),
        "{kernels:?}: {penumbrae:?}"
    );
    assert!(penumbrae[5] > 3.0 * penumbrae[0], "{penumbrae:?}");
}
