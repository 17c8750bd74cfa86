//! Triangles stored once and drawn many times: a two-level hierarchy.
//!
//! Objects drawn once keep their triangles in world space, in one hierarchy. Instances share
//! their object's triangles: each distinct stored mesh has a hierarchy of its own, in its
//! stored space, and a top hierarchy holds the instances' world boxes. A ray enters an
//! instance's mesh through the inverse of its placement; the distance along it is the same in
//! both spaces (the direction is mapped, not renormalised), so hits from every part compare
//! directly.
//!
//! Triangles are numbered in one sequence, the judge's triangle index: the world-space parts'
//! triangles first, in part order, then each instance's (not the GPU's drawn order, which
//! follows the objects).

use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::Range;

use glam::{Mat4, Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use zoo_scene::{Scene, SceneObject};

use crate::bvh::{Query, TriangleBvh, Visit, traverse_nodes};
use crate::robust::gamma;

thread_local! {
    /// Each thread's stack for the top hierarchy (the meshes' traversals use their own).
    static TOP_STACK: RefCell<Vec<(u32, f32)>> = const { RefCell::new(Vec::new()) };
}

/// Corners and texture coordinates of stored triangles.
#[derive(Default)]
struct Stored {
    corners: Vec<[Vec3; 3]>,
    uvs: Vec<[Vec2; 3]>,
}

impl Stored {
    fn push_object(&mut self, scene: &Scene, object: &SceneObject) {
        self.corners.extend(scene.stored_triangles(object));
        self.uvs.extend(
            scene
                .triangle_indices(object)
                .map(|t| t.map(|i| scene.mesh.uvs.get(i).copied().unwrap_or_default())),
        );
    }
}

/// One shared mesh in its stored space.
struct Mesh {
    bvh: TriangleBvh,
    stored: Stored,
}

/// One instance: which mesh, where it goes, and its first triangle index.
struct Instance {
    mesh: usize,
    to_world: Mat4,
    to_local: Mat4,
    first: usize,
}

/// Where a part's triangles are in the sequence of triangle indices.
#[derive(Clone, Copy)]
struct Part {
    first: usize,
    len: usize,
    instance: Option<usize>,
}

/// A hit triangle's world corners and texture coordinates, and which part it belongs to.
pub(crate) struct DrawnTriangle {
    /// The part's index, in the order the parts were given.
    pub part: usize,
    pub corners: [Vec3; 3],
    pub uvs: [Vec2; 3],
}

/// Triangles of some scene objects (the parts), instances sharing their meshes.
pub(crate) struct PlacedTriangles {
    world: TriangleBvh,
    world_stored: Stored,
    meshes: Vec<Mesh>,
    instances: Vec<Instance>,
    /// Over the world boxes of the instances `traced` lists (empty without instances).
    top: Bvh2,
    traced: Vec<usize>,
    parts: Vec<Part>,
    /// (first triangle index, part), sorted.
    by_index: Vec<(usize, usize)>,
}

impl PlacedTriangles {
    /// The triangles of `objects`, each one part.
    pub(crate) fn new<'a>(
        scene: &Scene,
        objects: impl IntoIterator<Item = &'a SceneObject>,
    ) -> Self {
        let objects: Vec<&SceneObject> = objects.into_iter().collect();
        let mut world_stored = Stored::default();
        let mut parts = vec![
            Part {
                first: 0,
                len: 0,
                instance: None
            };
            objects.len()
        ];
        for (part, object) in objects.iter().enumerate() {
            if !object.is_placed() {
                let first = world_stored.corners.len();
                world_stored.push_object(scene, object);
                parts[part].first = first;
                parts[part].len = world_stored.corners.len() - first;
            }
        }
        let mut next = world_stored.corners.len();
        let mut meshes: Vec<Mesh> = Vec::new();
        let mut mesh_of: HashMap<Range<usize>, usize> = HashMap::new();
        let mut instances = Vec::new();
        for (part, object) in objects.iter().enumerate() {
            if !object.is_placed() {
                continue;
            }
            let mesh = *mesh_of.entry(object.indices.clone()).or_insert_with(|| {
                let mut stored = Stored::default();
                stored.push_object(scene, object);
                meshes.push(Mesh {
                    bvh: TriangleBvh::new(&stored.corners),
                    stored,
                });
                meshes.len() - 1
            });
            let len = meshes[mesh].stored.corners.len();
            parts[part] = Part {
                first: next,
                len,
                instance: Some(instances.len()),
            };
            instances.push(Instance {
                mesh,
                to_world: object.placement,
                to_local: object.placement.inverse(),
                first: next,
            });
            next += len;
        }
        PlacedTriangles::assemble(world_stored, meshes, instances, parts)
    }

    /// World-space triangles, one part.
    pub(crate) fn from_triangles(triangles: &[[Vec3; 3]]) -> Self {
        PlacedTriangles::from_parts([triangles])
    }

    /// World-space triangles in parts (texture coordinates all 0).
    pub(crate) fn from_parts<'a>(parts: impl IntoIterator<Item = &'a [[Vec3; 3]]>) -> Self {
        let mut stored = Stored::default();
        let parts = (parts.into_iter())
            .map(|triangles| {
                let first = stored.corners.len();
                stored.corners.extend_from_slice(triangles);
                Part {
                    first,
                    len: triangles.len(),
                    instance: None,
                }
            })
            .collect();
        stored.uvs = vec![[Vec2::ZERO; 3]; stored.corners.len()];
        PlacedTriangles::assemble(stored, Vec::new(), Vec::new(), parts)
    }

    fn assemble(
        world_stored: Stored,
        meshes: Vec<Mesh>,
        instances: Vec<Instance>,
        parts: Vec<Part>,
    ) -> Self {
        // Instances of meshes without a triangle (all degenerate) are left out of the top.
        let (traced, boxes): (Vec<usize>, Vec<Aabb>) = (instances.iter().enumerate())
            .filter_map(|(k, i)| {
                let (lo, hi) = meshes[i.mesh].bvh.bounds()?;
                let (min, max) = placed_box(i.to_world, lo, hi);
                Some((k, Aabb::new(Vec3A::from(min), Vec3A::from(max))))
            })
            .unzip();
        let top = if boxes.is_empty() {
            Bvh2::default()
        } else {
            crate::bvh::build_bvh2(&boxes)
        };
        let mut by_index: Vec<(usize, usize)> = parts
            .iter()
            .enumerate()
            .map(|(p, part)| (part.first, p))
            .collect();
        by_index.sort_unstable();
        PlacedTriangles {
            world: TriangleBvh::new(&world_stored.corners),
            world_stored,
            meshes,
            instances,
            top,
            traced,
            parts,
            by_index,
        }
    }

    /// Number of triangles kept (instances counted).
    pub(crate) fn len(&self) -> usize {
        self.world.len()
            + (self.instances.iter())
                .map(|i| self.meshes[i.mesh].bvh.len())
                .sum::<usize>()
    }

    /// The part that holds triangle `index`.
    pub(crate) fn part(&self, index: usize) -> usize {
        // The part that starts last at or before `index` and holds it (parts without
        // triangles start where the next one does).
        let at = self.by_index.partition_point(|(first, _)| *first <= index);
        (self.by_index[..at].iter().rev())
            .find(|(first, part)| index < first + self.parts[*part].len)
            .expect("a triangle index within the parts")
            .1
    }

    /// Triangle `index`: its part, world corners and texture coordinates.
    pub(crate) fn triangle(&self, index: usize) -> DrawnTriangle {
        let part = self.part(index);
        let (stored, local, to_world) = match self.parts[part].instance {
            None => (&self.world_stored, index, None),
            Some(i) => {
                let instance = &self.instances[i];
                let stored = &self.meshes[instance.mesh].stored;
                (stored, index - instance.first, Some(instance.to_world))
            }
        };
        let corners = stored.corners[local];
        DrawnTriangle {
            part,
            corners: to_world.map_or(corners, |m| corners.map(|p| m.transform_point3(p))),
            uvs: stored.uvs[local],
        }
    }

    /// Calls `visit(instance, local query)` for each instance whose box `query` enters,
    /// nearer first; `visit` returns the distance to keep searching up to (`query`'s, or a
    /// nearer hit's), or `None` to stop.
    fn each_instance(
        &self,
        query: &Query,
        mut visit: impl FnMut(&Instance, &Query) -> Option<f32>,
    ) {
        if self.traced.is_empty() {
            return;
        }
        TOP_STACK.with_borrow_mut(|stack| {
            traverse_nodes(&self.top, query.ray, stack, |range, ray| {
                for p in range {
                    let traced = self.traced[self.top.primitive_indices[p] as usize];
                    let instance = &self.instances[traced];
                    let origin = instance.to_local.transform_point3(Vec3::from(ray.origin));
                    let direction = instance
                        .to_local
                        .transform_vector3(Vec3::from(ray.direction));
                    let Some(local) = Query::new(origin, direction, ray.tmax) else {
                        continue;
                    };
                    match visit(instance, &local) {
                        Some(tmax) => ray.tmax = ray.tmax.min(tmax),
                        None => return Visit::Stop,
                    }
                }
                Visit::Continue
            });
        });
    }

    /// The nearest hit that `accept(triangle index, distance)` takes.
    pub(crate) fn closest_where(
        &self,
        query: &Query,
        mut accept: impl FnMut(usize, f32) -> bool,
    ) -> Option<(usize, f32)> {
        let mut best = self.world.closest_where(query, &mut accept);
        self.each_instance(query, |instance, local| {
            let mut local = *local;
            if let Some((_, t)) = best {
                local.ray.tmax = local.ray.tmax.min(t);
            }
            let first = instance.first;
            let mesh = &self.meshes[instance.mesh].bvh;
            if let Some((i, t)) = mesh.closest_where(&local, |i, t| accept(first + i, t)) {
                best = Some((first + i, t));
            }
            Some(best.map_or(f32::INFINITY, |(_, t)| t))
        });
        best
    }

    /// Whether `query` hits a triangle that `blocks(triangle index, distance)` accepts.
    pub(crate) fn any_hit_where(
        &self,
        query: &Query,
        mut blocks: impl FnMut(usize, f32) -> bool,
    ) -> bool {
        if self.world.any_hit_where(query, &mut blocks) {
            return true;
        }
        let mut hit = false;
        self.each_instance(query, |instance, local| {
            let first = instance.first;
            let mesh = &self.meshes[instance.mesh].bvh;
            hit = mesh.any_hit_where(local, |i, t| blocks(first + i, t));
            (!hit).then_some(f32::INFINITY)
        });
        hit
    }

    /// Calls `hit` with the triangle index of every triangle `query` crosses.
    pub(crate) fn each_hit(&self, query: &Query, mut hit: impl FnMut(usize)) {
        self.world.each_hit(query, &mut hit);
        self.each_instance(query, |instance, local| {
            let first = instance.first;
            (self.meshes[instance.mesh].bvh).each_hit(local, |i| hit(first + i));
            Some(f32::INFINITY)
        });
    }
}

