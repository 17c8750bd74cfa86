//! Ray-traced shadows against the reference judge: exact hard shadows, and soft shadows that
//! approach the area reference as rays are added.

mod fine_masks;

// Link the plugin so its technique registers.
use zoo_plugin_rt_shadows as _;

use zoo_host::glam::UVec2;
use zoo_host::params::{ParamValue, ParamValues};
use zoo_host::test_support::judge;

const SIZE: UVec2 = UVec2::new(192, 144);

/// Whether the test adapter has hardware ray queries; with `ZOO_REQUIRE_RAY_QUERY` set (as
/// `tests/ray-query-driver.sh` sets it) a missing one fails instead of skipping.
fn has_ray_queries(gpu: &zoo_host::GpuContext) -> bool {
    let has = zoo_ray_tracing::Tracer::has_ray_queries(&gpu.device);
    if !has && std::env::var_os("ZOO_REQUIRE_RAY_QUERY").is_some() {
        panic!(
            "ZOO_REQUIRE_RAY_QUERY is set but {} has no ray queries",
            gpu.describe()
        );
    }
    has
}

/// One ray to each light's centre agrees with the judge's hard visibility: the core error (the
/// one-pixel band around the reference's shadow edges left out) is at most 0.0005 of the
/// pixels each light reaches, on scenes of every kind (curved receivers, thin casters,
/// contact, alpha-masked foliage, lamps close to walls, kilometre scale, coloured glass).
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
        "translucent.ron",
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

