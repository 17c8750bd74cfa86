//! Triangle edge adjacency for silhouette work, built once at scene load.
//!
//! Vertices are welded by exact position within each object (normals split vertices at creases;
//! silhouettes must not see those splits). Every undirected edge lists its incident triangles with
//! the direction in which each triangle traverses it, so techniques can count face orientations
//! with multiplicity: an edge of a closed, consistently wound mesh has exactly two incident faces
//! traversing it in opposite directions ([`EdgeKind::Manifold`]); an edge with one face is a
//! [`EdgeKind::Boundary`] of an open mesh; anything else is [`EdgeKind::NonManifold`].

use std::collections::HashMap;
use std::ops::Range;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::mesh::MeshData;

/// How an edge is connected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum EdgeKind {
    /// Two faces, opposite traversal: the normal case on closed meshes.
    Manifold = 0,
    /// One face: the edge of a hole or an open surface.
    Boundary = 1,
    /// More than two faces, or two faces traversing it the same way (inconsistent winding).
    NonManifold = 2,
}

/// One undirected edge as stored on the GPU (16 bytes).
///
/// `v0 < v1` in welded numbering; the indices stored are representative indices into the scene's
/// vertex buffer. `faces` is `first << 0` into [`Adjacency::edge_faces`]; `info` packs the face
/// count (low 24 bits) and the [`EdgeKind`] (high 8 bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
#[repr(C)]
pub struct EdgeRecord {
    pub v0: u32,
    pub v1: u32,
    pub first_face: u32,
    pub info: u32,
}

impl EdgeRecord {
    /// Bit at which [`EdgeRecord::info`] stores the [`EdgeKind`]; the face count fills the bits
    /// below (`EDGE_FACE_COUNT_MASK` in `shadow-volumes/volumes.wgsl`, which reads only them).
    pub const KIND_SHIFT: u32 = 24;
    /// Mask of the face count in [`EdgeRecord::info`].
    pub const FACE_COUNT_MASK: u32 = (1 << Self::KIND_SHIFT) - 1;

    /// Packs a face count and a connectivity class into [`EdgeRecord::info`].
    pub fn pack_info(face_count: u32, kind: EdgeKind) -> u32 {
        face_count.min(Self::FACE_COUNT_MASK) | (kind as u32) << Self::KIND_SHIFT
    }
    /// Number of incident faces.
    pub fn face_count(&self) -> u32 {
        self.info & Self::FACE_COUNT_MASK
    }
    /// Connectivity class.
    pub fn kind(&self) -> EdgeKind {
        match self.info >> Self::KIND_SHIFT {
            0 => EdgeKind::Manifold,
            1 => EdgeKind::Boundary,
            _ => EdgeKind::NonManifold,
        }
    }
}

/// Edge adjacency of a whole scene.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Adjacency {
    /// All edges, object by object.
    pub edges: Vec<EdgeRecord>,
    /// Incidences: `triangle_index << 1 | reversed`, where `reversed` = 1 when the triangle
    /// traverses the edge from `v1` to `v0`.
    pub edge_faces: Vec<u32>,
    /// Edge range of each object in `edges`.
    pub object_edges: Vec<Range<u32>>,
}

impl Adjacency {
    /// Builds adjacency for `mesh`, one object per range of `object_index_ranges` (ranges into
    /// `mesh.indices`). Vertices are welded only within an object. Objects with the same range
    /// (instances sharing their triangles) share one edge range.
    pub fn build(mesh: &MeshData, object_index_ranges: &[Range<usize>]) -> Adjacency {
        let mut out = Adjacency::default();
        let mut built = std::collections::HashMap::new();
        for range in object_index_ranges {
            let edges = built.entry(range.clone()).or_insert_with(|| {
                let start = out.edges.len() as u32;
                build_object(mesh, range.clone(), &mut out);
                start..out.edges.len() as u32
            });
            out.object_edges.push(edges.clone());
        }
        out
    }

    /// Builds adjacency for `mesh` as a single object.
    pub fn of_mesh(mesh: &MeshData) -> Adjacency {
        let whole = 0..mesh.indices.len();
        Adjacency::build(mesh, std::slice::from_ref(&whole))
    }

    fn count(&self, kind: EdgeKind) -> usize {
        self.edges.iter().filter(|e| e.kind() == kind).count()
    }

    /// Number of boundary edges.
    pub fn boundary_edges(&self) -> usize {
        self.count(EdgeKind::Boundary)
    }

    /// Number of non-manifold edges.
    pub fn non_manifold_edges(&self) -> usize {
        self.count(EdgeKind::NonManifold)
    }

    /// Incidences of `edge` as (triangle index, reversed).
    pub fn faces_of(&self, edge: &EdgeRecord) -> impl Iterator<Item = (u32, bool)> + '_ {
        let start = edge.first_face as usize;
        self.edge_faces[start..start + edge.face_count() as usize]
            .iter()
            .map(|f| (f >> 1, f & 1 == 1))
    }
}

