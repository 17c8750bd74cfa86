//! glTF 2.0 files (`.gltf` with its buffers, or binary `.glb`): the default scene's node
//! hierarchy flattened into one mesh in the file's model space, one part per material.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use crate::image_source::ImageSource;
use crate::mesh::{MeshData, MeshReport};

/// Extensions whose absence changes nothing the zoo draws; every other one is named in a
/// warning.
const HARMLESS_EXTENSIONS: [&str; 2] = ["KHR_materials_emissive_strength", "KHR_lights_punctual"];

/// Why a glTF file could not be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GltfError {
    #[error("cannot read: {0}")]
    Io(String),
    /// The JSON, the binary container or the glTF schema is violated.
    #[error("{0}")]
    Format(String),
    /// A part of the document holds data the zoo cannot use; `what` names it
    /// (`meshes[2].primitives[0].indices`, say).
    #[error("{what}: {message}")]
    Invalid { what: String, message: String },
    #[error("contains no triangles")]
    Empty,
}

/// A glTF file's geometry, split by material.
#[derive(Debug, Clone)]
pub struct GltfFile {
    /// One part per material used (in order of first use), none empty.
    pub parts: Vec<GltfPart>,
    pub report: MeshReport,
    /// What was left out: unsupported extensions and primitive modes, unreadable images.
    pub warnings: Vec<String>,
}

/// The triangles of one material.
#[derive(Debug, Clone)]
pub struct GltfPart {
    pub mesh: MeshData,
    pub material: GltfMaterial,
}

/// A glTF metallic-roughness material as the zoo shades it.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfMaterial {
    /// The material's name, or `material N` (`default` for primitives without one).
    pub name: String,
    /// Base colour factor (linear RGB).
    pub color: Vec3,
    pub metallic: f32,
    pub roughness: f32,
    /// The base colour texture (sRGB RGB; its alpha is the coverage of masked materials).
    pub texture: Option<ImageSource>,
    pub alpha: GltfAlpha,
    /// Whether back faces are drawn (glTF's default is single-sided).
    pub double_sided: bool,
}

/// How a material's alpha is used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GltfAlpha {
    Opaque,
    /// Alpha-tested: a hole where the texture's alpha is below `cutoff` (the file's cutoff
    /// already divided by the base colour factor's alpha, so that the test reads the texture
    /// alone).
    Mask {
        cutoff: f32,
    },
    /// Translucent with the base colour factor's alpha as opacity.
    Blend {
        opacity: f32,
    },
}

/// Loads a glTF or GLB file: the default scene (or the first one, or every root node when the
/// file has no scene) with its node transforms applied; missing normals are computed.
pub fn load_gltf(path: &Path) -> Result<GltfFile, GltfError> {
    let bytes = crate::files::read(path).map_err(|e| GltfError::Io(e.to_string()))?;
    parse_gltf(&bytes, path)
}

/// Parses glTF or GLB `bytes`; `path` names the file in image keys and resolves its external
/// buffers and images. See [`load_gltf`].
pub fn parse_gltf(bytes: &[u8], path: &Path) -> Result<GltfFile, GltfError> {
    if let Some(header) = bytes.strip_prefix(b"glTF") {
        // The container's parser takes the header's length for granted.
        let length = header
            .get(4..8)
            .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]));
        if length.is_none_or(|l| l < 12) {
            return Err(GltfError::Format(
                "GLB header is shorter than 12 bytes".into(),
            ));
        }
    }
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| GltfError::Format(e.to_string()))?;
    let root = document.into_json();
    check_position_indices(&root)?;
    let document = gltf::Document::from_json(root).map_err(|e| GltfError::Format(e.to_string()))?;
    let folder = path.parent().unwrap_or(Path::new("."));
    let buffers = read_buffers(&document, folder, blob)?;
    let buffers: Vec<&[u8]> = buffers.iter().map(Vec::as_slice).collect();

    let mut warnings = Vec::new();
    let ignored: Vec<&str> = document
        .extensions_used()
        .filter(|e| !HARMLESS_EXTENSIONS.contains(e))
        .collect();
    if !ignored.is_empty() {
        warnings.push(format!("extensions ignored: {}", ignored.join(", ")));
    }

    let mut images = ImageSources::new(&document, path, folder, &buffers);
    let mut loader = Loader {
        buffers: &buffers,
        parts: Vec::new(),
        part_of_material: HashMap::new(),
        report: MeshReport::default(),
        skipped_modes: 0,
    };
    for (node, transform) in scene_nodes(&document)? {
        if let Some(mesh) = node.mesh() {
            loader.add_mesh(&mesh, transform)?;
        }
    }
    if loader.skipped_modes > 0 {
        warnings.push(format!(
            "{} point or line primitives left out (only triangles cast and receive shadows)",
            loader.skipped_modes
        ));
    }
    let mut parts = Vec::new();
    for (material_index, mesh) in loader.parts {
        let material = match material_index {
            Some(i) => document.materials().nth(i),
            None => None,
        };
        let name = material_name(material.as_ref(), material_index);
        match gltf_material(material, name.clone(), &mut images) {
            Some(material) => parts.push(GltfPart { mesh, material }),
            None => warnings.push(format!(
                "material {name} is transparent everywhere under its alpha cutoff; its faces are left out"
            )),
        }
    }
    warnings.extend(images.warnings);
    if parts.is_empty() {
        return Err(GltfError::Empty);
    }
    Ok(GltfFile {
        parts,
        report: loader.report,
        warnings,
    })
}

