//! Closed casters, whose light-facing triangles alone suffice in the coverage maps.
//!
//! A light ray from outside a closed (watertight, consistently wound) opaque mesh that crosses
//! it enters it first, through a triangle facing the light; so a pixel whose ray crosses the
//! mesh has an entering triangle on its ray, nearer the light than any it leaves through, and
//! the coverage maps (`shaders/hybrid-edge/coverage.wgsl`) may skip the triangles facing away.
//! That holds for the light outside the mesh, which the shader knows only as "outside the
//! mesh's box" (a light inside the box may be inside the mesh, whose rays leave it first: all
//! its triangles are drawn). Masked and translucent casters can let a ray through their
//! entering triangle, and open meshes have no inside: all their triangles are drawn.

use zoo_host::glam::{Vec3, Vec4};
use zoo_host::scene::{EdgeKind, Scene};

zoo_host::gpu_struct! {
    "hybrid-edge/closed_caster.wgsl" =>
    /// One scene object as the coverage maps cull its triangles.
    #[derive(Debug, Clone, Copy, Default, PartialEq)]
    pub(crate) struct ClosedCaster {
        /// Its world box's low corner; w: 1 for a closed opaque caster whose counter-clockwise
        /// faces point out of it in world space, -1 for one whose faces point in, 0 for any
        /// other object (every triangle drawn).
        pub(crate) low: Vec4,
        /// Its world box's high corner.
        pub(crate) high: Vec4,
    }
}

/// Each scene object's [`ClosedCaster`], in object order.
pub(crate) fn closed_casters(scene: &Scene) -> Vec<ClosedCaster> {
    let mut volumes = std::collections::HashMap::new();
    (scene.objects.iter().enumerate())
        .map(|(i, object)| {
            let (low, high) = object.bounds.unwrap_or((Vec3::ZERO, Vec3::ZERO));
            let edges = scene.adjacency.object_edges.get(i).map_or(&[][..], |r| {
                &scene.adjacency.edges[r.start as usize..r.end as usize]
            });
            let closed = !edges.is_empty() && edges.iter().all(|e| e.kind() == EdgeKind::Manifold);
            let solid = object.casts_shadows
                && object.alpha_mask.is_none()
                && object.transmittance().is_none();
            let orientation = if closed && solid {
                let stored = *volumes
                    .entry(object.indices.start..object.indices.end)
                    .or_insert_with(|| signed_volume(scene, object.indices.clone()));
                let mirror = object.placement.determinant();
                let world = stored * mirror;
                if world > 0.0 {
                    1.0
                } else if world < 0.0 {
                    -1.0
                } else {
                    0.0
                }
            } else {
                0.0
            };
            ClosedCaster {
                low: low.extend(orientation),
                high: high.extend(0.0),
            }
        })
        .collect()
}

/// Six times the signed volume the triangles of `indices` enclose in stored space: positive
/// when their counter-clockwise sides face out.
fn signed_volume(scene: &Scene, indices: std::ops::Range<usize>) -> f32 {
    let mesh = &scene.mesh;
    let corner = |k: usize| mesh.positions[mesh.indices[k] as usize].as_dvec3();
    // In f64 about the first corner, so large coordinates keep the sign.
    let origin = corner(indices.start);
    let volume: f64 = indices
        .step_by(3)
        .map(|k| {
            let (a, b, c) = (
                corner(k) - origin,
                corner(k + 1) - origin,
                corner(k + 2) - origin,
            );
            a.dot(b.cross(c))
        })
        .sum();
    volume as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::test_support::scene_from_ron;

    /// The orientation of each object of a scene of `objects` (RON object entries).
    fn orientations(objects: &str) -> Vec<f32> {
        let scene = scene_from_ron(
            "closed",
            &format!(
                "(name: \"closed\", camera: (position: (0, 2, 6), target: (0, 0, 0)), \
                 lights: [Directional(direction: (0, -1, 0))], objects: [{objects}])"
            ),
        );
        closed_casters(&scene).iter().map(|c| c.low.w).collect()
    }

    #[test]
    fn closed_opaque_casters_are_oriented_and_others_drawn_whole() {
        let found = orientations(
            "(mesh: Box(size: (1, 1, 1))), \
             (mesh: Sphere(radius: 0.5, segments: 16, rings: 8), \
              transform: (translation: (3, 0, 0))), \
             (mesh: Plane(size: 4)), \
             (mesh: Box(size: (1, 1, 1)), casts_shadows: false), \
             (mesh: Box(size: (1, 1, 1)), opacity: 0.5), \
             (mesh: Box(size: (1, 1, 1)), transform: (scale: (-1, 1, 1))), \
             (mesh: Box(size: (1, 1, 1)), instances: [(translation: (0, 3, 0)), \
              (translation: (3, 3, 0), scale: (2, 1, 1))])",
        );
        // Cube and sphere point out; a plane is open; a cube that casts nothing or lets light
        // through is drawn whole. A mirrored cube is stored wound to point out; instances
        // (which cannot mirror) point out like their object.
        assert_eq!(found, [1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    }

    #[test]
    fn a_closed_mesh_wound_inwards_is_oriented_inwards() {
        let mut scene = scene_from_ron(
            "inward",
            "(name: \"inward\", camera: (position: (0, 2, 6), target: (0, 0, 0)), \
             lights: [Directional(direction: (0, -1, 0))], \
             objects: [(mesh: Box(size: (1, 1, 1)), instances: [(translation: (0, 0, 0)), \
              (translation: (3, 0, 0))])])",
        );
        // A room modelled to be seen from inside: every triangle wound the other way.
        let range = scene.objects[0].indices.clone();
        for triangle in scene.mesh.indices[range].chunks_exact_mut(3) {
            triangle.swap(1, 2);
        }
        let found: Vec<f32> = closed_casters(&scene).iter().map(|c| c.low.w).collect();
        assert_eq!(found, [-1.0, -1.0]);
    }

    #[test]
    fn boxes_are_the_objects_world_bounds() {
        let scene = scene_from_ron(
            "box",
            "(name: \"box\", camera: (position: (0, 2, 6), target: (0, 0, 0)), \
             lights: [Directional(direction: (0, -1, 0))], \
             objects: [(mesh: Box(size: (2, 2, 2)), transform: (translation: (5, 1, 0)))])",
        );
        let caster = closed_casters(&scene)[0];
        assert!(
            caster
                .low
                .truncate()
                .abs_diff_eq(Vec3::new(4.0, 0.0, -1.0), 1e-5)
        );
        assert!(
            caster
                .high
                .truncate()
                .abs_diff_eq(Vec3::new(6.0, 2.0, 1.0), 1e-5)
        );
    }
}
