//! Shadow-casting triangles in a BVH, queried with occlusion rays.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use zoo_scene::Scene;

/// Side length of the canonical frame the BVH works in (see [`Occluders::occluded`]).
const CANONICAL_SIZE: f32 = 1024.0;
/// Hits closer to the ray origin than this (canonical units, 2e-7 of the scene's diagonal)
/// are ignored: obvhs skips BVH nodes that end before 1e-4, so a smaller distance could be
/// found by one path and not another. The judge offsets origins by 2e-5 of the diagonal.
const CANONICAL_TMIN: f32 = 2e-4;
/// Padding of the triangles' boxes in the BVH (canonical units, 4e-6 of the diagonal): about
/// 65 ulps of the largest canonical coordinate (512).
const BOX_PADDING: f32 = 4e-3;

/// Triangles in a BVH, in a canonical frame ([`CanonicalFrame`]).
pub(crate) struct TriangleBvh {
    bvh: CwBvh,
    triangles: Vec<Triangle>,
    /// Per kept triangle: the index of the input triangle it came from.
    sources: Vec<usize>,
}

impl TriangleBvh {
    /// Builds the BVH over the non-degenerate ones of `triangles` (already canonical).
    pub(crate) fn new(triangles: &[Triangle]) -> TriangleBvh {
        let (sources, triangles): (Vec<usize>, Vec<Triangle>) = triangles
            .iter()
            .enumerate()
            .filter(|(_, t)| !is_degenerate(t))
            .map(|(i, t)| (i, *t))
            .unzip();
        // Leaf boxes are padded so that node tests, which lose about one ulp of the canonical
        // coordinates, never reject a ray that the triangle test accepts.
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| {
                let b = t.aabb();
                Aabb::new(
                    b.min - Vec3A::splat(BOX_PADDING),
                    b.max + Vec3A::splat(BOX_PADDING),
                )
            })
            .collect();
        let bvh = build_cwbvh(
            &boxes,
            BvhBuildParams::fast_build(),
            &mut Duration::default(),
        );
        TriangleBvh {
            bvh,
            triangles,
            sources,
        }
    }

    /// The nearest triangle `ray` hits before its `tmax`: its source index and distance (in
    /// the ray's frame).
    pub(crate) fn closest(&self, ray: Ray) -> Option<(usize, f32)> {
        if self.triangles.is_empty() {
            return None;
        }
        let mut hit = obvhs::ray::RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |ray, id| {
            let index = self.bvh.primitive_indices[id] as usize;
            self.triangles[index].intersect(ray)
        });
        found.then(|| {
            let index = self.bvh.primitive_indices[hit.primitive_id as usize] as usize;
            (self.sources[index], hit.t)
        })
    }

    /// Whether `ray` hits any triangle before its `tmax`.
    fn any_hit(&self, ray: Ray) -> bool {
        !self.triangles.is_empty()
            && !self.bvh.ray_traverse_miss(ray, |ray, id| {
                let index = self.bvh.primitive_indices[id] as usize;
                self.triangles[index].intersect(ray)
            })
    }

    /// Calls `hit` with the source index of every triangle `ray` crosses before its `tmax`.
    fn each_hit(&self, ray: Ray, mut hit: impl FnMut(usize)) {
        if self.triangles.is_empty() {
            return;
        }
        self.bvh.ray_traverse_miss(ray, |ray, id| {
            let index = self.bvh.primitive_indices[id] as usize;
            if self.triangles[index].intersect(ray) < ray.tmax {
                hit(self.sources[index]);
            }
            // Never report a hit, so traversal visits every candidate.
            f32::INFINITY
        });
    }
}

/// The frame BVHs work in: the scene centred and scaled so that its diagonal is
/// [`CANONICAL_SIZE`] (obvhs culls nodes that end before a fixed 1e-4, which would otherwise
/// drop nearby triangles in small scenes).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CanonicalFrame {
    /// World-space centre.
    centre: Vec3,
    /// World to canonical scale.
    scale: f32,
}