fn build_object(mesh: &MeshData, range: Range<usize>, out: &mut Adjacency) {
    // Weld: map each vertex used by this object to the first vertex with the same position.
    let mut weld: HashMap<[u32; 3], u32> = HashMap::new();
    let mut representative = |index: u32| -> u32 {
        let p: Vec3 = mesh.positions[index as usize];
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()].map(|b| {
            // +0.0 and -0.0 are the same point.
            if b == 0x8000_0000 { 0 } else { b }
        });
        *weld.entry(key).or_insert(index)
    };

    // Every incidence as ((min, max) welded vertex pair, its place in the sequence, incidence),
    // sorted by pair: each run is one edge, its incidences in order of appearance.
    let first_triangle = range.start / 3;
    let mut incidences: Vec<(u64, u32, u32)> = Vec::with_capacity(range.len());
    for (t, tri) in mesh.indices[range].chunks_exact(3).enumerate() {
        let triangle = (first_triangle + t) as u32;
        let w = [tri[0], tri[1], tri[2]].map(&mut representative);
        for k in 0..3 {
            let (a, b) = (w[k], w[(k + 1) % 3]);
            if a == b {
                continue;
            }
            let key = u64::from(a.min(b)) << 32 | u64::from(a.max(b));
            let reversed = u32::from(a > b);
            incidences.push((key, incidences.len() as u32, triangle << 1 | reversed));
        }
    }
    incidences.sort_unstable();

    // Edges in order of their first appearance.
    let mut runs: Vec<(u32, std::ops::Range<usize>)> = Vec::new();
    let mut start = 0;
    for end in 1..=incidences.len() {
        if end == incidences.len() || incidences[end].0 != incidences[start].0 {
            runs.push((incidences[start].1, start..end));
            start = end;
        }
    }
    runs.sort_unstable_by_key(|(first, _)| *first);
    for (_, run) in runs {
        let key = incidences[run.start].0;
        let first_face = out.edge_faces.len();
        out.edge_faces
            .extend(incidences[run].iter().map(|&(_, _, incidence)| incidence));
        let kind = match &out.edge_faces[first_face..] {
            [_] => EdgeKind::Boundary,
            [a, b] if (a & 1) != (b & 1) => EdgeKind::Manifold,
            _ => EdgeKind::NonManifold,
        };
        out.edges.push(EdgeRecord {
            v0: (key >> 32) as u32,
            v1: key as u32,
            first_face: first_face as u32,
            info: EdgeRecord::pack_info((out.edge_faces.len() - first_face) as u32, kind),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh;

    fn whole(m: &MeshData) -> Adjacency {
        Adjacency::of_mesh(m)
    }

    #[test]
    fn cube_has_eighteen_manifold_edges() {
        // 12 cube edges + 6 face diagonals; creases split normals but welding joins them.
        let adjacency = whole(&mesh::cuboid(Vec3::ONE));
        assert_eq!(adjacency.edges.len(), 18);
        assert!(
            adjacency
                .edges
                .iter()
                .all(|e| e.kind() == EdgeKind::Manifold && e.face_count() == 2)
        );
        assert_eq!(adjacency.edge_faces.len(), 36);
    }

    #[test]
    fn open_quad_has_four_boundary_edges_and_one_shared() {
        let quad = mesh::plane(1.0, 1);
        let adjacency = whole(&quad);
        assert_eq!(adjacency.edges.len(), 5);
        assert_eq!(adjacency.boundary_edges(), 4);
        assert_eq!(adjacency.count(EdgeKind::Manifold), 1);
    }

    #[test]
    fn three_faces_on_one_edge_are_non_manifold() {
        let m = MeshData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NEG_Y, Vec3::Z],
            normals: vec![Vec3::Z; 5],
            indices: vec![0, 1, 2, 1, 0, 3, 0, 1, 4],
            ..MeshData::default()
        };
        let adjacency = whole(&m);
        let shared: Vec<_> = adjacency
            .edges
            .iter()
            .filter(|e| e.kind() == EdgeKind::NonManifold)
            .collect();
        assert_eq!(shared.len(), 1);
        assert_eq!((shared[0].v0, shared[0].v1), (0, 1));
        let faces: Vec<_> = adjacency.faces_of(shared[0]).collect();
        assert_eq!(faces, vec![(0, false), (1, true), (2, false)]);
        assert_eq!(adjacency.boundary_edges(), 6);
    }

    #[test]
    fn inconsistent_winding_is_non_manifold() {
        let m = MeshData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NEG_Y],
            normals: vec![Vec3::Z; 4],
            indices: vec![0, 1, 2, 0, 1, 3],
            ..MeshData::default()
        };
        assert_eq!(whole(&m).non_manifold_edges(), 1);
    }

    #[test]
    fn objects_are_not_welded_together() {
        let mut m = mesh::plane(1.0, 1);
        let other = mesh::plane(1.0, 1);
        m.append(&other);
        let adjacency = Adjacency::build(&m, &[0..6, 6..12]);
        assert_eq!(adjacency.edges.len(), 10);
        assert_eq!(adjacency.non_manifold_edges(), 0);
        assert_eq!(adjacency.object_edges, vec![0..5, 5..10]);
        // Triangle indices are global.
        let last = adjacency.edges[9];
        assert!(adjacency.faces_of(&last).all(|(t, _)| t >= 2));
    }
}
