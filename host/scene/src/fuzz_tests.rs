//! Seeded mutations of valid scene, OBJ + MTL and glTF files: every one loads or gives an
//! error, none panics. The counts are bounded so that the suite stays quick; a failure prints
//! the seed and the mutated file.

use std::path::{Path, PathBuf};

use crate::Scene;
use crate::gltf_writer::DocumentSpec;

/// Mutations tried per loader; `ZOO_FUZZ_MUTATIONS` sets another count for longer runs.
fn mutations() -> u64 {
    std::env::var("ZOO_FUZZ_MUTATIONS")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(2000)
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Values that stress loaders where a number stood.
const NUMBERS: [&str; 12] = [
    "-1",
    "0",
    "1",
    "3",
    "255",
    "65535",
    "4294967295",
    "1e39",
    "-1e39",
    "NaN",
    "1e-45",
    "2.5",
];

/// `input` changed in one to three ways: a byte flipped, a span deleted or repeated, a cut, or
/// a number replaced by one of [`NUMBERS`].
fn mutate(input: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut out = input.to_vec();
    for _ in 0..1 + rng.below(3) {
        if out.is_empty() {
            break;
        }
        let at = rng.below(out.len());
        let len = 1 + rng.below(16).min(out.len() - at - 1);
        match rng.below(5) {
            0 => out[at] ^= 1 << rng.below(8),
            1 => {
                out.drain(at..at + len);
            }
            2 => {
                let span = out[at..at + len].to_vec();
                out.splice(at..at, span);
            }
            3 => out.truncate(at),
            _ => {
                let digits = |b: &u8| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'e');
                let Some(start) = out[at..].iter().position(digits).map(|p| p + at) else {
                    continue;
                };
                let end = out[start..]
                    .iter()
                    .position(|b| !digits(b))
                    .map_or(out.len(), |p| p + start);
                let number = NUMBERS[rng.below(NUMBERS.len())].as_bytes().to_vec();
                out.splice(start..end, number);
            }
        }
    }
    out
}

/// Runs `load` on [`mutations`] mutations of `valid`; a panic names the seed and the input.
fn fuzz(name: &str, valid: &[u8], load: impl Fn(&[u8])) {
    load(valid);
    for seed in 1..=mutations() {
        let mut rng = Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
        let input = mutate(valid, &mut rng);
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| load(&input)));
        assert!(
            outcome.is_ok(),
            "{name}: mutation {seed} panicked on:\n{}",
            String::from_utf8_lossy(&input)
        );
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("zoo-fuzz-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A scene of every light kind, every primitive, materials, instances and paths.
const SCENE: &str = r#"(
    name: "fuzz",
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov_y_degrees: 60, near: 0.05, far: 80),
    ambient: (0.1, 0.1, 0.1),
    lights: [
        Directional(direction: (-0.3, -1, -0.2), intensity: 1.5, angular_radius_degrees: 0.5),
        Point(position: (0, 4, 0), color: (1, 0.9, 0.8), intensity: 10, range: 20, radius: 0.1),
        Spot(position: (2, 3, 2), direction: (-1, -1, -1), angle_degrees: 30, softness: 0.2, radius: 0.05),
    ],
    objects: [
        (name: "floor", mesh: Plane(size: 10, subdivisions: 2), receiver: true, texture: Some("a.png")),
        (mesh: Box(size: (1, 1, 1)), transform: (translation: (0, 0.5, 0), rotation_degrees: (0, 30, 0), scale: (1, 2, 1))),
        (mesh: Sphere(radius: 0.5, segments: 8, rings: 6), opacity: 0.5, transmission: (1, 0.5, 0.5)),
        (mesh: Cylinder(radius: 0.2, height: 1, segments: 6), alpha_mask: Some("a.png"), alpha_cutoff: 0.3),
        (mesh: Torus(major_radius: 1, minor_radius: 0.2, segments: 8, rings: 4), specular: 0.5, shininess: 16),
        (mesh: Cone(radius: 0.3, height: 0.6, segments: 5), casts_shadows: false, color: (0.2, 0.3, 0.4)),
        (mesh: Box(size: (0.2, 0.4, 0.2)), instances: [(translation: (2, 0, 0)), (rotation_degrees: (0, 45, 0), scale: (1, 2, 0.5))]),
    ],
    paths: (
        camera: [(time: 0, position: (0, 2, 5), target: (0, 0, 0)), (time: 1, position: (1, 2, 5), target: (0, 0, 0))],
        lights: [(light: 1, keys: [(time: 0, value: (0, 4, 0)), (time: 2, value: (1, 4, 0))])],
    ),
)"#;