impl CanonicalFrame {
    /// The frame of world-space `triangles`.
    pub(crate) fn of<'a>(triangles: impl Iterator<Item = &'a [Vec3; 3]>) -> CanonicalFrame {
        let (lo, hi) = triangles
            .flatten()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(*v), hi.max(*v))
            });
        if !lo.is_finite() || !hi.is_finite() {
            return CanonicalFrame {
                centre: Vec3::ZERO,
                scale: 1.0,
            };
        }
        let diagonal = lo.distance(hi);
        CanonicalFrame {
            centre: (lo + hi) * 0.5,
            scale: if diagonal > 0.0 {
                CANONICAL_SIZE / diagonal
            } else {
                1.0
            },
        }
    }

    /// A world triangle in this frame.
    pub(crate) fn triangle(&self, [a, b, c]: &[Vec3; 3]) -> Triangle {
        let canonical = |v: Vec3| Vec3A::from((v - self.centre) * self.scale);
        Triangle {
            v0: canonical(*a),
            v1: canonical(*b),
            v2: canonical(*c),
        }
    }

    /// A world ray up to world distance `tmax` in this frame (`None` when not finite).
    pub(crate) fn ray(&self, origin: Vec3, direction: Vec3, tmax: f32) -> Option<Ray> {
        if !direction.is_finite() || !origin.is_finite() {
            return None;
        }
        // -0.0 + 0.0 == +0.0; every other value is unchanged.
        let direction = Vec3A::from(direction) + Vec3A::ZERO;
        Some(Ray {
            origin: Vec3A::from((origin - self.centre) * self.scale),
            direction,
            inv_direction: direction.map(reciprocal),
            tmin: CANONICAL_TMIN,
            tmax: tmax * self.scale,
        })
    }

    /// A distance in this frame back in world units.
    pub(crate) fn world_distance(&self, t: f32) -> f32 {
        t / self.scale
    }
}

/// Translucent shadow casters: their triangles, the object each belongs to, and the colour
/// each object lets through.
struct TranslucentCasters {
    bvh: TriangleBvh,
    /// Per input triangle: its object (an index into `transmittance`).
    owners: Vec<usize>,
    transmittance: Vec<Vec3>,
}

/// The occluding geometry of a scene: opaque casters, which block shadow rays, and
/// translucent ones, each of which filters a ray that crosses it once by its transmittance
/// colour (however many of its surfaces the ray crosses).
///
/// The triangles are stored in a canonical frame (centred on the scene, scaled so that its
/// diagonal is [`CANONICAL_SIZE`]): obvhs culls BVH nodes that end before a fixed distance of
/// 1e-4 from the ray origin, which would otherwise drop nearby occluders in small scenes.
pub struct Occluders {
    opaque: TriangleBvh,
    translucent: Option<TranslucentCasters>,
    frame: CanonicalFrame,
    epsilon: f32,
}

/// An object's world-space triangles.
fn object_triangles(scene: &Scene, object: &zoo_scene::SceneObject) -> Vec<[Vec3; 3]> {
    scene.mesh.indices[object.indices.clone()]
        .chunks_exact(3)
        .map(|tri| [tri[0], tri[1], tri[2]].map(|i| scene.mesh.positions[i as usize]))
        .collect()
}

impl Occluders {
    /// The triangles of every shadow-casting object of `scene`: opaque objects block, and
    /// translucent ones (opacity below 1) filter.
    pub fn new(scene: &Scene) -> Occluders {
        let mut opaque = Vec::new();
        let mut translucent = Vec::new();
        for object in scene.objects.iter().filter(|o| o.casts_shadows) {
            let triangles = object_triangles(scene, object);
            match object.transmittance() {
                None => opaque.extend(triangles),
                Some(t) => translucent.push((triangles, t)),
            }
        }
        let (lo, hi) = scene.bounds();
        Occluders::with_translucent(&opaque, &translucent, lo.distance(hi))
    }

    /// Opaque occluders from world-space triangles in a scene of the given diagonal size.
    pub fn from_triangles(triangles: &[[Vec3; 3]], scene_size: f32) -> Occluders {
        Occluders::with_translucent(triangles, &[], scene_size)
    }

