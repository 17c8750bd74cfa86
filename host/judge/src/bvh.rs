//! Triangles in a bounding volume hierarchy over world coordinates, traversed without any
//! distance cut-off.
//!
//! The hierarchy is built by obvhs (PLOC, a binary BVH) and traversed here: obvhs's compressed
//! wide BVH skips nodes that end closer than a fixed 1e-4 to the ray origin, which is a
//! distance in world units, so a scene's scale would decide which nearby occluders count. The
//! slab test here is conservative in floating point (Ize, "Robust BVH Ray Traversal", 2013:
//! the far distance is scaled by 1 + 2γ₃) and leaf boxes are grown by the triangle test's
//! rounding at the scene's coordinates, so traversal finds what brute force over every
//! triangle finds (tested for rays from inside the scene; a hit the triangle test accepts
//! only by rounding, outside the exact triangle, may still be missed from far outside it).

use std::cell::RefCell;

use glam::{Vec3, Vec3A};
use obvhs::Boundable;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::leaf_collapser::collapse;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::ploc::PlocBuilder;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;

use crate::robust::gamma;

/// A ray query: origin, direction and the open distance range (0, `tmax`]. Directions are unit
/// in world space; in an instance's stored space they are the world direction mapped by the
/// inverse placement, so distances are the same in both.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Query {
    pub(crate) ray: Ray,
}

impl Query {
    /// The segment from `origin` along `direction` up to `tmax` (infinite for rays to
    /// directional lights); `None` when the origin or direction is not finite or `tmax` is NaN
    /// (callers treat such a query as unoccluded).
    pub(crate) fn new(origin: Vec3, direction: Vec3, tmax: f32) -> Option<Query> {
        if !direction.is_finite() || !origin.is_finite() || tmax.is_nan() {
            return None;
        }
        // -0.0 + 0.0 == +0.0; every other value is unchanged.
        let direction = Vec3A::from(direction) + Vec3A::ZERO;
        Some(Query {
            ray: Ray {
                origin: Vec3A::from(origin),
                direction,
                inv_direction: direction.map(reciprocal),
                // Hits at the origin itself (t = 0) do not count: origins are offset off
                // their surface by its error bound (see `SurfacePoint::ray_origin`).
                tmin: f32::MIN_POSITIVE,
                tmax,
            },
        })
    }
}

/// A bounding volume hierarchy in flat arrays: the judge's own build (boxes grown by the
/// triangle test's rounding), for traversal on the GPU.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FlatBvh {
    /// Node 0 is the root; an inner node's children are nodes `first` and `first + 1`.
    pub nodes: Vec<FlatNode>,
    /// The input index of each stored triangle: a leaf holds stored triangles
    /// `first..first + count`. Degenerate triangles are left out.
    pub triangles: Vec<u32>,
}

/// One node of a [`FlatBvh`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatNode {
    pub min: Vec3,
    pub max: Vec3,
    /// First child (inner nodes) or first stored triangle (leaves).
    pub first: u32,
    /// Number of triangles: 0 for inner nodes.
    pub count: u32,
}

impl FlatBvh {
    /// The hierarchy over world-space `triangles`.
    pub fn build(triangles: &[[Vec3; 3]]) -> FlatBvh {
        TriangleBvh::new(triangles).flat()
    }

    /// A hierarchy over boxes (min, max): a leaf holds stored boxes `first..first + count`,
    /// [`Self::triangles`] giving each one's input index (for instances' boxes above their
    /// meshes' hierarchies).
    pub fn over_boxes(boxes: &[(Vec3, Vec3)]) -> FlatBvh {
        if boxes.is_empty() {
            return FlatBvh::default();
        }
        let aabbs: Vec<Aabb> = (boxes.iter())
            .map(|(lo, hi)| Aabb::new((*lo).into(), (*hi).into()))
            .collect();
        let bvh = build_bvh2(&aabbs);
        FlatBvh {
            nodes: flat_nodes(&bvh),
            triangles: bvh.primitive_indices.clone(),
        }
    }
}

