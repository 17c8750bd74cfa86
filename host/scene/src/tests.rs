use std::path::{Path, PathBuf};

use super::*;

const MINIMAL: &str = r#"(
    camera: (position: (0, 2, 5), target: (0, 0, 0)),
    lights: [Point(position: (0, 4, 0), intensity: 10)],
    objects: [
        (mesh: Plane(size: 10), receiver: true),
        (mesh: Box(size: (1, 1, 1)), transform: (translation: (0, 0.5, 0))),
    ],
)"#;

fn parse(text: &str) -> Result<Scene, SceneError> {
    Scene::from_ron(text, Path::new("test.ron"), Path::new("."))
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("zoo-scene-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn minimal_scene_loads() {
    let scene = parse(MINIMAL).unwrap();
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.objects.len(), 2);
    assert_eq!(scene.triangle_count(), 2 + 12);
    assert_eq!(scene.receivers.len(), 1);
    let plane = scene.receivers[0].plane;
    assert!((plane - glam::Vec4::new(0.0, 1.0, 0.0, 0.0)).length() < 1e-6);
    // The box sits on the floor.
    let (lo, hi) = scene.bounds();
    assert!((lo.y - 0.0).abs() < 1e-6 && (hi.y - 1.0).abs() < 1e-6);
    assert_eq!(scene.name, "test");
}

#[test]
fn malformed_ron_reports_line_and_column() {
    let text = "(\n    camera: (position: (0, 2, 5) target: (0, 0, 0)),\n)";
    let err = parse(text).unwrap_err();
    let SceneError::Parse { line, col, .. } = &err else {
        panic!("expected a parse error, got {err}");
    };
    assert_eq!(*line, 2);
    assert!(*col > 20, "column {col}");
    assert!(err.to_string().starts_with("test.ron:2:"), "{err}");
}

#[test]
fn unknown_fields_are_rejected_with_their_name() {
    let text = MINIMAL.replace("intensity: 10", "intensity: 10, colour: (1, 0, 0)");
    let err = parse(&text).unwrap_err().to_string();
    assert!(err.contains("colour"), "{err}");
    assert!(err.starts_with("test.ron:3:"), "{err}");
}

#[test]
fn non_finite_values_name_the_field() {
    let text = MINIMAL.replace("position: (0, 4, 0)", "position: (0, NaN, 0)");
    let err = parse(&text).unwrap_err().to_string();
    assert_eq!(
        err,
        "test.ron: lights[0].position: coordinates must be finite numbers"
    );
    let text = MINIMAL.replace("translation: (0, 0.5, 0)", "translation: (0, inf, 0)");
    let err = parse(&text).unwrap_err().to_string();
    assert!(err.contains("objects[1].transform.translation"), "{err}");
}

#[test]
fn too_many_lights_and_no_lights_are_errors() {
    let many = vec!["Point(position: (0, 4, 0))"; MAX_LIGHTS + 1].join(", ");
    let text = MINIMAL.replace("Point(position: (0, 4, 0), intensity: 10)", &many);
    let err = parse(&text).unwrap_err().to_string();
    assert!(err.contains("1025 lights given, at most 1024"), "{err}");

    let ok = vec!["Point(position: (0, 4, 0))"; 256].join(", ");
    let text = MINIMAL.replace("Point(position: (0, 4, 0), intensity: 10)", &ok);
    assert_eq!(parse(&text).unwrap().lights.len(), 256);

    let text = MINIMAL.replace("Point(position: (0, 4, 0), intensity: 10)", "");
    assert!(
        parse(&text)
            .unwrap_err()
            .to_string()
            .contains("at least one light")
    );
}

#[test]
fn bad_light_parameters_are_errors() {
    let text = MINIMAL.replace(
        "Point(position: (0, 4, 0), intensity: 10)",
        "Spot(position: (0, 4, 0), direction: (0, 0, 0))",
    );
    let err = parse(&text).unwrap_err().to_string();
    assert!(
        err.contains("lights[0].direction: must not be zero"),
        "{err}"
    );
    let text = MINIMAL.replace("intensity: 10", "intensity: 10, range: -1");
    assert!(
        parse(&text)
            .unwrap_err()
            .to_string()
            .contains("lights[0].range")
    );
}