    /// Opaque triangles and translucent objects (their triangles and the colour each lets
    /// through) in a scene of the given diagonal size.
    pub fn with_translucent(
        opaque: &[[Vec3; 3]],
        translucent: &[(Vec<[Vec3; 3]>, Vec3)],
        scene_size: f32,
    ) -> Occluders {
        let frame = CanonicalFrame::of(
            opaque
                .iter()
                .chain(translucent.iter().flat_map(|(t, _)| t.iter())),
        );
        let to_canonical = |tris: &mut dyn Iterator<Item = &[Vec3; 3]>| -> Vec<Triangle> {
            tris.map(|t| frame.triangle(t)).collect()
        };
        let translucent = (!translucent.is_empty()).then(|| TranslucentCasters {
            bvh: TriangleBvh::new(&to_canonical(
                &mut translucent.iter().flat_map(|(t, _)| t.iter()),
            )),
            owners: translucent
                .iter()
                .enumerate()
                .flat_map(|(k, (t, _))| std::iter::repeat_n(k, t.len()))
                .collect(),
            transmittance: translucent.iter().map(|(_, t)| *t).collect(),
        });
        Occluders {
            opaque: TriangleBvh::new(&to_canonical(&mut opaque.iter())),
            translucent,
            frame,
            epsilon: (scene_size * 2e-5).max(1e-5),
        }
    }

    /// Number of triangles (opaque and translucent).
    pub fn len(&self) -> usize {
        self.opaque.triangles.len()
            + self
                .translucent
                .as_ref()
                .map_or(0, |t| t.bvh.triangles.len())
    }

    /// Whether there are no occluders.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether any caster is translucent.
    pub fn has_translucent(&self) -> bool {
        self.translucent.is_some()
    }

    /// Offset along the normal applied to ray origins (scaled to the scene).
    pub fn epsilon(&self) -> f32 {
        self.epsilon
    }

    /// Whether an opaque caster lies on the segment from `origin` along unit `direction` up to
    /// `tmax`.
    ///
    /// Exact for every direction, including axis-aligned ones: obvhs 0.4 picks each slab's near
    /// plane from `direction < 0` but inverts -0.0 to a negative reciprocal, so a -0.0 component
    /// (from negating a light direction with a 0 component) made every BVH node miss. Negative
    /// zeros are turned into positive ones and the ray's reciprocals are computed here (see
    /// [`reciprocal`]). Occluders closer than 2e-7 of the scene's diagonal are not counted.
    pub fn occluded(&self, origin: Vec3, direction: Vec3, tmax: f32) -> bool {
        self.canonical_ray(origin, direction, tmax)
            .is_some_and(|ray| self.opaque.any_hit(ray))
    }

    /// The colour fraction of light that travels the segment: 0 when an opaque caster is on
    /// it, else the product of the transmittance of every translucent object it crosses.
    pub fn transmittance(&self, origin: Vec3, direction: Vec3, tmax: f32) -> Vec3 {
        let Some(ray) = self.canonical_ray(origin, direction, tmax) else {
            return Vec3::ONE;
        };
        if self.opaque.any_hit(ray) {
            return Vec3::ZERO;
        }
        let Some(translucent) = &self.translucent else {
            return Vec3::ONE;
        };
        let mut crossed = vec![false; translucent.transmittance.len()];
        translucent
            .bvh
            .each_hit(ray, |source| crossed[translucent.owners[source]] = true);
        crossed
            .iter()
            .zip(&translucent.transmittance)
            .filter(|(c, _)| **c)
            .fold(Vec3::ONE, |product, (_, t)| product * *t)
    }

    /// The query as a ray in the canonical frame (`None` when nothing can be hit).
    fn canonical_ray(&self, origin: Vec3, direction: Vec3, tmax: f32) -> Option<Ray> {
        if self.is_empty() {
            return None;
        }
        self.frame.ray(origin, direction, tmax)
    }
}

/// Whether a triangle has no area at f32 precision: its height over its longest edge is below
/// 1e-6 of that edge (whatever the vertex order). Such a triangle cannot occlude anything, but
/// the ray-triangle test divides by its vanishing normal and reports hits far outside it.
fn is_degenerate(t: &Triangle) -> bool {
    let twice_area = (t.v1 - t.v0).cross(t.v2 - t.v0).length();
    let longest = [t.v1 - t.v0, t.v2 - t.v1, t.v0 - t.v2]
        .map(|e| e.length_squared())
        .into_iter()
        .fold(0.0f32, f32::max);
    // height / longest = twice_area / longest^2; NaN (non-finite corners) is degenerate too.
    twice_area.partial_cmp(&(1e-6 * longest)) != Some(std::cmp::Ordering::Greater)
}