/// A hierarchy over `primitives` with obvhs's fast build settings: a PLOC build, reinsertion,
/// leaves collapsed, reinsertion again. (obvhs's own helper for these steps times them with
/// `std::time`, which panics in the browser build.)
pub fn build_bvh2<T: Boundable>(primitives: &[T]) -> Bvh2 {
    let config = BvhBuildParams::fast_build();
    let indices = (0..primitives.len() as u32).collect();
    let mut bvh = PlocBuilder::with_capacity(primitives.len()).build(
        config.ploc_search_distance,
        primitives,
        indices,
        config.sort_precision,
        config.search_depth_threshold,
    );
    let mut reinsertion = ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh, config.reinsertion_batch_ratio, None);
    let max_leaf = config.max_prims_per_leaf.clamp(1, 255);
    collapse(&mut bvh, max_leaf, config.collapse_traversal_cost);
    let after_collapse =
        config.reinsertion_batch_ratio * config.post_collapse_reinsertion_batch_ratio_multiplier;
    reinsertion.run(&mut bvh, after_collapse, None);
    #[cfg(debug_assertions)]
    bvh.validate(primitives, false, config.pre_split);
    bvh
}

/// The nodes of `bvh` in flat form.
fn flat_nodes(bvh: &Bvh2) -> Vec<FlatNode> {
    (bvh.nodes.iter())
        .map(|n| FlatNode {
            min: n.aabb.min.into(),
            max: n.aabb.max.into(),
            first: n.first_index,
            count: n.prim_count,
        })
        .collect()
}

/// What a leaf visit tells the traversal.
pub(crate) enum Visit {
    /// Keep going (with the ray's `tmax` possibly shortened by the visitor).
    Continue,
    /// Stop: the answer is known.
    Stop,
}

/// Triangles in a BVH, stored in traversal order.
pub(crate) struct TriangleBvh {
    bvh: Bvh2,
    triangles: Vec<Triangle>,
    /// Per stored triangle: the index of the input triangle it came from.
    sources: Vec<usize>,
}

thread_local! {
    /// Each thread's traversal stack, kept between queries.
    static STACK: RefCell<Vec<(u32, f32)>> = const { RefCell::new(Vec::new()) };
}

impl TriangleBvh {
    /// Builds the BVH over the non-degenerate ones of world-space `triangles`.
    pub(crate) fn new(triangles: &[[Vec3; 3]]) -> TriangleBvh {
        let (sources, kept): (Vec<usize>, Vec<Triangle>) = triangles
            .iter()
            .enumerate()
            .filter(|(_, t)| !has_no_area(t))
            .map(|(i, [a, b, c])| {
                let triangle = Triangle {
                    v0: (*a).into(),
                    v1: (*b).into(),
                    v2: (*c).into(),
                };
                (i, triangle)
            })
            .unzip();
        if kept.is_empty() {
            return TriangleBvh {
                bvh: Bvh2::default(),
                triangles: Vec::new(),
                sources: Vec::new(),
            };
        }
        // The triangle test rounds at the magnitude of the coordinates, so it accepts hits up
        // to a few ulps outside a triangle (at a vertex or an edge lying in a box face); boxes
        // grow by that much so that traversal finds the hits brute force would. This costs
        // only traversal time: which hits count is the triangle test's alone.
        let magnitude = kept
            .iter()
            .flat_map(|t| [t.v0, t.v1, t.v2])
            .map(|v| v.abs().max_element())
            .fold(0.0f32, f32::max);
        let padding = Vec3A::splat(gamma(16) * magnitude);
        let boxes: Vec<Aabb> = kept
            .iter()
            .map(|t| {
                let b = t.aabb();
                Aabb::new(b.min - padding, b.max + padding)
            })
            .collect();
        let mut bvh = build_bvh2(&boxes);
        // Store triangles in leaf order so that a leaf's triangles are contiguous.
        let order = std::mem::take(&mut bvh.primitive_indices);
        let triangles = order.iter().map(|&i| kept[i as usize]).collect();
        let sources = order.iter().map(|&i| sources[i as usize]).collect();
        bvh.primitive_indices = (0..order.len() as u32).collect();
        TriangleBvh {
            bvh,
            triangles,
            sources,
        }
    }

