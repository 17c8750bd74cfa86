//! Shadow-casting triangles in a BVH, queried with occlusion rays.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use zoo_scene::Scene;

/// The occluding geometry of a scene.
pub struct Occluders {
    bvh: CwBvh,
    triangles: Vec<Triangle>,
    epsilon: f32,
}

impl Occluders {
    /// The triangles of every shadow-casting object of `scene`.
    pub fn new(scene: &Scene) -> Occluders {
        let mut triangles = Vec::new();
        for object in scene.objects.iter().filter(|o| o.casts_shadows) {
            for tri in scene.mesh.indices[object.indices.clone()].chunks_exact(3) {
                let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| scene.mesh.positions[i as usize]);
                triangles.push([a, b, c]);
            }
        }
        let (lo, hi) = scene.bounds();
        Occluders::from_triangles(&triangles, lo.distance(hi))
    }

    /// Occluders from world-space triangles in a scene of the given diagonal size.
    pub fn from_triangles(triangles: &[[Vec3; 3]], scene_size: f32) -> Occluders {
        let triangles: Vec<Triangle> = triangles
            .iter()
            .map(|[a, b, c]| Triangle {
                v0: (*a).into(),
                v1: (*b).into(),
                v2: (*c).into(),
            })
            .collect();
        let bvh = build_cwbvh_from_tris(
            &triangles,
            BvhBuildParams::fast_build(),
            &mut Duration::default(),
        );
        Occluders {
            bvh,
            triangles,
            epsilon: (scene_size * 2e-5).max(1e-5),
        }
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether there are no occluders.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Offset along the normal applied to ray origins (scaled to the scene).
    pub fn epsilon(&self) -> f32 {
        self.epsilon
    }

    /// Whether anything lies on the segment from `origin` along unit `direction` up to `tmax`.
    pub fn occluded(&self, origin: Vec3, direction: Vec3, tmax: f32) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(direction), 0.0, tmax);
        !self.bvh.ray_traverse_miss(ray, |ray, id| {
            let index = self.bvh.primitive_indices[id] as usize;
            self.triangles[index].intersect(ray)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_blocks_rays_through_it_only() {
        let tri = [[
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ]];
        let o = Occluders::from_triangles(&tri, 3.0);
        assert!(o.occluded(Vec3::ZERO, Vec3::Y, 5.0));
        assert!(
            !o.occluded(Vec3::ZERO, Vec3::Y, 0.5),
            "segment ends before the triangle"
        );
        assert!(!o.occluded(Vec3::new(3.0, 0.0, 0.0), Vec3::Y, 5.0));
        assert!(!o.occluded(Vec3::ZERO, Vec3::NEG_Y, 5.0));
    }
}