#[test]
fn receiver_must_be_a_plane() {
    let text = MINIMAL.replace(
        "(mesh: Box(size: (1, 1, 1)),",
        "(mesh: Box(size: (1, 1, 1)), receiver: true,",
    );
    let err = parse(&text).unwrap_err().to_string();
    assert!(err.contains("objects[1].receiver: only Plane"), "{err}");
}

#[test]
fn missing_obj_names_scene_field_and_file() {
    let text = MINIMAL.replace("Box(size: (1, 1, 1))", r#"Obj("missing/bunny.obj")"#);
    let err = parse(&text).unwrap_err().to_string();
    assert!(
        err.starts_with("test.ron: objects[1].mesh: ./missing/bunny.obj: cannot read"),
        "{err}"
    );
}

#[test]
fn malformed_obj_reports_its_line() {
    let dir = temp_dir("badobj");
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 zz\nf 1 2 3\n").unwrap();
    let text = MINIMAL.replace("Box(size: (1, 1, 1))", r#"Obj("bad.obj")"#);
    let err = Scene::from_ron(&text, &dir.join("s.ron"), &dir)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bad.obj: line 3, column 7: `zz` is not a number"),
        "{err}"
    );
}

#[test]
fn obj_without_normals_and_with_quads_loads() {
    let dir = temp_dir("quadobj");
    std::fs::write(
        dir.join("quad.obj"),
        "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv 0 0 0\nf 4 3 2 1\nf 1 1 5\n",
    )
    .unwrap();
    let text = MINIMAL.replace("Box(size: (1, 1, 1))", r#"Obj("quad.obj")"#);
    let scene = Scene::from_ron(&text, &dir.join("s.ron"), &dir).unwrap();
    let object = &scene.objects[1];
    assert_eq!(
        object.indices.len(),
        6,
        "quad triangulated, degenerate face dropped"
    );
    assert!(object.report.normals_computed);
    assert_eq!(object.report.degenerate_removed, 1);
    let first = scene.mesh.indices[object.indices.start] as usize;
    assert!((scene.mesh.normals[first] - glam::Vec3::Y).length() < 1e-5);
}

#[test]
fn paths_are_validated() {
    let text = MINIMAL.replace(
        "objects: [",
        "paths: (lights: [(light: 3, keys: [(time: 0, value: (0, 1, 0))])]),\n    objects: [",
    );
    let err = parse(&text).unwrap_err().to_string();
    assert!(
        err.contains("paths.lights[0].light: light 3 does not exist"),
        "{err}"
    );
    let text = MINIMAL.replace(
        "objects: [",
        "paths: (camera: [(time: 1, position: (0, 1, 5), target: (0, 0, 0)), (time: 0, position: (0, 1, 5), target: (0, 0, 0))]),\n    objects: [",
    );
    assert!(
        parse(&text)
            .unwrap_err()
            .to_string()
            .contains("strictly increasing")
    );
}

#[test]
fn missing_scene_file_is_an_io_error() {
    let err = Scene::load(Path::new("no/such/scene.ron"))
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("no/such/scene.ron: cannot read scene"),
        "{err}"
    );
}

/// The real third-party meshes in `../shared/models` (not part of the repository).
fn shared_models() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "SKIPPED: {} is absent; the real-mesh loading test needs the shared models folder",
            dir.display()
        );
        None
    }
}

