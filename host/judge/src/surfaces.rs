//! The surface seen at each pixel, located on the scene's exact triangles, and where rays from
//! it start.

use glam::{Vec2, Vec3};
use zoo_scene::Scene;

use crate::bvh::Query;
use crate::placed::{DrawnTriangle, PlacedTriangles};
use crate::robust::{gamma, magnitude, offset_along, plane_test_error};

/// How far (relative to the view distance) the surface the judge finds along a pixel's ray
/// may lie from the G-buffer's position and still be taken as the same surface. Rasterisers
/// snap vertices to sub-pixel grids, which moves a grazing surface's depth by about 1e-4 of
/// the view distance; beyond this the pixel is a silhouette the ray misses.
const GBUFFER_AGREEMENT: f32 = 1.0 / 512.0;

/// A surface point that rays leave from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub position: Vec3,
    /// Unit shading normal on the side facing the camera: decides whether a light reaches
    /// the point and weights area samples.
    pub normal: Vec3,
    /// Unit normal of the triangle's plane on the side facing the camera: rays start on
    /// this side, so a triangle facing away from a light shadows its own points.
    pub geometric_normal: Vec3,
    /// The distance rays start from `position` along `geometric_normal`: the bound on the
    /// position's error off the surface, plus the ray-triangle test's error.
    pub offset: f32,
}

impl SurfacePoint {
    /// A point exactly on a flat surface with unit `normal` (geometric and shading), lying on
    /// a well-shaped triangle (angles far from 0) whose coordinates and size are at most
    /// `magnitude`: for analytic surfaces, such as test planes, that no G-buffer sees.
    pub fn on_plane(position: Vec3, normal: Vec3, magnitude: f32) -> SurfacePoint {
        let magnitude = magnitude.max(position.abs().max_element());
        SurfacePoint {
            position,
            normal,
            geometric_normal: normal,
            offset: gamma(2) * magnitude + gamma(8) * 2.0 * magnitude,
        }
    }

    /// Where rays from this point start: `position` moved off the surface by `offset` along
    /// the geometric normal.
    pub fn ray_origin(&self) -> Vec3 {
        offset_along(self.position, self.geometric_normal, self.offset)
    }
}

/// Where a ray meets a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    /// The point, its normal on the side the ray came from (shading normal = geometric
    /// normal), and its ray offset.
    pub point: SurfacePoint,
    /// Index of the input triangle.
    pub triangle: usize,
    pub distance: f32,
}

/// Every triangle of a scene (shadow casters or not), to find the exact surface seen through
/// a pixel or by a ray. Triangles are numbered by the judge's triangle index, one part per object (see
/// [`PlacedTriangles`]).
pub struct Surfaces {
    triangles: PlacedTriangles,
}

impl Surfaces {
    /// Every object of `scene` (instances sharing their triangles).
    pub fn new(scene: &Scene) -> Surfaces {
        Surfaces {
            triangles: PlacedTriangles::new(scene, &scene.objects),
        }
    }

    /// Surfaces from world-space triangles.
    pub fn from_triangles(triangles: Vec<[Vec3; 3]>) -> Surfaces {
        Surfaces::from_parts(&[triangles])
    }

    /// Surfaces from world-space triangles in parts (each triangle's part is its index in
    /// `parts`).
    pub(crate) fn from_parts(parts: &[Vec<[Vec3; 3]>]) -> Surfaces {
        Surfaces {
            triangles: PlacedTriangles::from_parts(parts.iter().map(Vec::as_slice)),
        }
    }

    /// The world-space corners of triangle `index`.
    pub fn corners(&self, index: usize) -> [Vec3; 3] {
        self.triangles.triangle(index).corners
    }

    /// The part (object) that holds triangle `index`.
    pub(crate) fn part(&self, index: usize) -> usize {
        self.triangles.part(index)
    }

    /// Triangle `index`: its part, world corners and texture coordinates.
    pub(crate) fn triangle(&self, index: usize) -> DrawnTriangle {
        self.triangles.triangle(index)
    }

