//! A minimal glTF 2.0 writer for generated test scenes and the loader's own tests: triangle
//! meshes with texture coordinates, a node tree, metallic-roughness materials and PNG images,
//! as binary GLB or as JSON with everything in data URIs.

use std::fmt::Write;

/// One mesh of a single triangle-list primitive.
#[derive(Debug, Clone, Default)]
pub struct MeshSpec {
    pub positions: Vec<[f32; 3]>,
    /// Empty, or one per position.
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
    /// Index into [`DocumentSpec::materials`]; `None` for the default material.
    pub material: Option<usize>,
}

/// A node: an optional mesh under a translation, rotation (quaternion x, y, z, w) and scale.
#[derive(Debug, Clone)]
pub struct NodeSpec {
    pub mesh: Option<usize>,
    pub translation: [f32; 3],
    pub rotation: [f32; 4],
    pub scale: [f32; 3],
    pub children: Vec<usize>,
}

impl Default for NodeSpec {
    fn default() -> Self {
        Self {
            mesh: None,
            translation: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
            scale: [1.0; 3],
            children: Vec::new(),
        }
    }
}

/// A material; `alpha_mode` is `OPAQUE`, `MASK` or `BLEND`.
#[derive(Debug, Clone)]
pub struct MaterialSpec {
    pub name: String,
    pub base_color: [f32; 4],
    pub metallic: f32,
    pub roughness: f32,
    /// Index into [`DocumentSpec::images`].
    pub texture: Option<usize>,
    pub alpha_mode: &'static str,
    pub alpha_cutoff: f32,
    pub double_sided: bool,
}

impl Default for MaterialSpec {
    fn default() -> Self {
        Self {
            name: String::new(),
            base_color: [1.0; 4],
            metallic: 0.0,
            roughness: 1.0,
            texture: None,
            alpha_mode: "OPAQUE",
            alpha_cutoff: 0.5,
            double_sided: false,
        }
    }
}

/// A whole document: one scene whose roots are `roots`.
#[derive(Debug, Clone, Default)]
pub struct DocumentSpec {
    pub meshes: Vec<MeshSpec>,
    pub nodes: Vec<NodeSpec>,
    pub roots: Vec<usize>,
    pub materials: Vec<MaterialSpec>,
    /// PNG files' bytes.
    pub images: Vec<Vec<u8>>,
    pub extensions_used: Vec<String>,
}

impl DocumentSpec {
    /// The binary GLB file (images in the binary chunk).
    pub fn to_glb(&self) -> Vec<u8> {
        let (json, mut bin) = self.json_and_binary(false);
        let mut json = json.into_bytes();
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }

    /// The JSON `.gltf` file with its buffer and images as base64 data URIs.
    pub fn to_gltf(&self) -> String {
        self.json_and_binary(true).0
    }