#[test]
fn real_meshes_load() {
    let Some(dir) = shared_models() else { return };
    for (file, min_triangles, open) in [
        ("stanford-bunny.obj", 60_000, true),
        ("teapot.obj", 1_000, true),
        ("suzanne.obj", 900, true),
        ("spot.obj", 5_000, false),
    ] {
        let obj = mesh::load_obj(&dir.join(file)).unwrap();
        let (mesh, report) = (obj.merged(), obj.report);
        assert!(
            mesh.triangle_count() >= min_triangles,
            "{file}: {}",
            mesh.triangle_count()
        );
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
        assert!(
            mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3),
            "{file}"
        );
        let adjacency = Adjacency::of_mesh(&mesh);
        if open {
            assert!(
                adjacency.boundary_edges() + adjacency.non_manifold_edges() > 0,
                "{file} should have open edges"
            );
        }
        eprintln!(
            "{file}: {} triangles, {} edges ({} boundary, {} non-manifold), {report:?}",
            mesh.triangle_count(),
            adjacency.edges.len(),
            adjacency.boundary_edges(),
            adjacency.non_manifold_edges()
        );
    }
}

#[test]
fn tessellation_scales_procedural_meshes() {
    let desc = parse_description(
        &MINIMAL.replace(
            "Box(size: (1, 1, 1))",
            "Sphere(radius: 1, segments: 32, rings: 16)",
        ),
        Path::new("t.ron"),
    )
    .unwrap();
    let base = Scene::from_description(&desc, Path::new("t.ron"), Path::new(".")).unwrap();
    let finer = Scene::from_description(
        &desc.with_tessellation(2.0),
        Path::new("t.ron"),
        Path::new("."),
    )
    .unwrap();
    let coarser = Scene::from_description(
        &desc.with_tessellation(0.25),
        Path::new("t.ron"),
        Path::new("."),
    )
    .unwrap();
    let sphere = |s: &Scene| s.objects[1].indices.len() / 3;
    // A UV sphere has 2 * segments * (rings - 1) triangles.
    assert_eq!(sphere(&base), 2 * 32 * 15);
    assert_eq!(sphere(&finer), 2 * 64 * 31);
    assert_eq!(sphere(&coarser), 2 * 8 * 3);
}

#[test]
fn scaling_a_scene_scales_every_length_and_keeps_angles() {
    let scene = parse(
        "(camera: (position: (0, 2, 5), target: (0, 0, 0), near: 0.1, far: 50),
          lights: [Point(position: (1, 3, 0), range: 20, radius: 0.2),
                   Directional(direction: (0, -1, 0.2), angular_radius_degrees: 0.5),
                   Spot(position: (0, 4, 0), direction: (0, -1, 0), range: 9, angle_degrees: 30, radius: 0.1)],
          objects: [(mesh: Plane(size: 4), receiver: true, transform: (translation: (0, 0.5, 0))), (mesh: Sphere(radius: 0.5), transform: (translation: (0, 1, 0)))],
          paths: (camera: [(time: 0, position: (0, 2, 5), target: (0, 0, 0))],
                  lights: [(light: 0, keys: [(time: 0, value: (1, 3, 0))]),
                           (light: 1, keys: [(time: 0, value: (0, -1, 0))])]))",
    )
    .unwrap();
    let big = scene.scaled(100.0);
    assert_eq!(big.mesh.positions.len(), scene.mesh.positions.len());
    for (a, b) in scene.mesh.positions.iter().zip(&big.mesh.positions) {
        assert_eq!(*a * 100.0, *b);
    }
    assert_eq!(big.mesh.normals, scene.mesh.normals);
    assert_eq!(big.camera.position, scene.camera.position * 100.0);
    assert_eq!((big.camera.near, big.camera.far), (10.0, 5000.0));
    assert_eq!(big.camera.fov_y, scene.camera.fov_y);
    let [point, sun, spot] = [0, 1, 2].map(|i| (scene.lights[i], big.lights[i]));
    assert_eq!(point.1.position, point.0.position * 100.0);
    assert_eq!((point.1.range, point.1.radius), (2000.0, 20.0));
    assert_eq!(sun.1.radius, sun.0.radius, "angular radius is kept");
    assert_eq!(sun.1.direction, sun.0.direction);
    assert_eq!(spot.1.spot_angle, spot.0.spot_angle);
    assert_eq!(spot.1.radius, spot.0.radius * 100.0);
    let receiver = (scene.receivers[0], big.receivers[0]);
    assert_eq!(receiver.1.plane.w, receiver.0.plane.w * 100.0);
    assert_eq!(receiver.1.corners[2], receiver.0.corners[2] * 100.0);
    assert_eq!(big.paths.camera[0].position, Vec3::new(0.0, 200.0, 500.0));
    assert_eq!(
        big.paths.lights[0].keys[0].value,
        Vec3::new(100.0, 300.0, 0.0)
    );
    assert_eq!(
        big.paths.lights[1].keys[0].value,
        Vec3::NEG_Y,
        "a direction"
    );
    let (lo, hi) = big.bounds();
    let (slo, shi) = scene.bounds();
    assert_eq!((lo, hi), (slo * 100.0, shi * 100.0));
}

