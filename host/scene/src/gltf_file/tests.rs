use std::path::Path;

use glam::Vec3;

use super::*;
use crate::gltf_writer::{DocumentSpec, MaterialSpec, MeshSpec, NodeSpec};

/// A unit quad in the XZ plane facing +Y, corners at ±0.5.
fn quad(material: Option<usize>) -> MeshSpec {
    MeshSpec {
        positions: vec![
            [-0.5, 0.0, -0.5],
            [-0.5, 0.0, 0.5],
            [0.5, 0.0, 0.5],
            [0.5, 0.0, -0.5],
        ],
        uvs: vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]],
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
    }
}

fn png(image: &image::RgbaImage) -> Vec<u8> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

/// A tree of two transformed nodes under a scaled root, and a second root: a masked quad,
/// a translucent quad and a quad without a material.
pub(crate) fn document() -> DocumentSpec {
    let leaf = image::RgbaImage::from_fn(4, 4, |x, _| image::Rgba([40, 160, 40, x as u8 * 80]));
    DocumentSpec {
        meshes: vec![quad(Some(0)), quad(Some(1)), quad(None)],
        nodes: vec![
            NodeSpec {
                translation: [10.0, 0.0, 0.0],
                scale: [2.0; 3],
                children: vec![1, 2],
                ..NodeSpec::default()
            },
            NodeSpec {
                mesh: Some(0),
                translation: [0.0, 1.0, 0.0],
                ..NodeSpec::default()
            },
            NodeSpec {
                mesh: Some(1),
                // A quarter turn about X: the quad stands up, facing -Z.
                rotation: [
                    std::f32::consts::FRAC_1_SQRT_2,
                    0.0,
                    0.0,
                    std::f32::consts::FRAC_1_SQRT_2,
                ],
                ..NodeSpec::default()
            },
            NodeSpec {
                mesh: Some(2),
                translation: [0.0, -3.0, 0.0],
                ..NodeSpec::default()
            },
        ],
        roots: vec![0, 3],
        materials: vec![
            MaterialSpec {
                name: "leaves".into(),
                base_color: [0.5, 1.0, 0.5, 0.8],
                texture: Some(0),
                alpha_mode: "MASK",
                alpha_cutoff: 0.5,
                double_sided: true,
                ..MaterialSpec::default()
            },
            MaterialSpec {
                name: "glass".into(),
                base_color: [0.9, 0.9, 1.0, 0.25],
                metallic: 1.0,
                roughness: 0.2,
                alpha_mode: "BLEND",
                ..MaterialSpec::default()
            },
        ],
        images: vec![png(&leaf)],
        extensions_used: Vec::new(),
    }
}

fn bounds_of(mesh: &MeshData) -> (Vec3, Vec3) {
    crate::mesh::bounds(&mesh.positions).unwrap()
}

#[test]
fn the_node_tree_flattens_with_its_transforms_into_one_part_per_material() {
    let spec = document();
    let path = Path::new("/models/garden.glb");
    for file in [
        parse_gltf(&spec.to_glb(), path).unwrap(),
        parse_gltf(spec.to_gltf().as_bytes(), path).unwrap(),
    ] {
        assert!(file.warnings.is_empty(), "{:?}", file.warnings);
        let names: Vec<&str> = file
            .parts
            .iter()
            .map(|p| p.material.name.as_str())
            .collect();
        assert_eq!(names, ["leaves", "glass", "default"]);

        // Root: x + 10, scale 2; node 1: y + 1 before the scale.
        let (lo, hi) = bounds_of(&file.parts[0].mesh);
        assert!(lo.abs_diff_eq(Vec3::new(9.0, 2.0, -1.0), 1e-5), "{lo}");
        assert!(hi.abs_diff_eq(Vec3::new(11.0, 2.0, 1.0), 1e-5), "{hi}");
        assert!(
            file.parts[0]
                .mesh
                .normals
                .iter()
                .all(|n| n.abs_diff_eq(Vec3::Y, 1e-5))
        );
        // Node 2 stands its quad up: z becomes y, facing -Z... scaled by the root.
        let (lo, hi) = bounds_of(&file.parts[1].mesh);
        assert!(lo.abs_diff_eq(Vec3::new(9.0, -1.0, 0.0), 1e-5), "{lo}");
        assert!(hi.abs_diff_eq(Vec3::new(11.0, 1.0, 0.0), 1e-5), "{hi}");
        // The second root.
        let (lo, _) = bounds_of(&file.parts[2].mesh);
        assert!(lo.abs_diff_eq(Vec3::new(-0.5, -3.0, -0.5), 1e-5), "{lo}");

        let leaves = &file.parts[0].material;
        assert_eq!(leaves.alpha, GltfAlpha::Mask { cutoff: 0.5 / 0.8 });
        assert!(leaves.double_sided);
        assert_eq!(leaves.color, Vec3::new(0.5, 1.0, 0.5));
        let Some(ImageSource::Encoded { name, bytes }) = &leaves.texture else {
            panic!("expected an embedded image, got {:?}", leaves.texture);
        };
        assert_eq!(name, Path::new("/models/garden.glb#images[0]"));
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let glass = &file.parts[1].material;
        assert_eq!(glass.alpha, GltfAlpha::Blend { opacity: 0.25 });
        assert!(!glass.double_sided);
        assert_eq!((glass.metallic, glass.roughness), (1.0, 0.2));
        // The specification's default material.
        let default = &file.parts[2].material;
        assert_eq!(
            (default.color, default.alpha),
            (Vec3::ONE, GltfAlpha::Opaque)
        );
        assert!(!default.double_sided);
    }
}

