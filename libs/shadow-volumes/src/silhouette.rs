//! CPU mirror of the volume-generation shader's face weights and edge multiplicities, for tests
//! and workload estimates.

use zoo_host::glam::{Vec3, Vec4};
use zoo_host::scene::{Adjacency, MeshData};

/// Weight of each triangle for a light at homogeneous position `light` ((p, 1) or
/// (-direction, 0)): +1 facing the light, -1 facing away on an open mesh (its triangles all
/// block light and are oriented toward it), 0 otherwise.
pub fn triangle_weights(mesh: &MeshData, light: Vec4, closed: bool) -> Vec<i32> {
    mesh.indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
            let toward: Vec3 = if light.w == 0.0 {
                light.truncate()
            } else {
                light.truncate() - (a + b + c) / 3.0
            };
            if (b - a).cross(c - a).dot(toward) > 0.0 {
                1
            } else if closed {
                0
            } else {
                -1
            }
        })
        .collect()
}

/// Side-quad multiplicity of every edge: the sum over its faces of weight times +1 (the face
/// runs v0 -> v1) or -1. Non-zero edges are silhouette edges; the sign is the quad's direction.
pub fn edge_multiplicities(adjacency: &Adjacency, weights: &[i32]) -> Vec<i32> {
    adjacency
        .edges
        .iter()
        .map(|edge| {
            adjacency
                .faces_of(edge)
                .map(|(t, reversed)| {
                    if reversed {
                        -weights[t as usize]
                    } else {
                        weights[t as usize]
                    }
                })
                .sum()
        })
        .collect()
}

/// Number of silhouette edges (non-zero multiplicity).
pub fn silhouette_edges(mesh: &MeshData, light: Vec4, closed: bool) -> usize {
    let adjacency = Adjacency::of_mesh(mesh);
    let weights = triangle_weights(mesh, light, closed);
    edge_multiplicities(&adjacency, &weights)
        .iter()
        .filter(|m| **m != 0)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::scene::mesh;

    fn tetrahedron() -> MeshData {
        let p = [
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ];
        let mut m = MeshData {
            positions: p.to_vec(),
            normals: vec![Vec3::Y; 4],
            indices: vec![0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2],
            ..MeshData::default()
        };
        // Make every face wind outward.
        for t in m.indices.chunks_exact_mut(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| p[i as usize]);
            if (b - a).cross(c - a).dot((a + b + c) / 3.0) < 0.0 {
                t.swap(1, 2);
            }
        }
        m
    }

    #[test]
    fn cube_silhouettes() {
        let cube = mesh::cuboid(Vec3::ONE);
        // Directly above: the top square's four edges (its diagonal cancels).
        assert_eq!(
            silhouette_edges(&cube, Vec4::new(0.0, 10.0, 0.0, 1.0), true),
            4
        );
        // Along a diagonal: three faces lit, a hexagon.
        assert_eq!(
            silhouette_edges(&cube, Vec4::new(1.0, 1.0, 1.0, 0.0), true),
            6
        );
        // Multiplicities are +-1 on a closed mesh.
        let adjacency = Adjacency::of_mesh(&cube);
        let w = triangle_weights(&cube, Vec4::new(3.0, 5.0, 2.0, 1.0), true);
        assert!(
            edge_multiplicities(&adjacency, &w)
                .iter()
                .all(|m| m.abs() <= 1)
        );
    }

    #[test]
    fn tetrahedron_silhouettes() {
        let t = tetrahedron();
        // Toward the centre of one face: that face is lit, its three edges are the silhouette.
        let face_center =
            (Vec3::new(1.0, -1.0, -1.0) + Vec3::new(-1.0, 1.0, -1.0) + Vec3::new(-1.0, -1.0, 1.0))
                / 3.0;
        assert_eq!(
            silhouette_edges(&t, (face_center * -10.0).extend(1.0), true),
            3
        );
        // Toward the middle of an edge: two faces lit, a quadrilateral silhouette.
        let edge_mid = (Vec3::new(1.0, 1.0, 1.0) + Vec3::new(1.0, -1.0, -1.0)) * 0.5;
        assert_eq!(silhouette_edges(&t, (edge_mid * 10.0).extend(1.0), true), 4);
    }

    #[test]
    fn open_quad_casts_from_either_side() {
        let quad = mesh::plane(1.0, 1);
        let adjacency = Adjacency::of_mesh(&quad);
        for light in [
            Vec4::new(0.2, 3.0, 0.1, 1.0),
            Vec4::new(0.2, -3.0, 0.1, 1.0),
        ] {
            let w = triangle_weights(&quad, light, false);
            assert!(
                w.iter().all(|x| *x != 0),
                "every triangle of an open mesh casts"
            );
            let m = edge_multiplicities(&adjacency, &w);
            // Four boundary edges, the shared diagonal cancels.
            assert_eq!(m.iter().filter(|x| **x != 0).count(), 4);
            assert!(m.iter().all(|x| x.abs() <= 1));
        }
    }

    #[test]
    fn non_manifold_edge_counts_with_multiplicity() {
        // Three triangles on the edge 0-1: two wound one way, one the other.
        let fan = MeshData {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Y,
                Vec3::new(0.5, 0.5, 1.0),
                Vec3::new(0.5, 0.5, -1.0),
            ],
            normals: vec![Vec3::Z; 5],
            indices: vec![0, 1, 2, 1, 0, 3, 0, 1, 4],
            ..MeshData::default()
        };
        let adjacency = Adjacency::of_mesh(&fan);
        let shared = adjacency
            .edges
            .iter()
            .position(|e| (e.v0, e.v1) == (0, 1))
            .unwrap();
        // Light far along +z: every triangle is oriented toward it (open mesh), and the
        // multiplicity on the shared edge is the signed count of traversals.
        let light = Vec4::new(0.3, 0.3, 10.0, 1.0);
        let w = triangle_weights(&fan, light, false);
        let m = edge_multiplicities(&adjacency, &w);
        // t0 = (0,1,2) faces the light (+1) and runs 0->1; t1 = (1,0,3) faces away, is flipped
        // (-1) and runs 1->0; t2 = (0,1,4) faces the light and runs 0->1: m = 1 + 1 + 1.
        assert_eq!(w, vec![1, -1, 1]);
        assert_eq!(m[shared], 3);
        // Every boundary edge of the fan has multiplicity +-1.
        for (i, e) in adjacency.edges.iter().enumerate() {
            if e.face_count() == 1 {
                assert_eq!(m[i].abs(), 1);
            }
        }
    }
}