/// Two quads with an MTL library: one material with a colour, specular, shininess, opacity
/// and a missing texture, one with an albedo image and an alpha mask.
const MATERIAL_OBJ: &str = "mtllib parts.mtl
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1
usemtl painted
f 1/1 2/2 3/3 4/4
v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1
usemtl leaves
f 5/1 6/2 7/3 8/4
";

const MATERIAL_MTL: &str = "newmtl painted
Kd 0.5 0.25 0.125\nKs 0.1 0.3 0.2\nNs 64\nd 0.5\nmap_Kd missing.png
newmtl leaves
Kd 1 1 1\nmap_Kd -bm 1 textures\\leaf.png\nmap_d leaf_mask.png
";

/// A bush of two OBJ parts whose materials come from its MTL library.
const BUSH_RON: &str = r#"(camera: (position: (0, 0, 5), target: (0, 0, 0)),
        lights: [Point(position: (0, 3, 3))],
        objects: [(name: "bush", mesh: Obj("parts.obj"), alpha_cutoff: 0.25)])"#;

/// A folder `name` with the bush's OBJ, MTL library, albedo texture and alpha mask.
fn material_files(name: &str) -> std::path::PathBuf {
    let dir = temp_dir(name);
    std::fs::create_dir_all(dir.join("textures")).unwrap();
    std::fs::write(dir.join("parts.obj"), MATERIAL_OBJ).unwrap();
    std::fs::write(dir.join("parts.mtl"), MATERIAL_MTL).unwrap();
    image::RgbImage::from_pixel(4, 2, image::Rgb([10, 200, 30]))
        .save(dir.join("textures/leaf.png"))
        .unwrap();
    image::GrayImage::from_fn(16, 16, |x, _| image::Luma([if x < 8 { 255 } else { 0 }]))
        .save(dir.join("leaf_mask.png"))
        .unwrap();
    dir
}