/// Checks that every primitive's POSITION names an accessor, which the schema's own checks
/// take for granted.
fn check_position_indices(root: &gltf::json::Root) -> Result<(), GltfError> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(index) = primitive.attributes.get(&position)
                && index.value() >= root.accessors.len()
            {
                return Err(GltfError::Invalid {
                    what: format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                    message: format!(
                        "accessor {} does not exist ({} accessors)",
                        index.value(),
                        root.accessors.len()
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Every buffer's bytes: the GLB's binary chunk, a data URI's, or a file's beside the
/// document. Each must hold at least the length the document gives it.
fn read_buffers(
    document: &gltf::Document,
    folder: &Path,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<Vec<u8>>, GltfError> {
    document
        .buffers()
        .map(|buffer| {
            let what = format!("buffers[{}]", buffer.index());
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => blob.take().ok_or_else(|| GltfError::Invalid {
                    what: what.clone(),
                    message: "refers to a binary chunk the file does not have".into(),
                }),
                gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                    gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), None)
                        .map(|d| d.0)
                        .map_err(|e| GltfError::Invalid {
                            what: what.clone(),
                            message: e.to_string(),
                        })
                }
                gltf::buffer::Source::Uri(uri) => {
                    let file = folder.join(percent_decoded(uri));
                    crate::files::read(&file).map_err(|e| GltfError::Invalid {
                        what: what.clone(),
                        message: format!("{}: {e}", file.display()),
                    })
                }
            }?;
            if data.len() < buffer.length() {
                return Err(GltfError::Invalid {
                    what,
                    message: format!(
                        "holds {} bytes, the document says {}",
                        data.len(),
                        buffer.length()
                    ),
                });
            }
            Ok(data)
        })
        .collect()
}

/// Every node of the scene to draw with its model matrix, parents before children.
fn scene_nodes<'a>(document: &'a gltf::Document) -> Result<Vec<(gltf::Node<'a>, Mat4)>, GltfError> {
    let roots: Vec<gltf::Node<'a>> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().collect(),
        None => {
            let children: HashSet<usize> = document
                .nodes()
                .flat_map(|n| n.children().map(|c| c.index()))
                .collect();
            document
                .nodes()
                .filter(|n| !children.contains(&n.index()))
                .collect()
        }
    };
    let mut out = Vec::new();
    let mut visited = HashSet::new();
    let mut stack: Vec<(gltf::Node<'a>, Mat4)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        if !visited.insert(node.index()) {
            return Err(GltfError::Invalid {
                what: format!("nodes[{}]", node.index()),
                message: "reached twice: nodes must form trees".into(),
            });
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        if !local.is_finite() {
            return Err(GltfError::Invalid {
                what: format!("nodes[{}]", node.index()),
                message: "transform is not finite".into(),
            });
        }
        let transform = parent * local;
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, transform)));
        out.push((node, transform));
    }
    Ok(out)
}

/// Gathers primitives into per-material meshes.
struct Loader<'a> {
    buffers: &'a [&'a [u8]],
    parts: Vec<(Option<usize>, MeshData)>,
    part_of_material: HashMap<Option<usize>, usize>,
    report: MeshReport,
    skipped_modes: usize,
}

