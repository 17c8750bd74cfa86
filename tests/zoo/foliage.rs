//! Alpha-tested casters: the foliage scene's generated textures and models (a glTF hedge, an
//! OBJ + MTL trellis), its masks in the G-buffer and the shadow-map depth passes, and every
//! technique judged on it.

use std::path::PathBuf;

use glam::{UVec2, Vec3};
use zoo_host::scene::gltf_writer::{DocumentSpec, MaterialSpec, MeshSpec, NodeSpec};
use zoo_host::scene::mesh::{MeshData, cuboid};
use zoo_host::test_support::{judge, workspace_root};

/// Texels a side of the generated textures.
const SIDE: u32 = 128;

/// The scene's generated textures: (file under `scenes/textures/`, image).
fn generated() -> Vec<(&'static str, image::RgbaImage)> {
    let unit = |v: u32| (v as f32 + 0.5) / SIDE as f32;
    // Five vertical planks, 0.12 of the width each, with gaps between them.
    let fence = image::RgbaImage::from_fn(SIDE, SIDE, |x, _| {
        let plank = (unit(x) * 5.0).fract() < 0.6;
        let grain = 150 + (x * 7 % 23) as u8;
        image::Rgba([
            grain,
            (grain as f32 * 0.75) as u8,
            90,
            if plank { 255 } else { 0 },
        ])
    });
    // Diagonal wires 0.12 of a cell wide on a diamond lattice of 8 cells a side.
    let chain = image::RgbaImage::from_fn(SIDE, SIDE, |x, y| {
        let (u, v) = (unit(x) * 8.0, unit(y) * 8.0);
        let wire = |t: f32| (t - t.round()).abs() < 0.06;
        let on = wire((u + v) * 0.5) || wire((u - v) * 0.5);
        image::Rgba([170, 175, 180, if on { 255 } else { 0 }])
    });
    // A leaf: an ellipse pointed along its axis, with a vein.
    let leaf = image::RgbaImage::from_fn(SIDE, SIDE, |x, y| {
        let (u, v) = (unit(x) * 2.0 - 1.0, unit(y) * 2.0 - 1.0);
        let width = 0.55 * (1.0 - v * v).max(0.0).sqrt() * (1.0 - 0.35 * v);
        let inside = u.abs() < width;
        let vein = u.abs() < 0.03;
        let green = if vein { 150 } else { 110 + (y % 9) as u8 * 4 };
        image::Rgba([40, green, 35, if inside { 255 } else { 0 }])
    });
    // Crossed laths 0.2 of a cell wide, two cells a side.
    let lattice = image::RgbaImage::from_fn(SIDE, SIDE, |x, y| {
        let (u, v) = (unit(x) * 2.0, unit(y) * 2.0);
        let lath = |t: f32| (t - t.round()).abs() < 0.1;
        let on = lath(u + v) || lath(u - v);
        image::Rgba([200, 185, 160, if on { 255 } else { 0 }])
    });
    vec![
        ("fence.png", fence),
        ("chain-link.png", chain),
        ("leaf.png", leaf),
        ("lattice.png", lattice),
    ]
}

/// A frond for the glTF hedge: leaflets in pairs along a stem.
fn frond() -> image::RgbaImage {
    image::RgbaImage::from_fn(SIDE / 2, SIDE / 2, |x, y| {
        let (u, v) = (
            (x as f32 + 0.5) / (SIDE / 2) as f32 * 2.0 - 1.0,
            (y as f32 + 0.5) / (SIDE / 2) as f32,
        );
        let stem = u.abs() < 0.04;
        let leaflet = ((v * 6.0).fract() - 0.5).abs() < 0.3 && u.abs() < 0.9 * (1.0 - v);
        image::Rgba([
            50,
            120 + (y % 5) as u8 * 8,
            45,
            if stem || leaflet { 255 } else { 0 },
        ])
    })
}

/// A mesh as the writer takes it.
fn mesh_spec(mesh: &MeshData, material: usize) -> MeshSpec {
    MeshSpec {
        positions: mesh.positions.iter().map(|p| p.to_array()).collect(),
        uvs: mesh.uvs.iter().map(|t| t.to_array()).collect(),
        indices: mesh.indices.clone(),
        material: Some(material),
    }
}

