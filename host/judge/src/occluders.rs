//! Shadow-casting triangles, queried with occlusion rays.

use glam::Vec3;
use zoo_scene::{AlphaMask, Scene, Textures};

use crate::bvh::Query;
use crate::placed::PlacedTriangles;
use crate::surfaces::texture_coordinates;

/// Translucent shadow casters: their triangles (one part per object) and the colour each
/// object lets through.
struct TranslucentCasters {
    triangles: PlacedTriangles,
    transmittance: Vec<Vec3>,
}

/// Alpha-tested casters: their triangles (one part per object) and each object's mask.
struct AlphaTestedCasters {
    triangles: PlacedTriangles,
    masks: Vec<AlphaMask>,
    textures: Textures,
}

impl AlphaTestedCasters {
    /// Whether the hit `t` along the ray on triangle `index` lands on the mask's
    /// coverage (alpha at or above the cutoff), read where the hit point's barycentric
    /// coordinates put it in the texture.
    fn blocks(&self, index: usize, origin: Vec3, direction: Vec3, t: f32) -> bool {
        let triangle = self.triangles.triangle(index);
        let mask = self.masks[triangle.part];
        let uv = texture_coordinates(&triangle.corners, &triangle.uvs, origin + direction * t);
        self.textures.alpha(mask.layer, uv) >= mask.cutoff
    }
}

/// The occluding geometry of a scene: opaque casters, which block shadow rays; masked ones,
/// which block them where their alpha mask covers the hit point (exactly, at the texture's
/// full resolution); and translucent ones, each of which filters a ray that crosses it once
/// by its transmittance colour (however many of its surfaces the ray crosses).
///
/// Triangles stay in their stored coordinates (world space, or an instance's shared mesh,
/// which rays enter through the inverse of its placement: [`PlacedTriangles`]), and nothing is
/// measured against the scene's size: every hit farther than 0 from the ray origin counts
/// (origins come off their surface by their error bound, [`crate::SurfacePoint::ray_origin`]).
pub struct Occluders {
    opaque: PlacedTriangles,
    masked: Option<AlphaTestedCasters>,
    translucent: Option<TranslucentCasters>,
}

impl Occluders {
    /// The triangles of every shadow-casting object of `scene`: opaque objects block, masked
    /// ones block where their mask covers, and translucent ones (opacity below 1) filter.
    /// Instances share their triangles here too.
    pub fn new(scene: &Scene) -> Occluders {
        let casters = || scene.objects.iter().filter(|o| o.casts_shadows);
        let opaque = casters().filter(|o| o.transmittance().is_none() && o.alpha_mask.is_none());
        let masked: Vec<_> = casters()
            .filter(|o| o.transmittance().is_none() && o.alpha_mask.is_some())
            .collect();
        let translucent: Vec<_> = casters().filter(|o| o.transmittance().is_some()).collect();
        Occluders {
            opaque: PlacedTriangles::new(scene, opaque),
            masked: (!masked.is_empty()).then(|| AlphaTestedCasters {
                masks: masked.iter().filter_map(|o| o.alpha_mask).collect(),
                triangles: PlacedTriangles::new(scene, masked),
                textures: scene.textures.clone(),
            }),
            translucent: (!translucent.is_empty()).then(|| TranslucentCasters {
                transmittance: translucent
                    .iter()
                    .filter_map(|o| o.transmittance())
                    .collect(),
                triangles: PlacedTriangles::new(scene, translucent),
            }),
        }
    }

    /// Opaque occluders from world-space triangles.
    pub fn from_triangles(triangles: &[[Vec3; 3]]) -> Occluders {
        Occluders::with_translucent(triangles, &[])
    }

    /// Opaque world-space triangles, and translucent objects (their world-space triangles and
    /// the colour each lets through).
    pub fn with_translucent(
        opaque: &[[Vec3; 3]],
        translucent: &[(Vec<[Vec3; 3]>, Vec3)],
    ) -> Occluders {
        Occluders {
            opaque: PlacedTriangles::from_triangles(opaque),
            masked: None,
            translucent: (!translucent.is_empty()).then(|| TranslucentCasters {
                triangles: PlacedTriangles::from_parts(
                    translucent.iter().map(|(t, _)| t.as_slice()),
                ),
                transmittance: translucent.iter().map(|(_, t)| *t).collect(),
            }),
        }
    }

    /// Number of triangles (opaque, masked and translucent; an instance's each time).
    pub fn len(&self) -> usize {
        self.opaque.len()
            + self.masked.as_ref().map_or(0, |m| m.triangles.len())
            + self.translucent.as_ref().map_or(0, |t| t.triangles.len())
    }