#[cfg(test)]
impl PlacedTriangles {
    /// The ray of `query` in `instance`'s stored space.
    fn local_query(instance: &Instance, query: &Query) -> Option<Query> {
        let origin = instance
            .to_local
            .transform_point3(Vec3::from(query.ray.origin));
        let direction = instance
            .to_local
            .transform_vector3(Vec3::from(query.ray.direction));
        Query::new(origin, direction, query.ray.tmax)
    }

    /// The nearest hit: its triangle index and distance.
    pub(crate) fn closest(&self, query: &Query) -> Option<(usize, f32)> {
        self.closest_where(query, |_, _| true)
    }

    /// The nearest hit by brute force over every triangle of every part.
    pub(crate) fn closest_brute_force(&self, query: &Query) -> Option<(usize, f32)> {
        let instances = self.instances.iter().filter_map(|instance| {
            let local = PlacedTriangles::local_query(instance, query)?;
            let (i, t) = self.meshes[instance.mesh].bvh.closest_brute_force(&local)?;
            Some((instance.first + i, t))
        });
        (self.world.closest_brute_force(query).into_iter())
            .chain(instances)
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Whether brute force over every triangle of every part finds a hit.
    pub(crate) fn any_hit_brute_force(&self, query: &Query) -> bool {
        self.world.any_hit_brute_force(query)
            || self.instances.iter().any(|instance| {
                PlacedTriangles::local_query(instance, query)
                    .is_some_and(|local| self.meshes[instance.mesh].bvh.any_hit_brute_force(&local))
            })
    }
}

/// The world box (min, max) around a stored box's placed corners, grown by the placement's
/// rounding at the box's magnitude so that slab tests against it stay conservative.
pub fn placed_box(to_world: Mat4, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
    let corners = (0..8).map(|k: u32| {
        let pick = |bit: u32| if k & bit == 0 { 0.0 } else { 1.0 };
        to_world.transform_point3(lo + (hi - lo) * Vec3::new(pick(1), pick(2), pick(4)))
    });
    let (min, max) = corners.fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(a, b), c| (a.min(c), b.max(c)),
    );
    let pad = Vec3::splat(gamma(8) * min.abs().max(max.abs()).max_element());
    (min - pad, max + pad)
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    const SCENE: &str = r#"(
        camera: (position: (0, 6, 14), target: (0, 0, 0)),
        lights: [Directional(direction: (0.3, -1, 0.2))],
        objects: [
            (mesh: Plane(size: 12)),
            (mesh: Box(size: (1, 2, 1)), instances: [
                (translation: (-2, 1, 0)),
                (translation: (2, 1, 1), rotation_degrees: (0, 35, 20), scale: (1.5, 0.5, 1)),
            ]),
            (mesh: Sphere(radius: 0.5, segments: 12, rings: 6), transform: (translation: (0, 3, 0))),
            (mesh: Cone(radius: 0.5, height: 1, segments: 12), instances: [
                (translation: (0, 0, -3)),
                (translation: (3, 2, -3), rotation_degrees: (90, 0, 0), scale: (0.1, 0.1, 0.1)),
            ]),
        ],
    )"#;

    #[test]
    fn traversal_finds_what_brute_force_over_every_part_finds() {
        let scene = Scene::from_ron(SCENE, Path::new("t.ron"), Path::new(".")).unwrap();
        let placed = PlacedTriangles::new(&scene, &scene.objects);
        assert_eq!(placed.len(), scene.drawn_triangle_count());
        let mut state = 5u64;
        let mut unit = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        let mut hits = 0;
        for _ in 0..5000 {
            let origin = Vec3::new(unit() * 12.0 - 6.0, unit() * 4.0, unit() * 12.0 - 6.0);
            let direction = Vec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5).normalize();
            let query = Query::new(origin, direction, 20.0).unwrap();
            let found = placed.closest(&query);
            assert_eq!(
                found,
                placed.closest_brute_force(&query),
                "{origin} {direction}"
            );
            assert_eq!(placed.any_hit_where(&query, |_, _| true), found.is_some());
            assert_eq!(placed.any_hit_brute_force(&query), found.is_some());
            if let Some((index, _)) = found {
                hits += 1;
                // The part of the hit holds the triangle index.
                let part = &placed.parts[placed.part(index)];
                assert!((part.first..part.first + part.len).contains(&index));
            }
        }
        assert!(hits > 1000, "{hits} hits");
    }
}