#[test]
fn strips_and_fans_become_counter_clockwise_triangles() {
    assert_eq!(
        triangles(Mode::TriangleStrip, &[0, 1, 2, 3, 4]),
        [0, 1, 2, 2, 1, 3, 2, 3, 4]
    );
    assert_eq!(
        triangles(Mode::TriangleFan, &[0, 1, 2, 3]),
        [0, 1, 2, 0, 2, 3]
    );
    assert_eq!(triangles(Mode::Triangles, &[0, 1, 2, 3]), [0, 1, 2]);
    assert!(triangles(Mode::TriangleStrip, &[0, 1]).is_empty());
}

#[test]
fn masks_never_covered_leave_their_faces_out_with_a_warning() {
    let mut spec = document();
    spec.materials[0].alpha_cutoff = 0.9; // above the factor's 0.8: never reached
    spec.extensions_used = vec!["KHR_texture_transform".into(), "KHR_lights_punctual".into()];
    let file = parse_gltf(&spec.to_glb(), Path::new("m.glb")).unwrap();
    let names: Vec<&str> = file
        .parts
        .iter()
        .map(|p| p.material.name.as_str())
        .collect();
    assert_eq!(names, ["glass", "default"]);
    assert_eq!(
        file.warnings,
        [
            "extensions ignored: KHR_texture_transform",
            "material leaves is transparent everywhere under its alpha cutoff; its faces are left out"
        ]
    );
    // A mask without a texture is opaque where the factor reaches the cutoff.
    spec.materials[0].alpha_cutoff = 0.5;
    spec.materials[0].texture = None;
    let file = parse_gltf(&spec.to_glb(), Path::new("m.glb")).unwrap();
    let leaves = file.parts.iter().find(|p| p.material.name == "leaves");
    assert_eq!(leaves.unwrap().material.alpha, GltfAlpha::Opaque);
}

/// The error of parsing `spec`'s JSON after replacing `from` with `to` (once).
fn error_after(spec: &DocumentSpec, from: &str, to: &str) -> String {
    let json = spec.to_gltf();
    assert!(json.contains(from), "{from} not in the document");
    let json = json.replacen(from, to, 1);
    parse_gltf(json.as_bytes(), Path::new("bad.gltf"))
        .map(|f| format!("loaded {} parts", f.parts.len()))
        .unwrap_or_else(|e| e.to_string())
}

#[test]
fn malformed_files_give_one_error_naming_what_failed() {
    let spec = document();
    let err = parse_gltf(b"{\"asset\": ", Path::new("bad.gltf")).unwrap_err();
    assert_eq!(
        err.to_string(),
        "EOF while parsing a value at line 1 column 10"
    );
    assert!(parse_gltf(b"glTF\x02\0\0\0\x10\0\0\0", Path::new("bad.glb")).is_err());

    // Indices past the vertices.
    let mut bad = spec.clone();
    bad.meshes[2].indices[4] = 7;
    let err = parse_gltf(&bad.to_glb(), Path::new("bad.glb"))
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        "meshes[2].primitives[0].indices: index 7 is out of range of 4 vertices"
    );
    // An accessor longer than its view.
    let err = error_after(
        &spec,
        r#""componentType":5126,"count":4,"type":"VEC3""#,
        r#""componentType":5126,"count":40,"type":"VEC3""#,
    );
    assert_eq!(
        err,
        "meshes[0].primitives[0].POSITION: reaches past its buffer"
    );
    // Positions of the wrong type.
    let err = error_after(
        &spec,
        r#""count":4,"type":"VEC3""#,
        r#""count":4,"type":"VEC4""#,
    );
    assert!(
        err.starts_with("meshes[0].primitives[0].POSITION: Vec4 of F32"),
        "{err}"
    );
    // A stride shorter than the elements, and an offset that overflows.
    let err = error_after(
        &spec,
        r#"{"buffer":0,"byteOffset":0,"byteLength":48}"#,
        r#"{"buffer":0,"byteOffset":0,"byteLength":48,"byteStride":4}"#,
    );
    assert!(
        err.contains("stride of 4 bytes is less than its 12-byte"),
        "{err}"
    );
    let err = error_after(
        &spec,
        r#"{"bufferView":0,"componentType":5126"#,
        r#"{"bufferView":0,"byteOffset":18446744073709551615,"componentType":5126"#,
    );
    assert!(
        err.ends_with("reaches past its buffer") || err.contains("byteOffset"),
        "{err}"
    );
    // A node that is its own descendant.
    let err = error_after(&spec, r#""children":[1, 2]"#, r#""children":[1, 2, 0]"#);
    assert_eq!(err, "nodes[0]: reached twice: nodes must form trees");
    // A buffer file that is not there, and one too short.
    let err = error_after(
        &spec,
        "data:application/octet-stream;base64,",
        "missing.bin#",
    );
    assert!(
        err.starts_with("buffers[0]: ") && err.contains("missing.bin"),
        "{err}"
    );
    let glb = spec.to_glb();
    let err = parse_gltf(&glb[..glb.len() - 64], Path::new("short.glb")).unwrap_err();
    assert!(matches!(err, GltfError::Format(_)), "{err}");
}

#[test]
fn percent_escapes_decode_and_malformed_ones_stay() {
    assert_eq!(percent_decoded("leaf%20mask.png"), "leaf mask.png");
    assert_eq!(percent_decoded("100%.png"), "100%.png");
    assert_eq!(percent_decoded("%zz%4"), "%zz%4");
    assert_eq!(percent_decoded("%FF"), "\u{fffd}");
}