/// A quad standing in the XY plane, `width` by `height`, its base on y = 0.
fn standing_quad(width: f32, height: f32) -> MeshData {
    let w = width / 2.0;
    MeshData {
        positions: vec![
            Vec3::new(-w, 0.0, 0.0),
            Vec3::new(w, 0.0, 0.0),
            Vec3::new(w, height, 0.0),
            Vec3::new(-w, height, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        uvs: [(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)]
            .map(|(u, v)| glam::Vec2::new(u, v))
            .to_vec(),
        indices: vec![0, 1, 2, 0, 2, 3],
    }
}

/// The hedge: a single-sided planter under a node holding six double-sided masked fronds,
/// each turned about its own node.
fn hedge() -> Vec<u8> {
    let mut png = std::io::Cursor::new(Vec::new());
    frond().write_to(&mut png, image::ImageFormat::Png).unwrap();
    let quarter_turns = |k: f32| {
        let (s, c) = (k * std::f32::consts::FRAC_PI_4).sin_cos();
        [0.0, s, 0.0, c]
    };
    let mut nodes = vec![
        NodeSpec {
            mesh: Some(0),
            translation: [0.0, 0.2, 0.0],
            ..NodeSpec::default()
        },
        NodeSpec {
            translation: [0.0, 0.4, 0.0],
            children: (2..8).collect(),
            ..NodeSpec::default()
        },
    ];
    for i in 0..6 {
        let along = i as f32 / 5.0 - 0.5;
        nodes.push(NodeSpec {
            mesh: Some(1),
            translation: [along * 1.0, 0.0, (i % 2) as f32 * 0.1 - 0.05],
            rotation: quarter_turns(i as f32 * 0.7 - 1.5),
            scale: [1.0, 0.8 + 0.1 * (i % 3) as f32, 1.0],
            ..NodeSpec::default()
        });
    }
    DocumentSpec {
        meshes: vec![
            mesh_spec(&cuboid(Vec3::new(1.4, 0.4, 0.5)), 0),
            mesh_spec(&standing_quad(0.6, 0.9), 1),
        ],
        nodes,
        roots: vec![0, 1],
        materials: vec![
            MaterialSpec {
                name: "planter".into(),
                base_color: [0.45, 0.3, 0.25, 1.0],
                roughness: 0.8,
                ..MaterialSpec::default()
            },
            MaterialSpec {
                name: "fronds".into(),
                base_color: [0.9, 1.0, 0.9, 1.0],
                texture: Some(0),
                alpha_mode: "MASK",
                alpha_cutoff: 0.5,
                double_sided: true,
                roughness: 0.6,
                ..MaterialSpec::default()
            },
        ],
        images: vec![png.into_inner()],
        extensions_used: Vec::new(),
    }
    .to_glb()
}

/// The trellis: a lattice panel (`map_Kd` and `map_d`) between two posts of plain wood.
fn trellis() -> (String, String) {
    let mut obj = String::from("# Generated by tests/zoo/foliage.rs\nmtllib trellis.mtl\n");
    let mut base = 0;
    let mut add = |obj: &mut String, mesh: &MeshData, material: &str| {
        obj.push_str(&format!("usemtl {material}\n"));
        for p in &mesh.positions {
            obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
        }
        for t in &mesh.uvs {
            // OBJ's v runs up the image.
            obj.push_str(&format!("vt {} {}\n", t.x, 1.0 - t.y));
        }
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| base + i + 1);
            obj.push_str(&format!("f {a}/{a} {b}/{b} {c}/{c}\n"));
        }
        base += mesh.positions.len() as u32;
    };
    let mut panel =
        standing_quad(1.6, 1.6).transformed(glam::Mat4::from_translation(Vec3::Y * 0.1));
    for t in &mut panel.uvs {
        *t *= 2.0;
    }
    add(&mut obj, &panel, "lattice");
    for x in [-0.85, 0.85] {
        let post = cuboid(Vec3::new(0.08, 1.9, 0.08));
        add(
            &mut obj,
            &post.transformed(glam::Mat4::from_translation(Vec3::new(x, 0.95, 0.0))),
            "wood",
        );
    }
    let mtl = "# Generated by tests/zoo/foliage.rs
newmtl lattice
Kd 0.9 0.85 0.8
Ks 0.05 0.05 0.05
Ns 16
map_Kd ../textures/lattice.png
map_d ../textures/lattice.png
newmtl wood
Kd 0.4 0.28 0.18
Ks 0.1 0.1 0.1
Ns 24
";
    (obj, mtl.to_string())
}

/// The scene's generated model files: (file under `scenes/models/`, bytes).
fn generated_models() -> Vec<(&'static str, Vec<u8>)> {
    let (obj, mtl) = trellis();
    vec![
        ("hedge.glb", hedge()),
        ("trellis.obj", obj.into_bytes()),
        ("trellis.mtl", mtl.into_bytes()),
    ]
}

fn texture_path(file: &str) -> PathBuf {
    workspace_root().join("scenes/textures").join(file)
}