/// Soft shadows from rays to the light's disk, one frame each: the mean error against the
/// area reference falls as rays are added, and the edge-aware filter lowers it further at a
/// few rays.
#[test]
fn soft_shadows_approach_the_area_reference_with_more_rays_and_the_filter() {
    let mae = |rays: &str, radius: &str| {
        let params = [
            ("rays_per_pixel", rays),
            ("denoise_radius", radius),
            ("accumulation", "1"),
        ];
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

/// The hierarchy's size and build time are counters (bench reports them per configuration):
/// every shadow-casting triangle once, in a hierarchy the GPU traversal can hold.
#[test]
fn the_hierarchy_is_counted() {
    use zoo_host::test_support::{counter, gpu, scene_path};
    let scene = zoo_host::Scene::load(&scene_path("planar-room.ron")).unwrap();
    let casting: usize = (scene.objects.iter())
        .filter(|o| o.casts_shadows)
        .map(|o| scene.triangle_indices(o).count())
        .sum();
    let mut renderer = zoo_host::Renderer::new(gpu(), scene, UVec2::new(64, 48)).unwrap();
    // The portable traversal, whose hierarchy is the judge's (the driver's is opaque).
    let values = ParamValues::from([("traversal".into(), ParamValue::Choice("Compute".into()))]);
    renderer.set_technique("rt-shadows", &values).unwrap();
    renderer.render(&zoo_host::View::Final).unwrap();
    let counters = renderer.wait_for_counters();
    let value = |name: &str| {
        counter(&counters, name).unwrap_or_else(|| panic!("no counter {name} in {counters:?}"))
    };
    assert_eq!(value("BVH triangles"), casting as f64);
    assert!(value("BVH nodes") >= 1.0 && value("BVH nodes") < 2.0 * casting as f64);
    assert!((1.0..64.0).contains(&value("BVH depth")));
    assert!(value("BVH build ms") > 0.0);
    assert_eq!(value("hardware ray queries"), 0.0);
}

/// Hardware ray queries give the portable traversal's answers, alpha-masked and translucent
/// casters included (visibility times the mean transmittance, as the judge scores it):
/// on every standard scene and on one without casters, one ray a light changes the visibility
/// of at most 0.0002 of the pixels (a ray through a shared edge or a corner may go either way),
/// and four rays a pixel differ by at most 0.002 on average. Skipped, with a message, on
/// adapters without ray queries.
#[test]
fn ray_queries_agree_with_the_portable_traversal() {
    use zoo_host::judging::scored_visibility;
    use zoo_host::test_support::{gpu, scene_from_ron, standard_scenes};
    use zoo_host::{Renderer, Scene, View};
    let gpu = gpu();
    if !has_ray_queries(&gpu) {
        eprintln!(
            "skipped: {} has no hardware ray queries (EXPERIMENTAL_RAY_QUERY)",
            gpu.describe()
        );
        return;
    }
    let mut scenes: Vec<Scene> = (standard_scenes().iter())
        .map(|path| Scene::load(path).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    scenes.push(scene_from_ron(
        "no-casters.ron",
        r#"(camera: (position: (0, 3, 6), target: (0, 0, 0)),
            lights: [Point(position: (0, 4, 0), radius: 0.3)],
            objects: [(mesh: Plane(size: 10), casts_shadows: false)])"#,
    ));
    let size = UVec2::new(96, 72);
    for scene in scenes {
        let name = scene.name.clone();
        let mut renderer = Renderer::new(gpu.clone(), scene, size).unwrap();
        let mut visibility = |traversal: &str, rays: i64| -> Vec<Vec<f32>> {
            let values = ParamValues::from([
                ("traversal".into(), ParamValue::Choice(traversal.into())),
                ("rays_per_pixel".into(), ParamValue::Int(rays)),
                ("denoise_radius".into(), ParamValue::Int(0)),
                ("accumulation".into(), ParamValue::Int(1)),
            ]);
            renderer.set_technique("rt-shadows", &values).unwrap();
            renderer.render(&View::Final).unwrap();
            let lights = renderer.lights().len();
            (0..lights)
                .map(|l| scored_visibility(&renderer, l).0)
                .collect()
        };
        let (portable, queried) = (visibility("Compute", 1), visibility("RayQuery", 1));
        let (portable_soft, queried_soft) = (visibility("Compute", 4), visibility("RayQuery", 4));
        let pixels = portable.iter().map(Vec::len).sum::<usize>().max(1) as f64;
        let changed = (portable.iter().flatten())
            .zip(queried.iter().flatten())
            .filter(|(a, b)| (**a < 0.5) != (**b < 0.5))
            .count() as f64
            / pixels;
        let soft_difference = (portable_soft.iter().flatten())
            .zip(queried_soft.iter().flatten())
            .map(|(a, b)| f64::from((a - b).abs()))
            .sum::<f64>()
            / pixels;
        eprintln!("{name}: hard changed {changed:.5}, soft mean difference {soft_difference:.5}");
        assert!(changed <= 0.0002, "{name}: {changed} of the pixels change");
        assert!(
            soft_difference <= 0.002,
            "{name}: soft differs by {soft_difference}"
        );
    }
}

/// Frames of a still view continue one sample sequence: sixteen frames of four unfiltered rays
/// come as close to the area reference as one frame of 64 rays.
#[test]
fn sixteen_frames_of_four_rays_match_one_frame_of_sixty_four() {
    let mae = |params: &[(&str, &str)]| {
        let run = judge("soft.ron", "rt-shadows", params, SIZE);
        let scores: Vec<_> = run.judged.scores.iter().filter_map(|s| s.metrics).collect();
        scores.iter().map(|m| m.mae).sum::<f64>() / scores.len() as f64
    };
    let unfiltered = ("denoise_radius", "0");
    let frames = mae(&[("rays_per_pixel", "4"), unfiltered, ("accumulation", "16")]);
    let rays = mae(&[("rays_per_pixel", "64"), unfiltered, ("accumulation", "1")]);
    eprintln!("soft: 16 frames of 4 rays mae {frames:.4}, one frame of 64 rays {rays:.4}");
    assert!(frames <= 1.2 * rays, "{frames} against {rays}");
}

/// The history starts again whenever the view changes, and counts the frames of a still one.
#[test]
fn a_camera_move_starts_the_accumulation_again() {
    use zoo_host::test_support::{counter, gpu, scene_path};
    let scene = zoo_host::Scene::load(&scene_path("soft.ron")).unwrap();
    let mut renderer = zoo_host::Renderer::new(gpu(), scene, UVec2::new(64, 48)).unwrap();
    renderer
        .set_technique("rt-shadows", &Default::default())
        .unwrap();
    let frames = |renderer: &zoo_host::Renderer| {
        counter(
            &renderer.technique_instance().counters(),
            "frames accumulated",
        )
    };
    for _ in 0..5 {
        renderer.render(&zoo_host::View::Final).unwrap();
    }
    assert_eq!(frames(&renderer), Some(5.0));
    let mut camera = *renderer.camera();
    camera.position.x += 0.1;
    renderer.set_camera(camera);
    renderer.render(&zoo_host::View::Final).unwrap();
    assert_eq!(frames(&renderer), Some(1.0), "a camera move starts again");
    assert_eq!(
        renderer.technique_instance().frames_to_converge(),
        16,
        "the judge waits for the default frames"
    );
}

/// Closest-hit rays: under a floating slab lit from above, every shadowed pixel of the floor has
/// its blocker distance end on the slab's surface (where the ray enters it), and every lit
/// pixel has none; from both traversals where the adapter has ray queries.
#[test]
fn blocker_distances_end_on_the_blocker() {
    use zoo_host::glam::{Vec3, Vec4Swizzles};
    use zoo_host::gpu::readback::{f16s, read_texture};
    use zoo_host::test_support::{gpu, scene_from_ron};
    use zoo_host::{Renderer, View};
    let scene = scene_from_ron(
        "slab.ron",
        r#"(camera: (position: (0, 6, 7), target: (0, 0, 0)),
            lights: [Point(position: (0.3, 5, 0.2))],
            objects: [
                (mesh: Plane(size: 10)),
                (mesh: Box(size: (2, 0.2, 2)), transform: (translation: (0, 1.5, 0))),
            ])"#,
    );
    let (slab_min, slab_max) = (Vec3::new(-1.0, 1.4, -1.0), Vec3::new(1.0, 1.6, 1.0));
    let on_slab = |p: Vec3| {
        let inside = p.cmpge(slab_min - 0.01).all() && p.cmple(slab_max + 0.01).all();
        let to_face = (p - slab_min).abs().min((p - slab_max).abs()).min_element();
        inside && to_face < 0.01
    };
    let light = Vec3::new(0.3, 5.0, 0.2);
    let gpu = gpu();
    let mut traversals = vec!["Compute"];
    if has_ray_queries(&gpu) {
        traversals.push("RayQuery");
    }
    for traversal in traversals {
        let mut renderer = Renderer::new(gpu.clone(), scene.clone(), UVec2::new(96, 72)).unwrap();
        let values = ParamValues::from([
            ("traversal".into(), ParamValue::Choice(traversal.into())),
            ("rays_per_pixel".into(), ParamValue::Int(1)),
            ("blocker_distance".into(), ParamValue::Bool(true)),
        ]);
        renderer.set_technique("rt-shadows", &values).unwrap();
        renderer.render(&View::Final).unwrap();
        let visibility = renderer.read_visibility(0);
        let gbuffer = renderer.read_gbuffer();
        let technique = renderer.technique_instance();
        let image = technique.debug_view("blocker distance").expect("traced");
        let texture = image.view.texture();
        let texels = f16s(&read_texture(
            &gpu,
            texture,
            0,
            zoo_host::wgpu::TextureAspect::All,
            8,
        ));
        let distances: Vec<f32> = texels.chunks_exact(4).map(|rgba| rgba[0]).collect();
        let (mut shadowed, mut lit) = (0, 0);
        for ((p, v), d) in gbuffer.positions.iter().zip(&visibility).zip(&distances) {
            if p.w < 0.5 || p.y.abs() > 1e-3 {
                continue; // Background, or not the floor.
            }
            let p = p.xyz();
            if *v < 0.5 {
                let end = p + (light - p).normalize() * *d;
                assert!(
                    on_slab(end),
                    "{traversal}: from {p} the blocker is {d} away, ending at {end}"
                );
                shadowed += 1;
            } else {
                assert_eq!(*d, 0.0, "{traversal}: a lit pixel at {p} has a blocker");
                lit += 1;
            }
        }
        assert!(
            shadowed > 100 && lit > 100,
            "{traversal}: {shadowed} shadowed, {lit} lit"
        );
    }
}