    /// Whether there are no occluders.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether any caster is translucent.
    pub fn has_translucent(&self) -> bool {
        self.translucent.is_some()
    }

    /// Whether an opaque caster lies on the segment from `origin` along unit `direction` up to
    /// `tmax` (any hit at a distance above 0 counts).
    ///
    /// Exact for every direction, including axis-aligned ones and -0.0 components (turned
    /// into +0.0 before the slab tests' reciprocals).
    pub fn occluded(&self, origin: Vec3, direction: Vec3, tmax: f32) -> bool {
        Query::new(origin, direction, tmax).is_some_and(|q| self.blocked(&q, origin, direction))
    }

    /// Whether an opaque caster, or a masked one where its mask covers, is on `query`.
    fn blocked(&self, query: &Query, origin: Vec3, direction: Vec3) -> bool {
        self.opaque.any_hit_where(query, |_, _| true)
            || self.masked.as_ref().is_some_and(|m| {
                (m.triangles).any_hit_where(query, |i, t| m.blocks(i, origin, direction, t))
            })
    }

    /// The colour fraction of light that travels the segment: 0 when an opaque caster is on
    /// it, else the product of the transmittance of every translucent object it crosses.
    pub fn transmittance(&self, origin: Vec3, direction: Vec3, tmax: f32) -> Vec3 {
        let Some(query) = Query::new(origin, direction, tmax) else {
            return Vec3::ONE;
        };
        if self.blocked(&query, origin, direction) {
            return Vec3::ZERO;
        }
        let Some(translucent) = &self.translucent else {
            return Vec3::ONE;
        };
        let mut crossed = vec![false; translucent.transmittance.len()];
        (translucent.triangles).each_hit(&query, |index| {
            crossed[translucent.triangles.part(index)] = true
        });
        crossed
            .iter()
            .zip(&translucent.transmittance)
            .filter(|(c, _)| **c)
            .fold(Vec3::ONE, |product, (_, t)| product * *t)
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
        let o = Occluders::from_triangles(&tri);
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
    fn bvh_agrees_with_brute_force_for_axis_and_near_axis_rays_and_nearest_hits() {
        let mut rng = Rng(0x5eed_1234);
        let mut disagreements = Vec::new();
        let mut closest_disagreements = Vec::new();
        let mut hits = 0;
        let mut rays = 0;
        for scene in 0..10 {
            let triangles = random_triangles(&mut rng, 150 + 60 * scene);
            let occluders = Occluders::from_triangles(&triangles);
            for _ in 0..10_000 {
                let origin = tricky_origin(&mut rng);
                let direction = tricky_direction(&mut rng);
                let tmax = if rng.below(2) == 0 {
                    f32::INFINITY
                } else {
                    rng.range(0.5, 20.0)
                };
                let bvh = occluders.occluded(origin, direction, tmax);
                let query = Query::new(origin, direction, tmax).unwrap();
                let brute = occluders.opaque.any_hit_brute_force(&query);
                // The nearest hit too: the same triangle (or one at the same distance).
                let nearest = occluders.opaque.closest(&query);
                let nearest_brute = occluders.opaque.closest_brute_force(&query);
                let same_nearest = match (nearest, nearest_brute) {
                    (Some((a, ta)), Some((b, tb))) => a == b || ta == tb,
                    (None, None) => true,
                    _ => false,
                };
                if !same_nearest && closest_disagreements.len() < 10 {
                    closest_disagreements.push((scene, origin, direction, nearest, nearest_brute));
                }
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
        assert!(
            closest_disagreements.is_empty(),
            "nearest hits disagree (scene, origin, direction, BVH, brute force):\n{closest_disagreements:#?}"
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
        let o = Occluders::from_triangles(&collinear);
        assert!(o.is_empty());
        // The same in every vertex order, and a sliver whose thin angle is at any corner.
        let [a, b, c] = collinear[0];
        for tri in [[b, c, a], [c, a, b], [a, c, b]] {
            assert!(Occluders::from_triangles(&[tri]).is_empty());
        }
        let sliver = [
            Vec3::ZERO,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(5.0, 1e-6, 0.0),
        ];
        let [a, b, c] = sliver;
        for tri in [[a, b, c], [b, c, a], [c, a, b]] {
            assert!(Occluders::from_triangles(&[tri]).is_empty());
        }
        let thin_but_real = [
            Vec3::ZERO,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(5.0, 1e-3, 0.0),
        ];
        assert_eq!(Occluders::from_triangles(&[thin_but_real]).len(), 1);
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
            let o = Occluders::from_triangles(&tri);
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