    /// The hierarchy in flat arrays, for traversal elsewhere (the GPU's ray tracing).
    pub(crate) fn flat(&self) -> FlatBvh {
        if self.triangles.is_empty() {
            return FlatBvh::default();
        }
        FlatBvh {
            nodes: flat_nodes(&self.bvh),
            triangles: self.sources.iter().map(|&s| s as u32).collect(),
        }
    }

    /// The root's box (grown by the triangle test's rounding), `None` without triangles.
    pub(crate) fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let root = self
            .bvh
            .nodes
            .first()
            .filter(|_| !self.triangles.is_empty())?;
        Some((root.aabb.min.into(), root.aabb.max.into()))
    }

    /// Number of triangles kept.
    pub(crate) fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Visits the leaves `query` may cross, nearer child first, calling `leaf` with each
    /// triangle range; `leaf` may shorten the ray's `tmax`.
    fn traverse(&self, query: &Query, leaf: impl FnMut(std::ops::Range<usize>, &mut Ray) -> Visit) {
        if !self.triangles.is_empty() {
            STACK.with_borrow_mut(|stack| traverse_nodes(&self.bvh, query.ray, stack, leaf));
        }
    }

    /// The nearest hit that `accept(input index, distance)` takes (masked surfaces let rays
    /// through their holes).
    pub(crate) fn closest_where(
        &self,
        query: &Query,
        mut accept: impl FnMut(usize, f32) -> bool,
    ) -> Option<(usize, f32)> {
        let mut best = None;
        self.traverse(query, |range, ray| {
            for i in range {
                let t = self.triangles[i].intersect(ray);
                if t < ray.tmax && accept(self.sources[i], t) {
                    ray.tmax = t;
                    best = Some((self.sources[i], t));
                }
            }
            Visit::Continue
        });
        best
    }

    /// Whether `query` hits a triangle that `blocks(input index, distance)` accepts (masked
    /// casters pass rays through their holes).
    pub(crate) fn any_hit_where(
        &self,
        query: &Query,
        mut blocks: impl FnMut(usize, f32) -> bool,
    ) -> bool {
        let mut hit = false;
        self.traverse(query, |mut range, ray| {
            hit = range.any(|i| {
                let t = self.triangles[i].intersect(ray);
                t < f32::INFINITY && blocks(self.sources[i], t)
            });
            if hit { Visit::Stop } else { Visit::Continue }
        });
        hit
    }

    /// Calls `hit` with the input index of every triangle `query` crosses.
    pub(crate) fn each_hit(&self, query: &Query, mut hit: impl FnMut(usize)) {
        self.traverse(query, |range, ray| {
            for i in range {
                if self.triangles[i].intersect(ray) < f32::INFINITY {
                    hit(self.sources[i]);
                }
            }
            Visit::Continue
        });
    }

    /// The nearest hit by brute force over every triangle (for tests of the traversal).
    #[cfg(test)]
    pub(crate) fn closest_brute_force(&self, query: &Query) -> Option<(usize, f32)> {
        self.triangles
            .iter()
            .zip(&self.sources)
            .map(|(t, s)| (*s, t.intersect(&query.ray)))
            .filter(|(_, t)| *t < f32::INFINITY)
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Whether brute force over every triangle finds a hit (for tests of the traversal).
    #[cfg(test)]
    pub(crate) fn any_hit_brute_force(&self, query: &Query) -> bool {
        self.triangles
            .iter()
            .any(|t| t.intersect(&query.ray) < f32::INFINITY)
    }
}