impl Loader<'_> {
    fn add_mesh(&mut self, mesh: &gltf::Mesh<'_>, transform: Mat4) -> Result<(), GltfError> {
        for primitive in mesh.primitives() {
            let what = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
            let Some(local) = self.read_primitive(&primitive, &what)? else {
                self.skipped_modes += 1;
                continue;
            };
            let mut world = local.transformed(transform);
            self.report.degenerate_removed += world.remove_degenerate();
            if world.indices.is_empty() {
                continue;
            }
            let material = primitive.material().index();
            let next = self.parts.len();
            let part = *self.part_of_material.entry(material).or_insert(next);
            if part == next {
                self.parts.push((material, world));
            } else {
                self.parts[part].1.append(&world);
            }
        }
        Ok(())
    }

    /// The primitive's triangles in its mesh's space, or `None` for points and lines.
    fn read_primitive(
        &mut self,
        primitive: &gltf::Primitive<'_>,
        what: &str,
    ) -> Result<Option<MeshData>, GltfError> {
        let mode = primitive.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Ok(None);
        }
        let attributes = Attributes {
            primitive,
            buffers: self.buffers,
            what,
        };
        let positions = attributes.positions()?;
        let count = positions.len();
        let normals = attributes.normals(count)?;
        let uvs = attributes.uvs(count)?;
        let indices = triangles(mode, &attributes.index_sequence(count)?);
        let mut mesh = MeshData {
            positions,
            normals,
            uvs,
            indices,
        };
        if mesh.normals.len() != count {
            mesh.compute_smooth_normals();
            self.report.normals_computed = true;
        }
        Ok(Some(mesh))
    }
}

/// Reads and checks the vertex attributes and indices of one primitive.
struct Attributes<'a, 'p> {
    primitive: &'a gltf::Primitive<'p>,
    buffers: &'a [&'a [u8]],
    /// The primitive, as errors name it.
    what: &'a str,
}

impl Attributes<'_, '_> {
    /// An error in `attribute` of the primitive.
    fn invalid(&self, attribute: &str, message: String) -> GltfError {
        GltfError::Invalid {
            what: format!("{}.{attribute}", self.what),
            message,
        }
    }

    /// Checks the accessor of `attribute` holds `types` in `dimensions`.
    fn check(
        &self,
        accessor: &gltf::Accessor<'_>,
        types: &[DataType],
        dimensions: Dimensions,
        attribute: &str,
    ) -> Result<(), GltfError> {
        check_accessor(accessor, types, dimensions, self.buffers)
            .map_err(|m| self.invalid(attribute, m))
    }

    /// The positions, which a primitive must have, all finite.
    fn positions(&self) -> Result<Vec<Vec3>, GltfError> {
        let accessor = (self.primitive.get(&gltf::Semantic::Positions))
            .ok_or_else(|| self.invalid("attributes", "has no POSITION".into()))?;
        self.check(&accessor, &[DataType::F32], Dimensions::Vec3, "POSITION")?;
        let positions: Vec<Vec3> = (self.primitive)
            .reader(|b| self.buffers.get(b.index()).copied())
            .read_positions()
            .ok_or_else(|| self.invalid("POSITION", "cannot be read".into()))?
            .map(Vec3::from)
            .collect();
        if let Some(bad) = positions.iter().position(|p| !p.is_finite()) {
            return Err(self.invalid("POSITION", format!("vertex {bad} is not finite")));
        }
        Ok(positions)
    }

    /// The normals, normalized; none when there are not `count` of them or one is unusable.
    fn normals(&self, count: usize) -> Result<Vec<Vec3>, GltfError> {
        let Some(accessor) = self.primitive.get(&gltf::Semantic::Normals) else {
            return Ok(Vec::new());
        };
        if accessor.count() != count {
            return Ok(Vec::new());
        }
        self.check(&accessor, &[DataType::F32], Dimensions::Vec3, "NORMAL")?;
        let normals: Vec<Vec3> = (self.primitive)
            .reader(|b| self.buffers.get(b.index()).copied())
            .read_normals()
            .map(|n| n.map(Vec3::from).collect())
            .unwrap_or_default();
        let usable = normals
            .iter()
            .all(|n| n.is_finite() && n.length_squared() > 1e-12);
        Ok(if usable {
            normals.into_iter().map(Vec3::normalize).collect()
        } else {
            Vec::new()
        })
    }