/// The committed textures and models are what the generator makes; `UPDATE_SCENE_TEXTURES=1`
/// rewrites them.
#[test]
fn the_foliage_textures_and_models_are_generated() {
    let update = std::env::var_os("UPDATE_SCENE_TEXTURES").is_some();
    let regenerate = "regenerate with UPDATE_SCENE_TEXTURES=1";
    for (file, image) in generated() {
        let path = texture_path(file);
        if update {
            image.save(&path).unwrap();
            continue;
        }
        let committed = image::open(&path)
            .unwrap_or_else(|e| panic!("{}: {e}; {regenerate}", path.display()))
            .to_rgba8();
        assert!(
            committed == image,
            "{} differs from its generator; {regenerate}",
            path.display()
        );
    }
    for (file, bytes) in generated_models() {
        let path = workspace_root().join("scenes/models").join(file);
        if update {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, &bytes).unwrap();
            continue;
        }
        let committed = std::fs::read(&path)
            .unwrap_or_else(|e| panic!("{}: {e}; {regenerate}", path.display()));
        assert!(
            committed == bytes,
            "{} differs from its generator; {regenerate}",
            path.display()
        );
    }
}

/// The masks are holes in the G-buffer: through the fence's gaps the ground shows.
#[test]
fn masked_surfaces_have_holes_where_their_masks_do() {
    let scene = zoo_host::Scene::load(&zoo_host::test_support::scene_path("foliage.ron")).unwrap();
    let masked = scene
        .objects
        .iter()
        .filter(|o| o.alpha_mask.is_some())
        .count();
    assert!(masked >= 12, "{masked} masked objects");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // The models' parts: the glTF hedge's single-sided planter and masked fronds, the OBJ
    // trellis's masked lattice and plain posts.
    let part = |name: &str| {
        let found = scene.objects.iter().find(|o| o.name == name);
        found.unwrap_or_else(|| panic!("no object {name}"))
    };
    let planter = part("hedge/planter");
    assert!(!planter.double_sided && planter.alpha_mask.is_none());
    let fronds = part("hedge/fronds");
    assert!(fronds.double_sided && fronds.albedo_texture.is_some());
    assert_eq!(fronds.alpha_mask.map(|m| m.cutoff), Some(0.5));
    assert_eq!(
        part("trellis/lattice").alpha_mask.map(|m| m.cutoff),
        Some(0.5)
    );
    assert!(part("trellis/wood").alpha_mask.is_none());
    let fence = zoo_host::test_support::scene_from_ron(
        "fence.ron",
        r#"(camera: (position: (0, 1, 4), target: (0, 1, 0), fov_y_degrees: 40),
        lights: [Directional(direction: (0, -1, -0.5))],
        objects: [
            (name: "ground", mesh: Plane(size: 40), transform: (translation: (0, 0, -2), rotation_degrees: (90, 0, 0))),
            (name: "fence", mesh: Plane(size: 2), alpha_mask: Some("textures/fence.png"),
             texture: Some("textures/fence.png"), transform: (translation: (0, 1, 0), rotation_degrees: (90, 0, 0))),
        ])"#,
    );
    let size = UVec2::new(128, 128);
    let mut renderer = zoo_host::Renderer::new(zoo_host::test_support::gpu(), fence, size).unwrap();
    renderer.render(&zoo_host::View::Final).unwrap();
    let gbuffer = renderer.read_gbuffer();
    // Along the middle row the fence (z = 0) covers 60 % of its width, and the ground (a wall
    // at z = -2) shows through the gaps.
    let row = size.y as usize / 2;
    let depths: Vec<f32> = (0..size.x as usize)
        .map(|x| gbuffer.positions[row * size.x as usize + x])
        // Where the ray through the pixel crosses the fence's plane (the camera is 4 m from it
        // and 6 m from the wall).
        .filter(|p| p.w > 0.0 && (p.x * 4.0 / (4.0 - p.z)).abs() < 0.95)
        .map(|p| p.z)
        .collect();
    let on_fence = depths.iter().filter(|z| z.abs() < 0.05).count();
    let on_ground = depths.iter().filter(|z| (**z + 2.0).abs() < 0.05).count();
    assert_eq!(on_fence + on_ground, depths.len(), "{depths:?}");
    let share = on_fence as f64 / depths.len() as f64;
    eprintln!("fence covers {share:.3} of the row");
    assert!((0.5..0.7).contains(&share), "fence share {share}");
}