#[test]
fn mutated_scene_files_load_or_fail_cleanly() {
    let dir = temp_dir("ron");
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 128]))
        .save(dir.join("a.png"))
        .unwrap();
    fuzz("scene", SCENE.as_bytes(), |input| {
        let text = String::from_utf8_lossy(input);
        let _ = Scene::from_ron(&text, &dir.join("fuzz.ron"), &dir);
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

const OBJ: &str = "# two materials, quads and a triangle
mtllib parts.mtl
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1
vn 0 0 1\nvn 0 1 0
v 1 2 3 0.5
l 1 2 3
o first
usemtl painted
f 1/1/1 2/2/1 3/3/1 4/4/1
g second
usemtl leaves
f 1/1 2/2 5/3
f -1/-1 -2/-2 -3/-3
s 1
";

const MTL: &str = "newmtl painted
Ka 0.1 0.1 0.1\nKd 0.5 0.25 0.125\nKs 0.1 0.3 0.2\nNs 64\nd 0.5\nillum 2\nmap_Kd a.png
newmtl leaves
Kd 1 1 1\nmap_Kd -bm 1 a.png\nmap_d -o 1 1 a.png\nTr 0.1
";

#[test]
fn mutated_obj_and_mtl_files_load_or_fail_cleanly() {
    let dir = temp_dir("obj");
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 128]))
        .save(dir.join("a.png"))
        .unwrap();
    let ron = r#"(camera: (position: (0, 0, 5), target: (0, 0, 0)),
        lights: [Point(position: (0, 3, 3))],
        objects: [(mesh: Obj("parts.obj"), alpha_cutoff: 0.25)])"#;
    let load = |dir: &Path| {
        let _ = Scene::from_ron(ron, &dir.join("obj.ron"), dir);
    };
    std::fs::write(dir.join("parts.mtl"), MTL).unwrap();
    fuzz("obj", OBJ.as_bytes(), |input| {
        std::fs::write(dir.join("parts.obj"), input).unwrap();
        load(&dir);
    });
    std::fs::write(dir.join("parts.obj"), OBJ).unwrap();
    fuzz("mtl", MTL.as_bytes(), |input| {
        std::fs::write(dir.join("parts.mtl"), input).unwrap();
        load(&dir);
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn mutated_gltf_and_glb_files_load_or_fail_cleanly() {
    let dir = temp_dir("gltf");
    let spec: DocumentSpec = crate::gltf_file::tests::document();
    let ron = r#"(camera: (position: (0, 0, 5), target: (0, 0, 0)),
        lights: [Point(position: (0, 3, 3))],
        objects: [(mesh: Gltf("model.glb"))])"#;
    fuzz("glb", &spec.to_glb(), |input| {
        std::fs::write(dir.join("model.glb"), input).unwrap();
        let _ = Scene::from_ron(ron, &dir.join("gltf.ron"), &dir);
    });
    fuzz("gltf", spec.to_gltf().as_bytes(), |input| {
        let _ = crate::gltf_file::parse_gltf(input, &dir.join("model.gltf"));
    });
    std::fs::remove_dir_all(&dir).unwrap();
}