    /// The JSON, and the binary buffer (empty when `embedded` puts it in a data URI).
    fn json_and_binary(&self, embedded: bool) -> (String, Vec<u8>) {
        let mut buffer = BinaryBuffer::default();
        let meshes: Vec<String> = (self.meshes.iter())
            .map(|mesh| buffer.add_mesh(mesh))
            .collect();
        let images: Vec<String> = self
            .images
            .iter()
            .map(|png| {
                if embedded {
                    format!(r#"{{"uri":"data:image/png;base64,{}"}}"#, base64(png))
                } else {
                    let view = buffer.add_view(png);
                    format!(r#"{{"bufferView":{view},"mimeType":"image/png"}}"#)
                }
            })
            .collect();
        let textures: Vec<String> = (0..self.images.len())
            .map(|i| format!(r#"{{"source":{i}}}"#))
            .collect();
        let materials: Vec<String> = self.materials.iter().map(material_json).collect();
        let nodes: Vec<String> = self.nodes.iter().map(node_json).collect();
        let BinaryBuffer {
            bin,
            views,
            accessors,
        } = buffer;
        let buffer = if embedded {
            format!(
                r#"{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}"#,
                bin.len(),
                base64(&bin)
            )
        } else {
            format!(r#"{{"byteLength":{}}}"#, bin.len())
        };
        let extensions = if self.extensions_used.is_empty() {
            String::new()
        } else {
            format!(r#","extensionsUsed":{:?}"#, self.extensions_used)
        };
        let json = format!(
            r#"{{"asset":{{"version":"2.0","generator":"Shadow Zoo test writer"}}{extensions},"scene":0,"scenes":[{{"nodes":{:?}}}],"nodes":[{}],"meshes":[{}],"materials":[{}],"textures":[{}],"images":[{}],"accessors":[{}],"bufferViews":[{}],"buffers":[{buffer}]}}"#,
            self.roots,
            nodes.join(","),
            meshes.join(","),
            materials.join(","),
            textures.join(","),
            images.join(","),
            accessors.join(","),
            views.join(","),
        );
        (json, if embedded { Vec::new() } else { bin })
    }
}

/// The file's one binary buffer as it is filled, with the JSON of its views and accessors.
#[derive(Default)]
struct BinaryBuffer {
    bin: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
}

impl BinaryBuffer {
    /// Appends `bytes` (4-byte aligned) as a new buffer view; returns its index.
    fn add_view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
            self.bin.len(),
            bytes.len()
        ));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// Adds an accessor's JSON; returns its index.
    fn add_accessor(&mut self, json: String) -> usize {
        self.accessors.push(json);
        self.accessors.len() - 1
    }

    /// Adds a mesh's positions, texture coordinates (if any) and indices; returns the
    /// mesh's JSON, one primitive reading them.
    fn add_mesh(&mut self, mesh: &MeshSpec) -> String {
        let floats = |values: &mut dyn Iterator<Item = f32>| -> Vec<u8> {
            values.flat_map(f32::to_le_bytes).collect()
        };
        let view = self.add_view(&floats(&mut mesh.positions.iter().flatten().copied()));
        let (lo, hi) = bounds(&mesh.positions);
        let positions = self.add_accessor(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"VEC3","min":{lo:?},"max":{hi:?}}}"#,
            mesh.positions.len()
        ));
        let mut attributes = format!(r#""POSITION":{positions}"#);
        if !mesh.uvs.is_empty() {
            let view = self.add_view(&floats(&mut mesh.uvs.iter().flatten().copied()));
            let uvs = self.add_accessor(format!(
                r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"VEC2"}}"#,
                mesh.uvs.len()
            ));
            write!(attributes, r#","TEXCOORD_0":{uvs}"#).unwrap();
        }
        let indices: Vec<u8> = mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.add_view(&indices);
        let indices = self.add_accessor(format!(
            r#"{{"bufferView":{view},"componentType":5125,"count":{},"type":"SCALAR"}}"#,
            mesh.indices.len()
        ));
        let material = mesh
            .material
            .map(|m| format!(r#","material":{m}"#))
            .unwrap_or_default();
        format!(
            r#"{{"primitives":[{{"attributes":{{{attributes}}},"indices":{indices}{material}}}]}}"#
        )
    }
}

/// The smallest and largest coordinates of `positions`.
fn bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    positions
        .iter()
        .fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
            )
        })
}

/// A material's JSON: metallic-roughness, with its base colour texture if any.
fn material_json(m: &MaterialSpec) -> String {
    let texture = m
        .texture
        .map(|t| format!(r#","baseColorTexture":{{"index":{t}}}"#))
        .unwrap_or_default();
    format!(
        r#"{{"name":"{}","pbrMetallicRoughness":{{"baseColorFactor":{:?},"metallicFactor":{:?},"roughnessFactor":{:?}{texture}}},"alphaMode":"{}","alphaCutoff":{:?},"doubleSided":{}}}"#,
        m.name, m.base_color, m.metallic, m.roughness, m.alpha_mode, m.alpha_cutoff, m.double_sided
    )
}

/// A node's JSON: its mesh if any, its transform and its children.
fn node_json(n: &NodeSpec) -> String {
    let mesh = n
        .mesh
        .map(|m| format!(r#""mesh":{m},"#))
        .unwrap_or_default();
    let children = if n.children.is_empty() {
        String::new()
    } else {
        format!(r#","children":{:?}"#, n.children)
    };
    format!(
        r#"{{{mesh}"translation":{:?},"rotation":{:?},"scale":{:?}{children}}}"#,
        n.translation, n.rotation, n.scale
    )
}

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn base64_matches_the_standard_alphabet_and_padding() {
        assert_eq!(super::base64(b""), "");
        assert_eq!(super::base64(b"f"), "Zg==");
        assert_eq!(super::base64(b"fo"), "Zm8=");
        assert_eq!(super::base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(super::base64(&[0xfb, 0xff]), "+/8=");
    }
}
