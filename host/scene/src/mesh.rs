//! Triangle meshes: procedural primitives, OBJ loading and clean-up.

use std::f32::consts::TAU;
use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3};

/// An indexed triangle mesh with per-vertex normals and texture coordinates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position once the mesh is in a scene (missing ones are 0);
    /// (0, 0) is the image's top-left corner, and coordinates repeat outside [0, 1].
    pub uvs: Vec<Vec2>,
    /// Three indices per triangle, counter-clockwise seen from the front.
    pub indices: Vec<u32>,
}

/// What loading or cleaning a mesh changed, for the scene statistics and the log.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MeshReport {
    /// Degenerate (zero-area) triangles removed.
    pub degenerate_removed: usize,
    /// Whether normals were computed because the source had none (or unusable ones).
    pub normals_computed: bool,
    /// Faces with more than three vertices that were triangulated.
    pub polygons_triangulated: usize,
}

/// Why an OBJ file could not be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObjError {
    #[error("cannot read: {0}")]
    Io(String),
    #[error("line {line}, column {col}: {message}")]
    Syntax {
        line: usize,
        col: usize,
        message: String,
    },
    #[error("{0}")]
    Load(String),
    #[error("contains no triangles")]
    Empty,
}

impl MeshData {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Applies `m` to positions and its inverse transpose to normals.
    pub fn transformed(&self, m: Mat4) -> MeshData {
        let normal_matrix = Mat3::from_mat4(m).inverse().transpose();
        let flip = Mat3::from_mat4(m).determinant() < 0.0;
        let mut indices = self.indices.clone();
        if flip {
            // A mirroring transform reverses the winding; restore counter-clockwise fronts.
            for tri in indices.chunks_exact_mut(3) {
                tri.swap(1, 2);
            }
        }
        MeshData {
            positions: self
                .positions
                .iter()
                .map(|p| m.transform_point3(*p))
                .collect(),
            normals: self
                .normals
                .iter()
                .map(|n| (normal_matrix * *n).normalize_or_zero())
                .collect(),
            uvs: self.uvs.clone(),
            indices,
        }
    }

    /// Removes triangles whose area is negligible against the mesh's size. Returns how many.
    pub fn remove_degenerate(&mut self) -> usize {
        let extent = bounds(&self.positions)
            .map(|(lo, hi)| (hi - lo).length())
            .unwrap_or(0.0);
        let min_double_area = (extent * 1e-7).powi(2);
        let before = self.indices.len() / 3;
        let positions = &self.positions;
        let mut kept = Vec::with_capacity(self.indices.len());
        for tri in self.indices.chunks_exact(3) {
            let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| positions[i as usize]);
            let distinct = tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2];
            if distinct && (b - a).cross(c - a).length() > min_double_area {
                kept.extend_from_slice(tri);
            }
        }
        self.indices = kept;
        before - self.indices.len() / 3
    }

    /// Replaces the normals with area-weighted vertex normals.
    pub fn compute_smooth_normals(&mut self) {
        let mut normals = vec![Vec3::ZERO; self.positions.len()];
        for tri in self.indices.chunks_exact(3) {
            let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| self.positions[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in tri {
                normals[i as usize] += n;
            }
        }
        self.normals = normals
            .into_iter()
            .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
            .collect();
    }

    /// Appends `other`, offsetting its indices; texture coordinates either mesh lacks are 0.
    pub fn append(&mut self, other: &MeshData) {
        let base = self.positions.len() as u32;
        self.uvs.resize(self.positions.len(), Vec2::ZERO);
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        let other_uvs = other
            .uvs
            .iter()
            .copied()
            .chain(std::iter::repeat(Vec2::ZERO));
        self.uvs.extend(other_uvs.take(other.positions.len()));
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }
}

/// Axis-aligned bounds of `points`, or `None` if empty.
pub fn bounds(points: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *points.first()?;
    Some(
        points
            .iter()
            .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
    )
}