#[test]
fn obj_materials_become_object_parts_with_textures_and_masks() {
    let dir = material_files("materials");
    let scene = Scene::from_ron(BUSH_RON, &dir.join("bush.ron"), &dir).unwrap();
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["bush/painted", "bush/leaves"]);
    let (painted, leaves) = (&scene.objects[0], &scene.objects[1]);
    assert_eq!(painted.color, Vec3::new(0.5, 0.25, 0.125));
    assert_eq!(
        (painted.specular, painted.shininess, painted.opacity),
        (0.3, 64.0, 0.5)
    );
    assert_eq!(painted.alpha_mask, None);
    // The missing image is a white layer and one warning naming it.
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0].contains("missing.png"),
        "{:?}",
        scene.warnings
    );
    let mask = leaves.alpha_mask.expect("map_d masks the leaves");
    assert_eq!(mask.cutoff, 0.25);
    let albedo = leaves.albedo_texture.expect("map_Kd after its options");
    assert_eq!(scene.textures.size, 16);
    assert_eq!(
        &scene.textures.layers[albedo as usize].rgba[..4],
        &[10, 200, 30, 255]
    );
    // OBJ's v runs up the image: the quad's left half is covered, its right half a hole.
    assert_eq!(
        scene.textures.alpha(mask.layer, glam::Vec2::new(0.2, 0.5)),
        1.0
    );
    assert_eq!(
        scene.textures.alpha(mask.layer, glam::Vec2::new(0.8, 0.5)),
        0.0
    );
    assert_eq!(
        scene.mesh.uvs[scene.mesh.indices[leaves.indices.start] as usize].y,
        1.0
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn objects_may_take_their_own_fields_instead_of_the_file_s_materials() {
    let dir = material_files("own-materials");
    let own = BUSH_RON.replace(
        "alpha_cutoff: 0.25",
        "file_materials: false, color: (0.1, 0.2, 0.3)",
    );
    let scene = Scene::from_ron(&own, &dir.join("bush.ron"), &dir).unwrap();
    assert!(
        scene
            .objects
            .iter()
            .all(|o| o.color == Vec3::new(0.1, 0.2, 0.3))
    );
    assert!(scene.objects.iter().all(|o| o.alpha_mask.is_none()));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_material_library_warns_and_keeps_the_object_s_material() {
    let dir = material_files("missing-library");
    std::fs::remove_file(dir.join("parts.mtl")).unwrap();
    let scene = Scene::from_ron(BUSH_RON, &dir.join("bush.ron"), &dir).unwrap();
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].color, Vec3::splat(0.8));
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0].contains("parts.mtl"),
        "{:?}",
        scene.warnings
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_alpha_cutoffs_and_translucent_masks_name_the_field() {
    let err = parse(
        r#"(camera: (position: (0, 0, 5), target: (0, 0, 0)),
        lights: [Point(position: (0, 3, 3))],
        objects: [(mesh: Box(size: (1, 1, 1)), alpha_cutoff: 1.5)])"#,
    )
    .unwrap_err();
    assert!(err.to_string().contains("objects[0].alpha_cutoff"), "{err}");
    let err = parse(
        r#"(camera: (position: (0, 0, 5), target: (0, 0, 0)),
        lights: [Point(position: (0, 3, 3))],
        objects: [(mesh: Box(size: (1, 1, 1)), alpha_mask: Some("leaf.png"), opacity: 0.5)])"#,
    )
    .unwrap_err();
    assert!(err.to_string().contains("objects[0].opacity"), "{err}");
}