    /// The nearest surface from `origin` along unit `direction`.
    pub fn closest(&self, origin: Vec3, direction: Vec3) -> Option<SurfaceHit> {
        self.closest_where(origin, direction, |_, _| true)
    }

    /// The nearest surface that `accept(triangle, distance)` takes.
    pub fn closest_where(
        &self,
        origin: Vec3,
        direction: Vec3,
        accept: impl FnMut(usize, f32) -> bool,
    ) -> Option<SurfaceHit> {
        let query = Query::new(origin, direction, f32::INFINITY)?;
        let (triangle, distance) = self.triangles.closest_where(&query, accept)?;
        let corners = &self.corners(triangle);
        let (position, error) = barycentric_point(corners, origin, direction);
        let mut normal = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize_or_zero();
        if normal.dot(direction) > 0.0 {
            normal = -normal;
        }
        // (On an instance, the ray then enters its stored space through the placement's
        // inverse; the offset along the world normal keeps it above the triangle there too,
        // tested with instances stretched 400:1 30 km from the origin.)
        let offset = normal.abs().dot(error)
            + plane_test_error(corners, magnitude(corners.iter().chain([&position])));
        Some(SurfaceHit {
            point: SurfacePoint {
                position,
                normal,
                geometric_normal: normal,
                offset,
            },
            triangle,
            distance,
        })
    }

    /// The surface a camera at `eye` sees where the G-buffer holds `position` with shading
    /// normal `normal` (facing the camera): the exact point where the ray from the eye
    /// through `position` meets the triangles, with its triangle's normal, when that point
    /// agrees with the G-buffer (within [`GBUFFER_AGREEMENT`] of the view distance).
    /// Elsewhere (silhouettes, where rasterisation covers a pixel centre the ray misses) the
    /// G-buffer's position and normal, offset by the bound on its reconstruction error.
    pub fn locate(&self, eye: Vec3, position: Vec3, normal: Vec3) -> SurfacePoint {
        let to = position - eye;
        let depth = to.length();
        let direction = to / depth;
        if depth > 0.0
            && let Some(hit) = self.closest(eye, direction)
            && (hit.distance - depth).abs() <= GBUFFER_AGREEMENT * depth
        {
            return SurfacePoint {
                normal,
                ..hit.point
            };
        }
        SurfacePoint {
            position,
            normal,
            geometric_normal: normal,
            offset: reconstruction_error(eye, position),
        }
    }
}

/// The relative error of a G-buffer position off its surface (γ₁₆): the position is rebuilt
/// as eye + depth × ray from the rasterised view depth, each step rounding at the magnitude of
/// the eye, the position and the view distance (about 16 roundings in all, with the
/// rasteriser's interpolation of the depth). A margin rather than a strict bound: GPU
/// interpolation is not correctly rounded. The GPU's tracers start their rays off G-buffer
/// positions by the same rule (`zoo_ray_tracing`'s `ray-tracing/origin.wgsl` reads this value).
pub const GBUFFER_POSITION_ERROR: f32 = gamma(16);

/// How far a G-buffer `position` seen from `eye` may lie off its surface:
/// [`GBUFFER_POSITION_ERROR`] of the eye's and the position's largest coordinates and the
/// view distance. The judge starts rays this far off G-buffer positions where the pixel's ray
/// misses the G-buffer's surface (silhouettes); the GPU's tracers everywhere.
pub fn reconstruction_error(eye: Vec3, position: Vec3) -> f32 {
    let depth = (position - eye).length();
    GBUFFER_POSITION_ERROR * (eye.abs().max_element() + position.abs().max_element() + depth)
}