/// Visits the leaves of the non-empty `bvh` that `ray` may cross, nearer child first, calling
/// `leaf` with each primitive range; `leaf` may shorten the ray's `tmax`. `stack` is scratch
/// space (a traversal inside a leaf visit needs a stack of its own).
pub(crate) fn traverse_nodes(
    bvh: &Bvh2,
    mut ray: Ray,
    stack: &mut Vec<(u32, f32)>,
    mut leaf: impl FnMut(std::ops::Range<usize>, &mut Ray) -> Visit,
) {
    let Some(root) = enters(&bvh.nodes[0].aabb, &ray) else {
        return;
    };
    stack.clear();
    stack.push((0, root));
    while let Some((index, near)) = stack.pop() {
        // A closer hit found since the node was pushed may rule it out.
        if near > ray.tmax {
            continue;
        }
        let node = &bvh.nodes[index as usize];
        let first = node.first_index as usize;
        if node.prim_count > 0 {
            let range = first..first + node.prim_count as usize;
            if let Visit::Stop = leaf(range, &mut ray) {
                return;
            }
            continue;
        }
        // Children are `first` and `first + 1`; the nearer one is pushed last.
        let children =
            [first, first + 1].map(|c| enters(&bvh.nodes[c].aabb, &ray).map(|t| (c as u32, t)));
        match children {
            [Some(a), Some(b)] if a.1 <= b.1 => stack.extend([b, a]),
            [Some(a), Some(b)] => stack.extend([a, b]),
            [Some(a), None] | [None, Some(a)] => stack.push(a),
            [None, None] => {}
        }
    }
}

/// The distance at which `ray` enters `aabb` within (0, tmax], or `None` when it misses.
/// Conservative: the far distance is enlarged by the slab test's worst rounding error.
fn enters(aabb: &Aabb, ray: &Ray) -> Option<f32> {
    let t1 = (aabb.min - ray.origin) * ray.inv_direction;
    let t2 = (aabb.max - ray.origin) * ray.inv_direction;
    let near = t1.min(t2).max_element().max(0.0);
    let far = t1.max(t2).min_element() * (1.0 + 2.0 * gamma(3));
    (near <= far && near <= ray.tmax).then_some(near)
}

/// Whether a triangle has no area at f32 precision (the triangles every hierarchy of the judge,
/// and the GPU tracer, leaves out): its height over its longest edge is below 1e-6 of that
/// edge (whatever the vertex order). Such a triangle cannot occlude anything, but the
/// ray-triangle test divides by its vanishing normal and reports hits far outside it.
pub fn has_no_area([v0, v1, v2]: &[Vec3; 3]) -> bool {
    let twice_area = (*v1 - *v0).cross(*v2 - *v0).length();
    let longest = [*v1 - *v0, *v2 - *v1, *v0 - *v2]
        .map(|e| e.length_squared())
        .into_iter()
        .fold(0.0f32, f32::max);
    // height / longest = twice_area / longest^2; NaN (non-finite corners) is degenerate too.
    twice_area.partial_cmp(&(1e-6 * longest)) != Some(std::cmp::Ordering::Greater)
}

/// The reciprocal of a direction component for slab tests: correctly rounded, except that it
/// stays finite (a 0 gives a huge positive value, so no 0 x inf = NaN; components below 1e-30,
/// which no unit direction of a scene has, are clamped too). obvhs's own `Ray::new` clamps every
/// |x| <= f32::EPSILON to 1 / f32::EPSILON, which makes slabs of near-axis rays (components
/// of 1e-7) end too early.
fn reciprocal(x: f32) -> f32 {
    const HUGE: f32 = 1e30;
    if x == 0.0 {
        HUGE
    } else {
        (1.0 / x).clamp(-HUGE, HUGE)
    }
}