/// Shadow maps with and without filtered moments keep the core error bound on the foliage
/// scene, where treating the masks as opaque shadows half of the lit ground.
#[test]
fn shadow_maps_test_alpha_on_the_foliage_scene() {
    for technique in ["sm-pcf", "vsm"] {
        let run = judge("foliage.ron", technique, &[], UVec2::new(192, 144));
        let judged = run.judged.scores.iter().filter(|s| s.metrics.is_some());
        assert_eq!(judged.count(), 2, "{technique} judges both lights");
        assert!(!run.judged.masks_opaque);
        for score in &run.judged.scores {
            let Some(m) = score.metrics else { continue };
            eprintln!(
                "{technique} light {}: core {:.4}/{:.4} mae {:.4}",
                score.light, m.false_shadow_core, m.false_lit_core, m.mae
            );
            assert!(
                m.false_shadow_core + m.false_lit_core <= 0.01,
                "{technique} light {}: {m:?}",
                score.light
            );
        }
    }
}

/// Shadow volumes cannot follow a mask: sv-zfail says so, and the judge measures what it
/// costs (the holes' light shadowed).
#[test]
fn shadow_volumes_declare_and_show_masks_as_opaque() {
    let run = judge("foliage.ron", "sv-zfail", &[], UVec2::new(192, 144));
    assert!(run.judged.masks_opaque);
    for score in &run.judged.scores {
        let m = score.metrics.expect("sv-zfail supports every light");
        eprintln!(
            "sv-zfail light {}: core {:.4}/{:.4} mae {:.4}",
            score.light, m.false_shadow_core, m.false_lit_core, m.mae
        );
        // Nothing falsely lit; the holes' light falsely shadowed.
        assert!(m.false_lit_core <= 0.001, "{m:?}");
        assert!(m.false_shadow_core > 0.005, "{m:?}");
    }
}

/// A third-party model's own texture coordinates: `spot` (from `../shared/models`, with the
/// UVs its authors laid out) masked by the lattice texture over a floor. Its shadow has the
/// mask's holes: the reference shadows clearly less of the floor than for the unmasked model,
/// ray tracing matches it exactly and shadow maps within the foliage scene's bounds.
#[test]
fn a_masked_third_party_model_casts_the_shadow_of_its_holes() {
    use zoo_host::test_support::{judge_scene, scene_from_ron, shared_models};
    let Some(models) = shared_models() else {
        return;
    };
    let spot = models.join("spot.obj");
    let scene = |mask: &str| {
        scene_from_ron(
            "masked-spot.ron",
            &format!(
                r#"(camera: (position: (0, 5.5, 3), target: (0, 0, 0)),
                    lights: [Directional(direction: (-1, -0.9, -0.2))],
                    objects: [
                        (mesh: Plane(size: 6)),
                        (mesh: Obj("{}"), transform: (translation: (1.3, 1.2, 0.3), scale: (1.5, 1.5, 1.5)){mask}),
                    ])"#,
                spot.display()
            ),
        )
    };
    let size = UVec2::new(192, 144);
    let masked = judge_scene(
        scene(r#", alpha_mask: Some("textures/lattice.png")"#),
        "rt-shadows",
        &[("rays_per_pixel", "1")],
        size,
    );
    let whole = judge_scene(scene(""), "rt-shadows", &[("rays_per_pixel", "1")], size);
    // The floor both views see (the masked model hides less of it): how much of it is in
    // the model's shadow.
    let floor = |run: &zoo_host::test_support::JudgeRun, i: usize| {
        let p = run.reference.gbuffer.positions[i];
        p.w > 0.5 && p.y.abs() < 1e-3
    };
    let common: Vec<usize> = (0..masked.reference.gbuffer.positions.len())
        .filter(|&i| floor(&masked, i) && floor(&whole, i))
        .collect();
    let shadowed = |run: &zoo_host::test_support::JudgeRun| {
        let hard = &run.reference.lights[0].hard;
        common.iter().filter(|&&i| hard[i] < 0.5).count() as f64 / common.len() as f64
    };
    let (holed, solid) = (shadowed(&masked), shadowed(&whole));
    let exact = masked.metrics(0);
    eprintln!(
        "spot: shadowed {holed:.4} masked against {solid:.4} whole; rt-shadows core {:.5}/{:.5}",
        exact.false_shadow_core, exact.false_lit_core
    );
    assert!(solid > 0.05, "the model shadows the floor ({solid})");
    assert!(holed < 0.9 * solid, "the mask's holes let light through");
    assert!(
        exact.false_shadow_core + exact.false_lit_core <= 0.0005,
        "{exact:?}"
    );
    let mapped = judge_scene(
        scene(r#", alpha_mask: Some("textures/lattice.png")"#),
        "sm-pcf",
        &[],
        size,
    );
    let m = mapped.metrics(0);
    eprintln!(
        "spot: sm-pcf core {:.5}/{:.5} mae {:.4}",
        m.false_shadow_core, m.false_lit_core, m.mae
    );
    assert!(
        m.false_shadow_core <= 0.01 && m.false_lit_core <= 0.01,
        "{m:?}"
    );
}