/// The texture coordinates at `point` on the triangle `corners` whose corners have `uvs`
/// (barycentric interpolation; `point` is taken to lie in the triangle's plane).
pub(crate) fn texture_coordinates(corners: &[Vec3; 3], uvs: &[Vec2; 3], point: Vec3) -> Vec2 {
    let [a, b, c] = *corners;
    let (e1, e2, d) = (b - a, c - a, point - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d1, d2) = (d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let (v, w) = ((d22 * d1 - d12 * d2) / det, (d11 * d2 - d12 * d1) / det);
    uvs[0] * (1.0 - v - w) + uvs[1] * v + uvs[2] * w
}

/// The point where the ray from `origin` along `direction` meets the plane of `corners`,
/// computed from its barycentric coordinates (so that its error depends on the triangle's
/// coordinates, not on the ray's length), and the bound on its error per axis:
/// γ₇ (|b₀ v₀| + |b₁ v₁| + |b₂ v₂|) (Pharr, Jakob and Humphreys, PBR 3rd ed., 3.9.5).
fn barycentric_point(corners: &[Vec3; 3], origin: Vec3, direction: Vec3) -> (Vec3, Vec3) {
    let [v0, v1, v2] = *corners;
    let (e1, e2) = (v1 - v0, v2 - v0);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    let s = origin - v0;
    let (b1, b2) = if det != 0.0 {
        let q = s.cross(e1);
        (s.dot(p) / det, direction.dot(q) / det)
    } else {
        (0.0, 0.0)
    };
    let (b1, b2) = (b1.clamp(0.0, 1.0), b2.clamp(0.0, 1.0));
    let total = b1 + b2;
    let (b1, b2) = if total > 1.0 {
        (b1 / total, b2 / total)
    } else {
        (b1, b2)
    };
    let b0 = 1.0 - b1 - b2;
    let position = b0 * v0 + b1 * v1 + b2 * v2;
    let error = gamma(7) * ((b0 * v0).abs() + (b1 * v1).abs() + (b2 * v2).abs());
    (position, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_are_on_the_triangle_and_face_the_ray() {
        let s = Surfaces::from_triangles(vec![[
            Vec3::new(-1.0, 2.0, -1.0),
            Vec3::new(1.0, 2.0, -1.0),
            Vec3::new(0.0, 2.0, 1.0),
        ]]);
        let hit = s.closest(Vec3::new(0.1, 0.0, 0.0), Vec3::Y).expect("above");
        assert!((hit.point.position - Vec3::new(0.1, 2.0, 0.0)).length() < 1e-6);
        assert_eq!(hit.point.geometric_normal, Vec3::NEG_Y);
        assert!((hit.distance - 2.0).abs() < 1e-6);
        assert!(hit.point.offset > 0.0 && hit.point.offset < 1e-5);
        let from_above = s.closest(Vec3::new(0.1, 5.0, 0.0), Vec3::NEG_Y).unwrap();
        assert_eq!(from_above.point.geometric_normal, Vec3::Y);
        assert!(s.closest(Vec3::new(3.0, 0.0, 0.0), Vec3::Y).is_none());
    }

    #[test]
    fn located_points_agree_with_the_gbuffer_or_fall_back_to_it() {
        let floor = vec![
            [
                Vec3::new(-10.0, 0.0, -10.0),
                Vec3::new(-10.0, 0.0, 10.0),
                Vec3::new(10.0, 0.0, 10.0),
            ],
            [
                Vec3::new(-10.0, 0.0, -10.0),
                Vec3::new(10.0, 0.0, 10.0),
                Vec3::new(10.0, 0.0, -10.0),
            ],
        ];
        let s = Surfaces::from_triangles(floor);
        let eye = Vec3::new(0.0, 3.0, 4.0);
        // A G-buffer position a little off the floor (reconstruction error): the exact point
        // on the floor replaces it, with the floor's normal.
        let shading = Vec3::new(0.1, 1.0, 0.0).normalize();
        let seen = s.locate(eye, Vec3::new(1.0, 1e-4, -2.0), shading);
        assert!(seen.position.y.abs() < 1e-6, "{}", seen.position);
        assert_eq!(seen.geometric_normal, Vec3::Y);
        assert_eq!(seen.normal, shading);
        // A position the ray does not reach (a silhouette): the G-buffer's own point.
        let beyond = Vec3::new(30.0, 1.0, 0.0);
        let kept = s.locate(eye, beyond, Vec3::Y);
        assert_eq!(kept.position, beyond);
        assert!(kept.offset > 0.0);
    }
}