/// Builds indexed rings of a surface of revolution. `profile` gives (radius, y, normal radial,
/// normal y) for each ring; the seam reuses column 0 so the surface is closed after welding.
/// Texture coordinates run around (u) and up the profile (v from 1 at the first ring to 0 at
/// the last, so images stand upright); the seam's quads interpolate u back from
/// (segments - 1) / segments to 0.
fn revolve(profile: &[(f32, f32, f32, f32)], segments: u32) -> MeshData {
    let segments = segments.max(3);
    let mut mesh = MeshData::default();
    let last_ring = (profile.len().max(2) - 1) as f32;
    for (ring, &(r, y, nr, ny)) in profile.iter().enumerate() {
        for s in 0..segments {
            mesh.uvs.push(Vec2::new(
                s as f32 / segments as f32,
                1.0 - ring as f32 / last_ring,
            ));
            let angle = TAU * s as f32 / segments as f32;
            let (sin, cos) = angle.sin_cos();
            mesh.positions.push(Vec3::new(r * cos, y, -r * sin));
            mesh.normals
                .push(Vec3::new(nr * cos, ny, -nr * sin).normalize_or_zero());
        }
    }
    for ring in 0..profile.len().saturating_sub(1) as u32 {
        for s in 0..segments {
            let next = (s + 1) % segments;
            let a = ring * segments + s;
            let b = ring * segments + next;
            let c = (ring + 1) * segments + s;
            let d = (ring + 1) * segments + next;
            mesh.indices.extend_from_slice(&[a, b, d, a, d, c]);
        }
    }
    mesh
}

/// A flat disk cap at height `y` facing up (`up = true`) or down, as a fan around a centre vertex.
fn cap(radius: f32, y: f32, segments: u32, up: bool) -> MeshData {
    let segments = segments.max(3);
    let normal = if up { Vec3::Y } else { Vec3::NEG_Y };
    let mut mesh = MeshData {
        positions: vec![Vec3::new(0.0, y, 0.0)],
        normals: vec![normal],
        uvs: vec![Vec2::splat(0.5)],
        indices: Vec::new(),
    };
    for s in 0..segments {
        let angle = TAU * s as f32 / segments as f32;
        let (sin, cos) = angle.sin_cos();
        mesh.uvs.push(Vec2::new(0.5 + 0.5 * cos, 0.5 + 0.5 * sin));
        mesh.positions
            .push(Vec3::new(radius * cos, y, -radius * sin));
        mesh.normals.push(normal);
    }
    for s in 0..segments {
        let a = 1 + s;
        let b = 1 + (s + 1) % segments;
        if up {
            mesh.indices.extend_from_slice(&[0, a, b]);
        } else {
            mesh.indices.extend_from_slice(&[0, b, a]);
        }
    }
    mesh
}