    /// The first texture coordinates, `count` of them (zero where missing or not finite).
    fn uvs(&self, count: usize) -> Result<Vec<Vec2>, GltfError> {
        let uvs = match self.primitive.get(&gltf::Semantic::TexCoords(0)) {
            Some(accessor) if accessor.count() == count => {
                let types = [DataType::F32, DataType::U8, DataType::U16];
                self.check(&accessor, &types, Dimensions::Vec2, "TEXCOORD_0")?;
                (self.primitive)
                    .reader(|b| self.buffers.get(b.index()).copied())
                    .read_tex_coords(0)
                    .map(|t| t.into_f32().map(Vec2::from).collect())
                    .unwrap_or_default()
            }
            _ => Vec::new(),
        };
        Ok(if uvs.len() == count {
            uvs.into_iter()
                .map(|t: Vec2| if t.is_finite() { t } else { Vec2::ZERO })
                .collect()
        } else {
            vec![Vec2::ZERO; count]
        })
    }

    /// The vertex sequence the primitive's mode assembles (its indices, each below `count`,
    /// or every vertex in order).
    fn index_sequence(&self, count: usize) -> Result<Vec<u32>, GltfError> {
        let Some(accessor) = self.primitive.indices() else {
            return Ok((0..count as u32).collect());
        };
        let types = [DataType::U8, DataType::U16, DataType::U32];
        self.check(&accessor, &types, Dimensions::Scalar, "indices")?;
        let indices: Vec<u32> = (self.primitive)
            .reader(|b| self.buffers.get(b.index()).copied())
            .read_indices()
            .map(|i| i.into_u32().collect())
            .unwrap_or_default();
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= count) {
            return Err(self.invalid(
                "indices",
                format!("index {bad} is out of range of {count} vertices"),
            ));
        }
        Ok(indices)
    }
}

/// Triangle list indices of a triangle list, strip or fan (counter-clockwise kept).
fn triangles(mode: Mode, sequence: &[u32]) -> Vec<u32> {
    match mode {
        Mode::TriangleStrip => (0..sequence.len().saturating_sub(2))
            .flat_map(|i| {
                let [a, b, c] = [sequence[i], sequence[i + 1], sequence[i + 2]];
                if i % 2 == 0 { [a, b, c] } else { [b, a, c] }
            })
            .collect(),
        Mode::TriangleFan => (1..sequence.len().saturating_sub(1))
            .flat_map(|i| [sequence[0], sequence[i], sequence[i + 1]])
            .collect(),
        _ => sequence[..sequence.len() / 3 * 3].to_vec(),
    }
}

/// Checks that an accessor has a type the zoo reads and lies inside its buffer, so that the
/// reader neither fails silently nor reads past the data.
fn check_accessor(
    accessor: &gltf::Accessor<'_>,
    types: &[DataType],
    dimensions: Dimensions,
    buffers: &[&[u8]],
) -> Result<(), String> {
    if accessor.sparse().is_some() {
        return Err("sparse accessors are not supported".into());
    }
    if accessor.dimensions() != dimensions || !types.contains(&accessor.data_type()) {
        return Err(format!(
            "{:?} of {:?} is not a supported type",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    if accessor.count() == 0 {
        return Err("has no elements".into());
    }
    let view = accessor
        .view()
        .ok_or_else(|| "has no buffer view".to_string())?;
    let element = accessor.size();
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "its view's stride of {stride} bytes is less than its {element}-byte elements"
        ));
    }
    let end = (accessor.count() - 1)
        .checked_mul(stride)
        .and_then(|n| n.checked_add(accessor.offset()))
        .and_then(|n| n.checked_add(element));
    let data = buffers.get(view.buffer().index()).map_or(0, |b| b.len());
    let view_fits = view
        .offset()
        .checked_add(view.length())
        .is_some_and(|e| e <= data);
    match end {
        Some(end) if end <= view.length() && view_fits => Ok(()),
        _ => Err("reaches past its buffer".into()),
    }
}

fn material_name(material: Option<&gltf::Material<'_>>, index: Option<usize>) -> String {
    match (material.and_then(|m| m.name()), index) {
        (Some(name), _) => name.to_string(),
        (None, Some(i)) => format!("material {i}"),
        (None, None) => "default".into(),
    }
}