#[test]
fn more_textures_than_array_layers_is_an_error() {
    let objects: Vec<String> = (0..257)
        .map(|i| format!(r#"(mesh: Box(size: (1, 1, 1)), texture: Some("t{i}.png"))"#))
        .collect();
    let text = format!(
        r#"(camera: (position: (0, 0, 5), target: (0, 0, 0)),
        lights: [Point(position: (0, 3, 3))], objects: [{}])"#,
        objects.join(", ")
    );
    let err = parse(&text).unwrap_err();
    assert!(err.to_string().contains("257 distinct textures"), "{err}");
}

#[test]
fn gltf_objects_take_their_materials_textures_and_sides() {
    let dir = temp_dir("gltf");
    let spec = crate::gltf_file::tests::document();
    std::fs::write(dir.join("garden.glb"), spec.to_glb()).unwrap();
    // The same document as JSON, its image in a file that is missing.
    let json = spec.to_gltf();
    let start = json.find("data:image/png").unwrap();
    let end = start + json[start..].find('"').unwrap();
    let json = json.replace(&json[start..end], "leaf%20missing.png");
    std::fs::write(dir.join("garden.gltf"), json).unwrap();
    let ron = r#"(camera: (position: (0, 0, 5), target: (0, 0, 0)),
        lights: [Point(position: (0, 3, 3))],
        objects: [(name: "garden", mesh: Gltf("garden.glb"), transmission: (1, 0.5, 0.5))])"#;
    let scene = Scene::from_ron(ron, &dir.join("g.ron"), &dir).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["garden/leaves", "garden/glass", "garden/default"]);
    let [leaves, glass, default] = &scene.objects[..] else {
        unreachable!()
    };
    let mask = leaves.alpha_mask.expect("MASK is an alpha test");
    assert_eq!(mask.cutoff, 0.5 / 0.8);
    // The mask reads the albedo layer's alpha: one layer for both.
    assert_eq!(leaves.albedo_texture, Some(mask.layer));
    assert_eq!(scene.textures.layers.len(), 1);
    assert!(leaves.double_sided && !glass.double_sided && !default.double_sided);
    // The image's alpha ramps 0, 80, 160, 240 across its columns; u = 0.875 is the last.
    let alpha = scene
        .textures
        .alpha(mask.layer, glam::Vec2::new(0.875, 0.5));
    assert!((alpha - 240.0 / 255.0).abs() < 1e-6, "{alpha}");
    assert_eq!(leaves.color, Vec3::new(0.5, 1.0, 0.5));
    assert_eq!((glass.opacity, glass.alpha_mask), (0.25, None));
    assert_eq!(glass.transmittance(), Some(Vec3::new(0.75, 0.375, 0.375)));
    assert_eq!((glass.specular, default.opacity), (1.0, 1.0));

    // An image file that is missing: one warning naming it, and the leaves drawn unmasked.
    let scene = Scene::from_ron(&ron.replace(".glb", ".gltf"), &dir.join("g.ron"), &dir).unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0].contains("leaf missing.png"),
        "{:?}",
        scene.warnings
    );
    let mask = scene.objects[0].alpha_mask.unwrap();
    assert_eq!(
        scene.textures.alpha(mask.layer, glam::Vec2::splat(0.5)),
        1.0
    );

    // A malformed file: one error naming the scene, the field and the file.
    std::fs::write(dir.join("garden.glb"), b"glTF\x02\0\0\0").unwrap();
    let err = Scene::from_ron(ron, &dir.join("g.ron"), &dir).unwrap_err();
    let SceneError::Gltf { field, file, .. } = &err else {
        panic!("expected a glTF error, got {err}");
    };
    assert_eq!(
        (field.as_str(), file),
        ("objects[0].mesh", &dir.join("garden.glb"))
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

const INSTANCED: &str = r#"(
    camera: (position: (0, 4, 9), target: (0, 0, 0)),
    lights: [Directional(direction: (0.3, -1, 0.2))],
    objects: [
        (name: "floor", mesh: Plane(size: 20)),
        (name: "post", mesh: Box(size: (0.5, 2, 0.5)), transform: (translation: (0, 1, 0)),
         instances: [
            (translation: (-3, 0, 0)),
            (translation: (4, 0, 1), rotation_degrees: (0, 30, 0), scale: (1, 0.5, 2)),
            (scale: (2, 2, 2)),
         ]),
    ],
)"#;

#[test]
fn instances_share_their_triangles_and_place_them() {
    let scene = parse(INSTANCED).unwrap();
    assert_eq!(scene.objects.len(), 4);
    // The box is stored once (12 triangles) and drawn three times.
    assert_eq!(scene.triangle_count(), 2 + 12);
    assert_eq!(scene.drawn_triangle_count(), 2 + 3 * 12);
    assert_eq!(scene.triangle_summary(), "38 triangles drawn, 14 stored");
    let posts = &scene.objects[1..];
    assert!(
        posts
            .iter()
            .all(|o| o.indices == posts[0].indices && o.is_placed())
    );
    assert!(!scene.objects[0].is_placed());
    let names: Vec<&str> = posts.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["post[0]", "post[1]", "post[2]"]);
    // Stored with the object's transform; each instance places that after it.
    let (lo, hi) = crate::mesh::bounds(
        &scene
            .stored_triangles(&posts[0])
            .flatten()
            .collect::<Vec<_>>(),
    )
    .unwrap();
    assert!(lo.abs_diff_eq(Vec3::new(-0.25, 0.0, -0.25), 1e-6), "{lo}");
    assert!(hi.abs_diff_eq(Vec3::new(0.25, 2.0, 0.25), 1e-6), "{hi}");
    let world = |o: &SceneObject| {
        crate::mesh::bounds(&scene.object_triangles(o).flatten().collect::<Vec<_>>()).unwrap()
    };
    let (lo, hi) = world(&posts[0]);
    assert!(
        lo.abs_diff_eq(Vec3::new(-3.25, 0.0, -0.25), 1e-6)
            && hi.abs_diff_eq(Vec3::new(-2.75, 2.0, 0.25), 1e-6)
    );
    let (lo, hi) = world(&posts[2]);
    assert!(
        lo.abs_diff_eq(Vec3::new(-0.5, 0.0, -0.5), 1e-6)
            && hi.abs_diff_eq(Vec3::new(0.5, 4.0, 0.5), 1e-6)
    );
    // The scene's bounds hold every instance (the tallest post, 4 high).
    let (lo, hi) = scene.bounds();
    assert!(lo.y <= 0.0 && hi.y >= 4.0 - 1e-5 && lo.x <= -10.0 && hi.x >= 10.0);
    for (object, bounds) in scene.objects.iter().zip(scene.each_object_bounds()) {
        let (lo, hi) = bounds.unwrap();
        let (wlo, whi) = world(object);
        assert!(
            lo.cmple(wlo + 1e-5).all() && hi.cmpge(whi - 1e-5).all(),
            "{}",
            object.name
        );
    }
    // Instances share one edge range of the adjacency.
    let edges = &scene.adjacency.object_edges;
    assert!(edges[1] == edges[2] && edges[2] == edges[3]);
}