/// A `size` x `size` square in the XZ plane facing +Y.
pub fn plane(size: f32, subdivisions: u32) -> MeshData {
    let n = subdivisions.max(1);
    let mut mesh = MeshData::default();
    for j in 0..=n {
        for i in 0..=n {
            let x = (i as f32 / n as f32 - 0.5) * size;
            let z = (j as f32 / n as f32 - 0.5) * size;
            mesh.positions.push(Vec3::new(x, 0.0, z));
            mesh.normals.push(Vec3::Y);
            mesh.uvs.push(Vec2::new(i as f32, j as f32) / n as f32);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            let b = a + 1;
            let c = a + n + 1;
            let d = c + 1;
            mesh.indices.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    mesh
}

/// An axis-aligned box centred at the origin with flat-shaded faces.
pub fn cuboid(size: Vec3) -> MeshData {
    let h = size * 0.5;
    let mut mesh = MeshData::default();
    // Each face: normal, and two in-plane axes u, v with u x v = normal.
    let faces = [
        (Vec3::X, Vec3::NEG_Z, Vec3::Y),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::X, Vec3::NEG_Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    for (normal, u, v) in faces {
        let base = mesh.positions.len() as u32;
        for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            mesh.positions.push((normal + u * su + v * sv) * h);
            mesh.normals.push(normal);
            mesh.uvs.push(Vec2::new(su + 1.0, 1.0 - sv) * 0.5);
        }
        mesh.indices
            .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    mesh
}

/// A UV sphere with `rings` latitude bands; the poles are single vertices (no slivers).
pub fn sphere(radius: f32, segments: u32, rings: u32) -> MeshData {
    let segments = segments.max(3);
    let rings = rings.max(2);
    let profile: Vec<_> = (1..rings)
        .map(|r| {
            let phi = std::f32::consts::PI * r as f32 / rings as f32;
            let (s, c) = phi.sin_cos();
            (radius * s, radius * c, s, c)
        })
        .rev()
        .collect();
    let mut mesh = revolve(&profile, segments);
    let ring_count = profile.len() as u32;
    let south = mesh.positions.len() as u32;
    mesh.positions.push(Vec3::new(0.0, -radius, 0.0));
    mesh.normals.push(Vec3::NEG_Y);
    mesh.uvs.push(Vec2::new(0.5, 1.0));
    let north = south + 1;
    mesh.positions.push(Vec3::new(0.0, radius, 0.0));
    mesh.normals.push(Vec3::Y);
    mesh.uvs.push(Vec2::new(0.5, 0.0));
    let top = (ring_count - 1) * segments;
    for s in 0..segments {
        let next = (s + 1) % segments;
        mesh.indices.extend_from_slice(&[south, next, s]);
        mesh.indices
            .extend_from_slice(&[north, top + s, top + next]);
    }
    mesh
}

/// A capped cylinder of the given radius from y = 0 to y = `height`.
pub fn cylinder(radius: f32, height: f32, segments: u32) -> MeshData {
    let mut mesh = revolve(
        &[(radius, 0.0, 1.0, 0.0), (radius, height, 1.0, 0.0)],
        segments,
    );
    mesh.append(&cap(radius, 0.0, segments, false));
    mesh.append(&cap(radius, height, segments, true));
    mesh
}

/// A capped cone with its base (radius `radius`) at y = 0 and its apex at y = `height`.
pub fn cone(radius: f32, height: f32, segments: u32) -> MeshData {
    let slant = Vec3::new(height, radius, 0.0).normalize_or_zero();
    let segments = segments.max(3);
    let mut mesh = revolve(&[(radius, 0.0, slant.x, slant.y)], segments);
    // Apex: one vertex per segment so each side keeps a sensible normal; they weld into one.
    let apex_base = mesh.positions.len() as u32;
    for s in 0..segments {
        let angle = TAU * (s as f32 + 0.5) / segments as f32;
        let (sin, cos) = angle.sin_cos();
        mesh.positions.push(Vec3::new(0.0, height, 0.0));
        mesh.normals
            .push(Vec3::new(slant.x * cos, slant.y, -slant.x * sin));
        mesh.uvs
            .push(Vec2::new((s as f32 + 0.5) / segments as f32, 0.0));
    }
    for s in 0..segments {
        let next = (s + 1) % segments;
        mesh.indices.extend_from_slice(&[s, next, apex_base + s]);
    }
    mesh.append(&cap(radius, 0.0, segments, false));
    mesh
}

/// A torus around the Y axis.
pub fn torus(major_radius: f32, minor_radius: f32, segments: u32, rings: u32) -> MeshData {
    let rings = rings.max(3);
    let profile: Vec<_> = (0..=rings)
        .map(|r| {
            // Reuse angle 0 for the last ring so the tube closes exactly.
            let theta = TAU * (r % rings) as f32 / rings as f32;
            let (s, c) = theta.sin_cos();
            (major_radius + minor_radius * c, minor_radius * s, c, s)
        })
        .collect();
    revolve(&profile, segments)
}

/// An OBJ file's geometry, split by material.
#[derive(Debug, Clone)]
pub struct ObjFile {
    /// One part per material (or one for faces without a material), none empty.
    pub parts: Vec<ObjPart>,
    pub report: MeshReport,
    /// Material libraries that could not be read or parsed, as messages naming them (their
    /// parts render with the object's own material).
    pub warnings: Vec<String>,
}

/// The faces of one material.
#[derive(Debug, Clone)]
pub struct ObjPart {
    pub mesh: MeshData,
    /// The material from the file's MTL library, if the faces name one it holds.
    pub material: Option<tobj::Material>,
}

impl ObjFile {
    /// Every part's geometry as one mesh.
    pub fn merged(&self) -> MeshData {
        let mut mesh = MeshData::default();
        for part in &self.parts {
            mesh.append(&part.mesh);
        }
        mesh
    }
}

/// Loads an OBJ file: faces are triangulated, missing normals computed, and the `mtllib`
/// libraries it names are read from beside it.
pub fn load_obj(path: &Path) -> Result<ObjFile, ObjError> {
    let text = crate::files::read_to_string(path).map_err(|e| ObjError::Io(e.to_string()))?;
    parse_obj(&text, path.parent())
}

/// Parses OBJ text; `library_folder` resolves its `mtllib` lines (without one, materials are
/// left out silently). See [`load_obj`].
pub fn parse_obj(text: &str, library_folder: Option<&Path>) -> Result<ObjFile, ObjError> {
    let polygons_triangulated = prevalidate_obj(text)?;
    let (models, materials, warnings) = read_obj(text, library_folder)?;
    let mut parts: Vec<ObjPart> = Vec::new();
    let mut last_material = None;
    let mut report = MeshReport {
        polygons_triangulated,
        ..MeshReport::default()
    };
    for model in &models {
        let mesh = model_mesh(&model.mesh, &mut report);
        if mesh.indices.is_empty() {
            continue;
        }
        let id = model.mesh.material_id.filter(|&id| id < materials.len());
        // Consecutive models of one material (objects and groups) make one part.
        match parts.last_mut() {
            Some(last) if last_material == Some(id) => last.mesh.append(&mesh),
            _ => parts.push(ObjPart {
                mesh,
                material: id.map(|id| materials[id].clone()),
            }),
        }
        last_material = Some(id);
    }
    if parts.is_empty() {
        return Err(ObjError::Empty);
    }
    Ok(ObjFile {
        parts,
        report,
        warnings,
    })
}

/// OBJ text as tobj reads it: its models, its libraries' materials and the warnings about
/// the libraries left out.
type ReadObj = (Vec<tobj::Model>, Vec<tobj::Material>, Vec<String>);

/// Reads OBJ text with its material libraries (from `library_folder`; a library that cannot
/// be read is left out with a warning): its models, materials and warnings.
fn read_obj(text: &str, library_folder: Option<&Path>) -> Result<ReadObj, ObjError> {
    let mut reader = std::io::Cursor::new(text.as_bytes());
    let warnings = std::cell::RefCell::new(Vec::new());
    let (models, materials) = tobj::load_obj_buf(&mut reader, &tobj::GPU_LOAD_OPTIONS, |library| {
        let Some(folder) = library_folder else {
            return Ok(Default::default());
        };
        let file = folder.join(library);
        let loaded = crate::files::read_to_string(&file)
            .map_err(|e| e.to_string())
            .and_then(|text| {
                prevalidate_mtl(&text)?;
                tobj::load_mtl_buf(&mut text.as_bytes()).map_err(|e| e.to_string())
            });
        loaded.map_err(|e| {
            (warnings.borrow_mut()).push(format!("material library {}: {e}", file.display()));
            tobj::LoadError::OpenFileFailed
        })
    })
    .map_err(|e| ObjError::Load(e.to_string()))?;
    Ok((models, materials.unwrap_or_default(), warnings.into_inner()))
}

/// One model's mesh, with its normals (computed when the file's are missing or unusable)
/// and without degenerate triangles; `report` counts what was changed.
fn model_mesh(m: &tobj::Mesh, report: &mut MeshReport) -> MeshData {
    let positions: Vec<Vec3> = m
        .positions
        .chunks_exact(3)
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    // OBJ puts v = 0 at the image's bottom row.
    let uvs = if m.texcoords.len() / 2 == positions.len() {
        m.texcoords
            .chunks_exact(2)
            .map(|t| Vec2::new(t[0], 1.0 - t[1]))
            .map(|t| if t.is_finite() { t } else { Vec2::ZERO })
            .collect()
    } else {
        vec![Vec2::ZERO; positions.len()]
    };
    let mut mesh = MeshData {
        normals: Vec::new(),
        indices: m.indices.clone(),
        positions,
        uvs,
    };
    let usable_normals = m.normals.len() == m.positions.len()
        && m.normals.chunks_exact(3).all(|n| {
            let n = Vec3::new(n[0], n[1], n[2]);
            n.is_finite() && n.length_squared() > 1e-12
        });
    if usable_normals {
        mesh.normals = m
            .normals
            .chunks_exact(3)
            .map(|n| Vec3::new(n[0], n[1], n[2]).normalize())
            .collect();
    } else {
        mesh.compute_smooth_normals();
        report.normals_computed = true;
    }
    report.degenerate_removed += mesh.remove_degenerate();
    mesh
}

/// Checks the colour statements of an MTL library, which its parser requires to hold three
/// numbers; the error names the line.
fn prevalidate_mtl(text: &str) -> Result<(), String> {
    for (line_index, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(keyword @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() else {
            continue;
        };
        if words.take(3).filter(|w| w.parse::<f32>().is_ok()).count() < 3 {
            return Err(format!(
                "line {}: {keyword} needs three numbers",
                line_index + 1
            ));
        }
    }
    Ok(())
}

/// Checks vertex coordinates and face indices line by line, so errors carry line and column.
/// Returns the number of faces with more than three vertices.
fn prevalidate_obj(text: &str) -> Result<usize, ObjError> {
    let mut vertex_count = 0i64;
    let mut texcoord_count = 0i64;
    let mut normal_count = 0i64;
    let mut polygons = 0;
    for (line_index, line) in text.lines().enumerate() {
        let syntax = |(col, message): LineError| ObjError::Syntax {
            line: line_index + 1,
            col,
            message,
        };
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        match keyword {
            "v" => {
                check_vertex(line, &words.collect::<Vec<_>>()).map_err(syntax)?;
                vertex_count += 1;
            }
            // Faces and polylines: tobj reads both with the same index rules.
            "f" | "l" => {
                let corners: Vec<&str> = words.collect();
                if keyword == "f" && corners.len() < 3 {
                    return Err(syntax((
                        line.len() + 1,
                        "face needs at least three vertices".into(),
                    )));
                }
                if keyword == "f" && corners.len() > 3 {
                    polygons += 1;
                }
                for corner in corners {
                    check_corner(corner, [vertex_count, texcoord_count, normal_count])
                        .map_err(|message| syntax((column_of(line, corner), message)))?;
                }
            }
            "vt" => texcoord_count += 1,
            "vn" => normal_count += 1,
            _ => {}
        }
    }
    Ok(polygons)
}

/// An error on one line of an OBJ file: its column (from 1) and message.
type LineError = (usize, String);

/// The column (from 1) of `word`, a slice of `line`.
fn column_of(line: &str, word: &str) -> usize {
    word.as_ptr() as usize - line.as_ptr() as usize + 1
}

/// Checks a `v` line's words (after the keyword): three finite coordinates, and an optional
/// weight that keeps them finite when it divides them.
fn check_vertex(line: &str, words: &[&str]) -> Result<(), LineError> {
    // x y z, then an optional w that divides them (or r g b, which do not).
    if let [x, y, z, w] = words[..] {
        let scaled = [x, y, z].map(|c| {
            let (c, w) = (c.parse::<f32>(), w.parse::<f32>());
            c.ok().zip(w.ok()).map(|(c, w)| c / w)
        });
        if !scaled.iter().all(|c| c.is_some_and(f32::is_finite)) {
            return Err((
                column_of(line, w),
                format!("vertex weight `{w}` gives non-finite coordinates"),
            ));
        }
    }
    if words.len() < 3 {
        return Err((line.len() + 1, "vertex needs three coordinates".into()));
    }
    for &word in &words[..3] {
        match word.parse::<f32>() {
            Ok(v) if v.is_finite() => {}
            Ok(_) => {
                return Err((
                    column_of(line, word),
                    format!("vertex coordinate `{word}` is not finite"),
                ));
            }
            Err(_) => {
                return Err((column_of(line, word), format!("`{word}` is not a number")));
            }
        }
    }
    Ok(())
}

/// Checks one corner of a face or polyline against the vertices, texture coordinates and
/// normals `defined` so far: `v`, `v/vt`, `v//vn` or `v/vt/vn`, each index counting from 1,
/// or back from the last one defined when negative.
fn check_corner(corner: &str, defined: [i64; 3]) -> Result<(), String> {
    let mut fields = corner.split('/');
    for (kind, defined) in ["vertex", "texture coordinate", "normal"]
        .into_iter()
        .zip(defined)
    {
        let text = fields.next().unwrap_or("");
        if text.is_empty() && kind != "vertex" {
            continue;
        }
        let index: i64 = text
            .parse()
            .map_err(|_| format!("`{corner}` is not a {kind} index"))?;
        let resolved = if index < 0 {
            defined.saturating_add(index).saturating_add(1)
        } else {
            index
        };
        if resolved < 1 || resolved > defined {
            return Err(format!(
                "{kind} index {index} is out of range (1..={defined} defined so far)"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closed_after_welding(mesh: &MeshData) -> bool {
        let adjacency = crate::adjacency::Adjacency::of_mesh(mesh);
        adjacency.boundary_edges() == 0 && adjacency.non_manifold_edges() == 0
    }

    #[test]
    fn primitives_are_closed_and_outward() {
        for (name, mesh) in [
            ("box", cuboid(Vec3::new(1.0, 2.0, 3.0))),
            ("sphere", sphere(1.0, 24, 12)),
            ("cylinder", cylinder(0.5, 2.0, 20)),
            ("cone", cone(0.5, 1.0, 20)),
            ("torus", torus(1.0, 0.3, 24, 12)),
        ] {
            assert!(closed_after_welding(&mesh), "{name} is not closed");
            // Outward winding: the signed volume is positive.
            let volume: f32 = mesh
                .indices
                .chunks_exact(3)
                .map(|t| {
                    let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
                    a.dot(b.cross(c)) / 6.0
                })
                .sum();
            assert!(volume > 0.0, "{name} has inward winding ({volume})");
            // Vertex normals agree with face normals.
            for t in mesh.indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
                let face = (b - a).cross(c - a).normalize();
                let n = mesh.normals[t[0] as usize];
                assert!(face.dot(n) > 0.0, "{name}: normal opposes face");
            }
        }
        let v = sphere(1.0, 64, 32);
        let volume: f32 = v
            .indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| v.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        assert!((volume - 4.18879).abs() < 0.05, "sphere volume {volume}");
    }

    #[test]
    fn plane_faces_up() {
        let p = plane(2.0, 3);
        assert_eq!(p.triangle_count(), 18);
        let t = &p.indices[0..3];
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| p.positions[i as usize]);
        assert!((b - a).cross(c - a).y > 0.0);
    }

    #[test]
    fn mirroring_transform_keeps_outward_winding() {
        let m = cuboid(Vec3::ONE).transformed(Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            assert!(face.dot(m.normals[t[0] as usize]) > 0.0);
        }
    }

    #[test]
    fn obj_quads_are_triangulated_and_normals_computed() {
        let obj = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", None).unwrap();
        let (mesh, report) = (obj.merged(), obj.report);
        assert_eq!(mesh.triangle_count(), 2);
        assert!(report.normals_computed);
        assert_eq!(report.polygons_triangulated, 1);
        assert!(mesh.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
    }

    #[test]
    fn obj_degenerate_triangles_are_removed() {
        let obj = parse_obj(
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n",
            None,
        )
        .unwrap();
        let (mesh, report) = (obj.merged(), obj.report);
        assert_eq!(mesh.triangle_count(), 1);
        assert_eq!(report.degenerate_removed, 1);
    }

    #[test]
    fn obj_errors_name_line_and_column() {
        let err = parse_obj("v 0 0 0\nv 1 nan 0\n", None).unwrap_err();
        assert_eq!(
            err,
            ObjError::Syntax {
                line: 2,
                col: 5,
                message: "vertex coordinate `nan` is not finite".into()
            }
        );
        let err = parse_obj("v 0 0 0\nv 1 x 0\n", None).unwrap_err();
        assert!(err.to_string().starts_with("line 2, column 5"), "{err}");
        let err = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", None).unwrap_err();
        assert!(
            err.to_string().contains("vertex index 7 is out of range"),
            "{err}"
        );
        assert_eq!(parse_obj("# nothing\n", None).unwrap_err(), ObjError::Empty);
        assert_eq!(
            parse_obj("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", None).unwrap_err(),
            ObjError::Empty
        );
    }
}