/// The zoo's reading of a glTF material, or `None` when it is transparent everywhere.
fn gltf_material(
    material: Option<gltf::Material<'_>>,
    name: String,
    images: &mut ImageSources<'_>,
) -> Option<GltfMaterial> {
    let Some(material) = material else {
        // The specification's default material: white, fully rough, metallic, single-sided.
        return Some(GltfMaterial {
            name,
            color: Vec3::ONE,
            metallic: 1.0,
            roughness: 1.0,
            texture: None,
            alpha: GltfAlpha::Opaque,
            double_sided: false,
        });
    };
    let pbr = material.pbr_metallic_roughness();
    let [r, g, b, a] = pbr.base_color_factor().map(|c| c.clamp(0.0, 1.0));
    let texture = pbr.base_color_texture().and_then(|info| {
        if info.tex_coord() != 0 {
            images.warnings.push(format!(
                "material {name}: texture coordinate set {} is not supported; set 0 is used",
                info.tex_coord()
            ));
        }
        images.source(&info.texture().source())
    });
    let alpha = match material.alpha_mode() {
        gltf::material::AlphaMode::Opaque => GltfAlpha::Opaque,
        gltf::material::AlphaMode::Blend => GltfAlpha::Blend { opacity: a },
        gltf::material::AlphaMode::Mask => {
            // Coverage is the texture's alpha times the factor's: the test reads the texture
            // against the cutoff divided by the factor.
            let cutoff = material.alpha_cutoff().unwrap_or(0.5).clamp(0.0, 1.0);
            if cutoff <= 0.0 {
                GltfAlpha::Opaque
            } else if cutoff > a {
                return None;
            } else if texture.is_some() {
                GltfAlpha::Mask { cutoff: cutoff / a }
            } else {
                GltfAlpha::Opaque
            }
        }
    };
    Some(GltfMaterial {
        name,
        color: Vec3::new(r, g, b),
        metallic: pbr.metallic_factor().clamp(0.0, 1.0),
        roughness: pbr.roughness_factor().clamp(0.0, 1.0),
        texture,
        alpha,
        double_sided: material.double_sided(),
    })
}

/// Where each image of the file comes from: its own file, or bytes inside the file.
struct ImageSources<'a> {
    document: &'a gltf::Document,
    path: &'a Path,
    folder: &'a Path,
    buffers: &'a [&'a [u8]],
    known: HashMap<usize, Option<ImageSource>>,
    warnings: Vec<String>,
}

impl<'a> ImageSources<'a> {
    fn new(
        document: &'a gltf::Document,
        path: &'a Path,
        folder: &'a Path,
        buffers: &'a [&'a [u8]],
    ) -> Self {
        Self {
            document,
            path,
            folder,
            buffers,
            known: HashMap::new(),
            warnings: Vec::new(),
        }
    }

    fn source(&mut self, image: &gltf::Image<'_>) -> Option<ImageSource> {
        if let Some(known) = self.known.get(&image.index()) {
            return known.clone();
        }
        let name = PathBuf::from(format!("{}#images[{}]", self.path.display(), image.index()));
        // The schema allows an image with neither a URI nor a view with its MIME type, which
        // the reader cannot represent.
        let json = &self.document.as_json().images[image.index()];
        let readable = match json.buffer_view {
            Some(_) => json.mime_type.is_some(),
            None => json.uri.is_some(),
        };
        let source = if !readable {
            Err("has neither a URI nor a buffer view with a MIME type".to_string())
        } else {
            match image.source() {
                gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
                    let file = percent_decoded(uri);
                    Ok(ImageSource::File(self.folder.join(file)))
                }
                gltf::image::Source::Uri { uri, .. } => {
                    let source = gltf::buffer::Source::Uri(uri);
                    gltf::buffer::Data::from_source(source, None)
                        .map(|data| ImageSource::Encoded {
                            name: name.clone(),
                            bytes: Arc::from(data.0),
                        })
                        .map_err(|e| e.to_string())
                }
                gltf::image::Source::View { view, .. } => {
                    let start = view.offset();
                    let bytes = self
                        .buffers
                        .get(view.buffer().index())
                        .and_then(|b| b.get(start..start.checked_add(view.length())?));
                    match bytes {
                        Some(bytes) => Ok(ImageSource::Encoded {
                            name: name.clone(),
                            bytes: Arc::from(bytes),
                        }),
                        None => Err("its buffer view reaches past the buffer".into()),
                    }
                }
            }
        };
        let source = source
            .map_err(|e| {
                self.warnings.push(format!(
                    "{}: {e}; the material is drawn without it",
                    name.display()
                ))
            })
            .ok();
        self.known.insert(image.index(), source.clone());
        source
    }
}

/// A URI's percent escapes (`%20`) decoded; malformed escapes are kept as written.
fn percent_decoded(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(byte)) => {
                out.push(byte);
                i += 3;
            }
            (byte, _) => {
                out.push(byte);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
pub(crate) mod tests;