#[test]
fn scaling_places_instances_where_the_scaled_copies_would_be() {
    let scene = parse(INSTANCED).unwrap();
    let big = scene.scaled(250.0);
    for (small, large) in scene.objects.iter().zip(&big.objects) {
        for (a, b) in scene
            .object_triangles(small)
            .zip(big.object_triangles(large))
        {
            for (p, q) in a.iter().zip(&b) {
                assert!(
                    (*p * 250.0).abs_diff_eq(*q, 1e-3),
                    "{}: {p} {q}",
                    small.name
                );
            }
        }
    }
}

#[test]
fn bad_instances_name_the_field() {
    let mirrored = INSTANCED.replace("scale: (1, 0.5, 2)", "scale: (-1, 0.5, 2)");
    let err = parse(&mirrored).unwrap_err().to_string();
    assert!(err.contains("objects[1].instances[1].scale"), "{err}");
    assert!(err.contains("mirror"), "{err}");
    // Two negative components turn the shape half way round without mirroring it.
    let turned = INSTANCED.replace("scale: (1, 0.5, 2)", "scale: (-1, -0.5, 2)");
    assert!(parse(&turned).is_ok());
    let flat = INSTANCED.replace("(scale: (2, 2, 2))", "(scale: (2, 0, 2))");
    let err = parse(&flat).unwrap_err().to_string();
    assert!(
        err.contains("objects[1].instances[2].scale") && err.contains("non-zero"),
        "{err}"
    );
    let tiny = INSTANCED.replace("(scale: (2, 2, 2))", "(scale: (1e-20, 1e-20, 1e-20))");
    let err = parse(&tiny).unwrap_err().to_string();
    assert!(
        err.contains("objects[1].instances[2].scale") && err.contains("invert"),
        "{err}"
    );
    let infinite = INSTANCED.replace("(translation: (-3, 0, 0))", "(translation: (-3, inf, 0))");
    let err = parse(&infinite).unwrap_err().to_string();
    assert!(err.contains("objects[1].instances[0].translation"), "{err}");
    let receiver = INSTANCED.replace(
        r#"mesh: Plane(size: 20))"#,
        r#"mesh: Plane(size: 20), receiver: true, instances: [(translation: (0, 1, 0))])"#,
    );
    let err = parse(&receiver).unwrap_err().to_string();
    assert!(
        err.contains("objects[0].instances") && err.contains("receiver"),
        "{err}"
    );
    let many = format!("[{}]", vec!["()"; MAX_INSTANCES + 1].join(","));
    let crowd = INSTANCED.replace(
        r#"mesh: Plane(size: 20))"#,
        &format!("mesh: Plane(size: 20), instances: {many})"),
    );
    let err = parse(&crowd).unwrap_err().to_string();
    assert!(
        err.contains("objects[0].instances") && err.contains("65536"),
        "{err}"
    );
}