/// The reciprocal of a direction component for slab tests: exact except that it stays finite
/// (a 0 gives a huge positive value, so no 0 x inf = NaN) and has the sign obvhs's traversal
/// assumes (negative exactly when the component is < 0). obvhs's own `Ray::new` clamps every
/// |x| <= f32::EPSILON to 1 / f32::EPSILON, which makes slabs of near-axis rays (components
/// of 1e-7) end too early, and gives -0.0 a negative reciprocal.
fn reciprocal(x: f32) -> f32 {
    const HUGE: f32 = 1e30;
    if x == 0.0 {
        HUGE
    } else {
        (1.0 / x).clamp(-HUGE, HUGE)
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
        // The direction of a light shining straight down, negated: (-0, 1, -0).
        assert!(o.occluded(Vec3::ZERO, -Vec3::NEG_Y, 5.0));
    }

    /// Small deterministic generator (PCG-style LCG with an xorshift output).
    struct Rng(u64);

    impl Rng {
        fn next_u32(&mut self) -> u32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = self.0 ^ (self.0 >> 33);
            (x >> 16) as u32
        }
        fn unit(&mut self) -> f32 {
            (self.next_u32() >> 8) as f32 / (1u32 << 24) as f32
        }
        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.unit()
        }
        fn below(&mut self, n: u32) -> u32 {
            self.next_u32() % n
        }
        fn sign(&mut self) -> f32 {
            if self.below(2) == 0 { 1.0 } else { -1.0 }
        }
        /// An integer grid coordinate: vertices and origins share these planes.
        fn grid(&mut self) -> f32 {
            self.below(17) as f32 - 8.0
        }
    }

    fn random_triangles(rng: &mut Rng, count: usize) -> Vec<[Vec3; 3]> {
        (0..count)
            .map(|i| {
                if i % 2 == 0 {
                    // Axis-aligned and grid-snapped: faces of BVH boxes lie on grid planes.
                    let axis = rng.below(3) as usize;
                    let at = rng.grid();
                    let mut corner = || {
                        let mut v = Vec3::new(rng.grid(), rng.grid(), rng.grid());
                        v[axis] = at;
                        v
                    };
                    [corner(), corner(), corner()]
                } else {
                    let centre = Vec3::new(
                        rng.range(-8.0, 8.0),
                        rng.range(-8.0, 8.0),
                        rng.range(-8.0, 8.0),
                    );
                    let mut corner = || {
                        centre
                            + Vec3::new(
                                rng.range(-2.0, 2.0),
                                rng.range(-2.0, 2.0),
                                rng.range(-2.0, 2.0),
                            )
                    };
                    [corner(), corner(), corner()]
                }
            })
            .collect()
    }

    /// Directions that break careless slab tests: exact axes with +0.0 and -0.0 in every other
    /// component, near-axis directions (1e-7 components), one zero component, and random ones.
    fn tricky_direction(rng: &mut Rng) -> Vec3 {
        let zero = |rng: &mut Rng| if rng.below(2) == 0 { 0.0 } else { -0.0 };
        match rng.below(5) {
            0 => {
                let mut d = Vec3::new(zero(rng), zero(rng), zero(rng));
                d[rng.below(3) as usize] = rng.sign();
                d
            }
            1 => {
                let mut d = Vec3::new(rng.sign() * 1e-7, rng.sign() * 1e-7, rng.sign() * 1e-7);
                d[rng.below(3) as usize] = rng.sign();
                d.normalize()
            }
            2 => {
                let mut d = Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                d[rng.below(3) as usize] = zero(rng);
                if d.length() < 1e-3 {
                    d = Vec3::new(zero(rng), 1.0, zero(rng));
                }
                // Negating as the judge does for light directions turns 0.0 into -0.0.
                d.normalize()
            }
            _ => loop {
                let d = Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                if d.length() > 0.1 {
                    break d.normalize();
                }
            },
        }
    }

    /// Origins in open space, and origins lying exactly on grid planes (box faces).
    fn tricky_origin(rng: &mut Rng) -> Vec3 {
        let mut o = Vec3::new(
            rng.range(-10.0, 10.0),
            rng.range(-10.0, 10.0),
            rng.range(-10.0, 10.0),
        );
        for axis in 0..3 {
            if rng.below(2) == 0 {
                o[axis] = rng.grid();
            }
        }
        o
    }

    #[test]
    fn bvh_agrees_with_brute_force_for_axis_and_near_axis_rays() {
        let mut rng = Rng(0x5eed_1234);
        let mut disagreements = Vec::new();
        let mut hits = 0;
        let mut rays = 0;
        for scene in 0..10 {
            let triangles = random_triangles(&mut rng, 150 + 60 * scene);
            let occluders = Occluders::from_triangles(&triangles, 30.0);
            for _ in 0..10_000 {
                let origin = tricky_origin(&mut rng);
                let direction = tricky_direction(&mut rng);
                let tmax = if rng.below(2) == 0 {
                    f32::INFINITY
                } else {
                    rng.range(0.5, 20.0)
                };
                let bvh = occluders.occluded(origin, direction, tmax);
                let ray = occluders.canonical_ray(origin, direction, tmax).unwrap();
                let brute = occluders
                    .opaque
                    .triangles
                    .iter()
                    .any(|t| t.intersect(&ray) < ray.tmax);
                rays += 1;
                hits += usize::from(brute);
                if bvh != brute && disagreements.len() < 10 {
                    disagreements.push((scene, origin, direction, tmax, brute));
                }
            }
        }
        assert_eq!(rays, 100_000);
        assert!(
            hits > rays / 10,
            "too few occluded rays to mean anything: {hits}"
        );
        assert!(
            disagreements.is_empty(),
            "BVH and brute force disagree (scene, origin, direction, tmax, brute force):\n{disagreements:#?}"
        );
    }

    #[test]
    fn degenerate_triangles_never_occlude() {
        // Collinear corners: found in real meshes, and the ray-triangle test divides by zero.
        let collinear = [[
            Vec3::new(4.0, 0.0, -4.0),
            Vec3::new(6.0, -2.0, -4.0),
            Vec3::new(0.0, 4.0, -4.0),
        ]];
        let o = Occluders::from_triangles(&collinear, 10.0);
        assert!(o.is_empty());
        // The same in every vertex order, and a sliver whose thin angle is at any corner.
        let [a, b, c] = collinear[0];
        for tri in [[b, c, a], [c, a, b], [a, c, b]] {
            assert!(Occluders::from_triangles(&[tri], 10.0).is_empty());
        }
        let sliver = [
            Vec3::ZERO,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(5.0, 1e-6, 0.0),
        ];
        let [a, b, c] = sliver;
        for tri in [[a, b, c], [b, c, a], [c, a, b]] {
            assert!(Occluders::from_triangles(&[tri], 10.0).is_empty());
        }
        let thin_but_real = [
            Vec3::ZERO,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(5.0, 1e-3, 0.0),
        ];
        assert_eq!(Occluders::from_triangles(&[thin_but_real], 10.0).len(), 1);
        assert!(!o.occluded(
            Vec3::new(-2.0, 6.0, -3.0),
            Vec3::new(-1e-7, -1e-7, -1.0),
            4.0
        ));
        assert!(!o.occluded(Vec3::new(4.0, 0.0, 0.0), Vec3::NEG_Z, 10.0));
    }

    #[test]
    fn nearby_occluders_are_found_at_every_scale() {
        for scale in [1e-3f32, 1.0, 1e3] {
            let tri = [[
                Vec3::new(-1.0, 1.0, -1.0) * scale,
                Vec3::new(1.0, 1.0, -1.0) * scale,
                Vec3::new(0.0, 1.0, 1.0) * scale,
            ]];
            let o = Occluders::from_triangles(&tri, 3.0 * scale);
            // The triangle lies 1e-3 of the scene's size above the origin.
            let origin = Vec3::new(0.0, 1.0 - 1e-3, 0.0) * scale;
            assert!(o.occluded(origin, Vec3::Y, f32::INFINITY), "scale {scale}");
            assert!(
                o.occluded(origin, -Vec3::NEG_Y, f32::INFINITY),
                "scale {scale}"
            );
            assert!(
                !o.occluded(origin, Vec3::NEG_Y, f32::INFINITY),
                "scale {scale}"
            );
        }
    }
}
