//! Light view and projection matrices: a perspective frustum fitted to a spot cone, an
//! orthographic box fitted to what the camera sees for directional lights, and six 90-degree
//! cube faces (widened by a guard band) for point lights.

use zoo_host::glam::camera::rh::{proj::directx, view::look_to_mat4};
use zoo_host::glam::{Mat4, Vec3, Vec4Swizzles};
use zoo_host::scene::{Camera, Light};

/// How a shadow-map layer projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Perspective with the given tangent of the half field of view.
    Perspective {
        tan_half_fov: f32,
        near: f32,
        far: f32,
    },
    /// Orthographic with the given world extent (width = height) and depth range.
    Orthographic { extent: f32, near: f32, far: f32 },
    /// A general projective map (perspective or light-space perspective shadow maps): texel
    /// sizes vary over the map, so lookups measure them where they are.
    Warped,
}

/// One shadow-map layer's camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightFrustum {
    pub view: Mat4,
    pub view_proj: Mat4,
    pub projection: Projection,
}

impl LightFrustum {
    pub(crate) fn new(view: Mat4, projection: Projection) -> LightFrustum {
        let proj = match projection {
            // Warped layers are built with their own matrix (`LightFrustum::warped`).
            Projection::Warped => Mat4::IDENTITY,
            Projection::Perspective {
                tan_half_fov,
                near,
                far,
            } => directx::perspective(2.0 * tan_half_fov.atan(), 1.0, near, far),
            Projection::Orthographic { extent, near, far } => {
                let h = extent * 0.5;
                directx::orthographic(-h, h, -h, h, near, far)
            }
        };
        LightFrustum {
            view,
            view_proj: proj * view,
            projection,
        }
    }

    /// A layer with any projective `view_proj` (its depth in [0, 1] front to back).
    pub fn warped(view: Mat4, view_proj: Mat4) -> LightFrustum {
        LightFrustum {
            view,
            view_proj,
            projection: Projection::Warped,
        }
    }

    /// World size of one texel of a `resolution`-texel map at `point` (for warped maps: the
    /// larger of the two texel sides across the view ray direction `view`'s z axis).
    pub fn texel_world_size(&self, point: Vec3, resolution: u32) -> f32 {
        match self.projection {
            Projection::Warped => {
                let to_world = self.view.inverse();
                let step = 1e-3 * point.length().max(1.0);
                let uv = |p: Vec3| self.view_proj.project_point3(p).truncate() * 0.5;
                let texels = |axis: Vec3| {
                    let moved = uv(point + to_world.transform_vector3(axis) * step);
                    (moved - uv(point)).length() * resolution as f32 / step
                };
                1.0 / texels(Vec3::X).min(texels(Vec3::Y)).max(1e-12)
            }
            Projection::Perspective { tan_half_fov, .. } => {
                let distance = -self.view.transform_point3(point).z;
                2.0 * distance * tan_half_fov / resolution as f32
            }
            Projection::Orthographic { extent, .. } => extent / resolution as f32,
        }
    }

    /// Whether `point` projects inside the map and its depth range.
    pub fn contains(&self, point: Vec3) -> bool {
        let clip = self.view_proj * point.extend(1.0);
        let ndc = clip.xyz() / clip.w;
        clip.w > 0.0 && ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0 && (0.0..=1.0).contains(&ndc.z)
    }
}

/// An up vector not parallel to `direction`.
pub(crate) fn up_for(direction: Vec3) -> Vec3 {
    if direction.cross(Vec3::Y).length_squared() < 1e-4 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// Near plane of a perspective light map: close enough for nearby casters, far enough to
/// keep depth precision (a thousandth of the range, at any scale).
pub fn perspective_near(range: f32) -> f32 {
    resolvable(range * 1e-3, range)
}

/// `length`, or when it vanishes, the smallest length still resolvable beside coordinates of
/// size `magnitude` (a millionth of it): guards fits of degenerate boxes without a fixed
/// distance, so a fit is the same at every scale.
pub fn resolvable(length: f32, magnitude: f32) -> f32 {
    length.max(magnitude.abs() * 1e-6).max(1e-30)
}

/// Rungs an octave of a stabilised directional map's extent ladder: a map covers at most
/// 2^(1/8), 9 %, more than its fit (coarser rungs waste more texels, 25 % at ratio 1.25, and
/// thin casters fall between them), and changes only when the fit has grown or shrunk by as
/// much.
pub const EXTENT_RUNGS_PER_OCTAVE: f32 = 8.0;

/// The diagonal of the box around `boxes` (1 when there are none): the unit that quantised
/// fits are measured in, so that they scale with the scene.
pub(crate) fn scene_unit(boxes: &[Aabb]) -> f32 {
    let (lo, hi) = boxes.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), b| (lo.min(b.0), hi.max(b.1)),
    );
    if lo.cmple(hi).all() && (hi - lo).is_finite() {
        resolvable(lo.distance(hi), magnitude(lo, hi))
    } else {
        1.0
    }
}

/// The largest absolute coordinate of two points.
pub(crate) fn magnitude(a: Vec3, b: Vec3) -> f32 {
    a.abs().max(b.abs()).max_element()
}

/// A perspective frustum around a spot light's cone (with a small margin).
pub fn spot_frustum(light: &Light) -> LightFrustum {
    let half = (light.spot_angle * 1.05).min(85f32.to_radians());
    let view = look_to_mat4(light.position, light.direction, up_for(light.direction));
    LightFrustum::new(
        view,
        Projection::Perspective {
            tan_half_fov: half.tan(),
            near: perspective_near(light.range),
            far: light.range,
        },
    )
}

/// An orthographic frustum along `direction` holding the whole box `bounds` (a light's view of
/// the entire scene, as reflective shadow maps need: every lit surface, not only what the
/// camera sees).
pub fn directional_frustum_over(direction: Vec3, bounds: Aabb) -> LightFrustum {
    let (lo, hi) = bounds;
    let centre = (lo + hi) * 0.5;
    let radius = resolvable(lo.distance(hi) * 0.5, magnitude(lo, hi));
    let eye = centre - direction * (radius * 1.01);
    let view = look_to_mat4(eye, direction, up_for(direction));
    LightFrustum::new(
        view,
        Projection::Orthographic {
            extent: radius * 2.02,
            near: 0.0,
            far: radius * 2.02,
        },
    )
}

/// Cube face directions and up vectors, in array-layer order +X, -X, +Y, -Y, +Z, -Z.
pub const CUBE_FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Y),
    (Vec3::NEG_X, Vec3::NEG_Y),
    (Vec3::Y, Vec3::Z),
    (Vec3::NEG_Y, Vec3::NEG_Z),
    (Vec3::Z, Vec3::NEG_Y),
    (Vec3::NEG_Z, Vec3::NEG_Y),
];

/// Six faces around a point light. Each covers slightly more than 90 degrees so that filter
/// taps up to `guard_texels` beyond a face edge still land inside the same face's map.
pub fn cube_frustums(light: &Light, resolution: u32, guard_texels: u32) -> [LightFrustum; 6] {
    let inner = resolution.saturating_sub(2 * guard_texels).max(1) as f32;
    let tan_half_fov = resolution as f32 / inner;
    CUBE_FACES.map(|(direction, up)| {
        LightFrustum::new(
            look_to_mat4(light.position, direction, up),
            Projection::Perspective {
                tan_half_fov,
                near: perspective_near(light.range),
                far: light.range,
            },
        )
    })
}

/// The face of the cube whose central 90-degree region contains `direction`.
pub fn cube_face(direction: Vec3) -> usize {
    let a = direction.abs();
    if a.x >= a.y && a.x >= a.z {
        if direction.x >= 0.0 { 0 } else { 1 }
    } else if a.y >= a.z {
        if direction.y >= 0.0 { 2 } else { 3 }
    } else if direction.z >= 0.0 {
        4
    } else {
        5
    }
}

/// World-space axis-aligned box.
pub type Aabb = (Vec3, Vec3);

pub(crate) fn corners((lo, hi): Aabb) -> [Vec3; 8] {
    [0, 1, 2, 3, 4, 5, 6, 7].map(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

pub(crate) fn transformed_bounds(m: Mat4, points: &[Vec3]) -> Aabb {
    points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| {
            let q = m.transform_point3(*p);
            (lo.min(q), hi.max(q))
        },
    )
}

/// World-space corners of the camera's view frustum, its far plane pulled in to `far`.
pub fn camera_frustum_corners(camera: &Camera, aspect: f32, far: f32) -> [Vec3; 8] {
    let view_proj = camera.projection(aspect) * camera.view();
    let inverse = view_proj.inverse();
    // Depth of `far` in the camera's [0, 1] depth range.
    let (n, f) = (camera.near, camera.far);
    let far_depth = (f * (far - n) / (far * (f - n))).clamp(0.0, 1.0);
    let mut out = [Vec3::ZERO; 8];
    for (i, corner) in out.iter_mut().enumerate() {
        let x = if i & 1 == 0 { -1.0 } else { 1.0 };
        let y = if i & 2 == 0 { -1.0 } else { 1.0 };
        let z = if i & 4 == 0 { 0.0 } else { far_depth };
        *corner = inverse.project_point3(Vec3::new(x, y, z));
    }
    out
}

/// An orthographic frustum for a directional light travelling along `direction`: its sides
/// fit the receivers the camera can see (each object's box clipped to the box around the camera
/// frustum), and its depth range reaches back to every caster that can shadow them.
///
/// With `stable_texels` = Some(resolution), the extent is rounded up to a step of a geometric
/// ladder ([`EXTENT_RUNGS_PER_OCTAVE`] rungs an octave, anchored to the size of the objects'
/// bounds) and the centre snapped to whole texels, so small camera moves leave the
/// map unchanged and larger ones move it by whole texels: shadow edges do not shimmer.
pub fn directional_frustum(
    direction: Vec3,
    camera: &Camera,
    aspect: f32,
    objects: &[Aabb],
    casters: &[Aabb],
    stable_texels: Option<u32>,
) -> LightFrustum {
    let view = look_to_mat4(Vec3::ZERO, direction, up_for(direction));
    let all = objects.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), b| (lo.min(b.0), hi.max(b.1)),
    );
    let farthest = corners(all)
        .iter()
        .map(|c| c.distance(camera.position))
        .fold(0.0, f32::max)
        .min(camera.far);
    let frustum = camera_frustum_corners(camera, aspect, farthest);
    let frustum_box = transformed_bounds(Mat4::IDENTITY, &frustum);
    // Receivers: the visible part of every object, in light space.
    let mut visible: Vec<Vec3> = Vec::new();
    for (lo, hi) in objects {
        let (clo, chi) = (lo.max(frustum_box.0), hi.min(frustum_box.1));
        if clo.cmple(chi).all() {
            visible.extend(corners((clo, chi)));
        }
    }
    if visible.is_empty() {
        visible.extend(corners(all));
    }
    let (lo, hi) = transformed_bounds(view, &visible);
    // Casters: anything whose light-space box overlaps the receivers' footprint.
    let mut nearest = hi.z;
    for caster in casters {
        let (clo, chi) = transformed_bounds(view, &corners(*caster));
        if clo.x <= hi.x && chi.x >= lo.x && clo.y <= hi.y && chi.y >= lo.y {
            nearest = nearest.max(chi.z);
        }
    }
    // Square extent centred on the receivers (the map is square).
    let mut extent = resolvable((hi.x - lo.x).max(hi.y - lo.y), magnitude(lo, hi)) * 1.02;
    let mut center = (lo + hi) * 0.5;
    if let Some(resolution) = stable_texels {
        // The ladder's rungs are fractions of the scene's size, not of a world unit, so a
        // scene scaled by any factor gets the same map, scaled. Two texels of margin:
        // rounding the centre moves the receivers by up to half a texel.
        let unit = scene_unit(objects);
        let rung = ((extent / unit).log2() * EXTENT_RUNGS_PER_OCTAVE).floor() + 1.0;
        extent = unit * (rung / EXTENT_RUNGS_PER_OCTAVE).exp2() * (1.0 + 2.0 / resolution as f32);
        let texel = extent / resolution as f32;
        center.x = (center.x / texel).round() * texel;
        center.y = (center.y / texel).round() * texel;
    }
    let margin = resolvable(nearest - lo.z, magnitude(lo, hi).max(nearest.abs())) * 0.01;
    let (mut near, mut far) = (-nearest - margin, -lo.z + margin);
    if stable_texels.is_some() {
        // The depth range moves outward in coarse steps too.
        let step = extent / 16.0;
        near = (near / step).floor() * step;
        far = (far / step).ceil() * step;
    }
    let view = Mat4::from_translation(Vec3::new(-center.x, -center.y, 0.0)) * view;
    LightFrustum::new(view, Projection::Orthographic { extent, near, far })
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::scene::LightKind;

    fn spot() -> Light {
        Light {
            kind: LightKind::Spot,
            position: Vec3::new(1.0, 6.0, 2.0),
            direction: Vec3::new(0.2, -1.0, -0.3).normalize(),
            radiance: Vec3::ONE,
            range: 30.0,
            spot_angle: 35f32.to_radians(),
            spot_softness: 0.2,
            radius: 0.0,
        }
    }

    #[test]
    fn spot_frustum_covers_the_cone() {
        let light = spot();
        let f = spot_frustum(&light);
        // Points on the cone's edge at several distances are inside the map.
        let up = light.direction.cross(Vec3::X).normalize();
        for distance in [0.5, 5.0, 25.0] {
            for k in 0..16 {
                let angle = k as f32 / 16.0 * std::f32::consts::TAU;
                let side = zoo_host::glam::Quat::from_axis_angle(light.direction, angle) * up;
                let edge = light.direction * light.spot_angle.cos() + side * light.spot_angle.sin();
                assert!(
                    f.contains(light.position + edge * distance),
                    "edge at {distance}"
                );
            }
        }
        assert!(
            !f.contains(light.position - light.direction * 2.0),
            "behind the light"
        );
    }

    #[test]
    fn texel_world_size_matches_the_projection() {
        let light = spot();
        let f = spot_frustum(&light);
        let resolution = 2048;
        for distance in [1.0, 4.0, 12.0] {
            let p = light.position + light.direction * distance;
            let size = f.texel_world_size(p, resolution);
            let Projection::Perspective { tan_half_fov, .. } = f.projection else {
                unreachable!()
            };
            assert!((size - 2.0 * distance * tan_half_fov / resolution as f32).abs() < 1e-6);
            // Moving by one texel's world size across the axis moves one texel in the map.
            let side = light.direction.cross(Vec3::Y).normalize();
            let a = f.view_proj.project_point3(p);
            let b = f.view_proj.project_point3(p + side * size);
            let texels = (b - a).truncate().length() * 0.5 * resolution as f32;
            assert!((texels - 1.0).abs() < 1e-3, "{texels} texels");
        }
        // Orthographic: constant.
        let camera = Camera {
            position: Vec3::new(0.0, 5.0, 8.0),
            target: Vec3::ZERO,
            fov_y: 1.0,
            near: 0.1,
            far: 100.0,
        };
        let bounds = (Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 2.0, 5.0));
        let f = directional_frustum(
            Vec3::new(0.3, -1.0, 0.2).normalize(),
            &camera,
            1.0,
            &[bounds],
            &[],
            None,
        );
        let Projection::Orthographic { extent, .. } = f.projection else {
            unreachable!()
        };
        assert_eq!(f.texel_world_size(Vec3::ZERO, 1024), extent / 1024.0);
    }

    #[test]
    fn stable_directional_fits_scale_with_the_scene() {
        // The extent's ladder is anchored to the scene's size: the same scene at any scale gets
        // the same map, scaled (a ladder of world units gave maps up to 25 % apart).
        let fit = |s: f32| {
            let camera = Camera {
                position: Vec3::new(3.0, 4.0, 6.0),
                target: Vec3::ZERO,
                fov_y: 50f32.to_radians(),
                near: 0.1,
                far: 200.0,
            }
            .scaled(s);
            let floor = (
                Vec3::new(-7.0, -0.01, -7.0) * s,
                Vec3::new(7.0, 0.0, 7.0) * s,
            );
            let post = (Vec3::new(-0.3, 0.0, -0.3) * s, Vec3::new(0.3, 2.5, 0.3) * s);
            let direction = Vec3::new(0.5, -1.0, -0.3).normalize();
            let objects = [floor, post];
            let f = directional_frustum(direction, &camera, 1.0, &objects, &objects, Some(256));
            let Projection::Orthographic { extent, near, far } = f.projection else {
                unreachable!()
            };
            (extent / s, near / s, far / s)
        };
        let unit = fit(1.0);
        for s in [0.01, 0.37, 100.0, 10_000.0] {
            let scaled = fit(s);
            for (a, b) in [(unit.0, scaled.0), (unit.1, scaled.1), (unit.2, scaled.2)] {
                assert!(
                    (a - b).abs() <= 1e-4 * a.abs().max(1.0),
                    "{unit:?} at scale {s}: {scaled:?}"
                );
            }
        }
    }

    #[test]
    fn directional_fit_contains_relevant_casters_and_visible_receivers() {
        let camera = Camera {
            position: Vec3::new(3.0, 4.0, 6.0),
            target: Vec3::new(0.0, 0.0, 0.0),
            fov_y: 50f32.to_radians(),
            near: 0.1,
            far: 200.0,
        };
        let floor = (Vec3::new(-20.0, -0.01, -20.0), Vec3::new(20.0, 0.0, 20.0));
        let tall = (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 15.0, 1.0));
        let far_away = (Vec3::new(100.0, 0.0, 100.0), Vec3::new(101.0, 50.0, 101.0));
        let direction = Vec3::new(0.4, -1.0, -0.3).normalize();
        let objects = [floor, tall, far_away];
        let f = directional_frustum(direction, &camera, 1.5, &objects, &objects, None);
        // Every visible floor point (sampled on a grid of rays from the camera) is covered.
        let inverse = (camera.projection(1.5) * camera.view()).inverse();
        for i in 0..=10 {
            for j in 0..=10 {
                let ndc = Vec3::new(i as f32 / 5.0 - 1.0, j as f32 / 5.0 - 1.0, 0.5);
                let through = inverse.project_point3(ndc);
                let dir = (through - camera.position).normalize();
                if dir.y >= -1e-3 {
                    continue;
                }
                let t = -camera.position.y / dir.y;
                let hit = camera.position + dir * t;
                if hit.x.abs() <= 20.0 && hit.z.abs() <= 20.0 {
                    assert!(f.contains(hit), "visible floor point {hit} outside the map");
                }
            }
        }
        // The tall caster (which shadows the visible floor) lies entirely in the depth range.
        for c in corners(tall) {
            let ndc = f.view_proj.project_point3(c);
            assert!(
                (0.0..=1.0).contains(&ndc.z),
                "caster corner {c} at depth {}",
                ndc.z
            );
        }
        // The far-away caster is not what the fit is sized for: the map is much smaller than
        // the whole scene.
        let Projection::Orthographic { extent, .. } = f.projection else {
            unreachable!()
        };
        assert!(extent < 100.0, "extent {extent} covers the whole scene");
    }

    #[test]
    fn stable_fit_ignores_small_camera_moves_and_snaps_to_texels() {
        let camera = |x: f32| Camera {
            position: Vec3::new(3.0 + x, 4.0, 6.0),
            target: Vec3::new(x, 0.0, 0.0),
            fov_y: 50f32.to_radians(),
            near: 0.1,
            far: 200.0,
        };
        let floor = (Vec3::new(-20.0, -0.01, -20.0), Vec3::new(20.0, 0.0, 20.0));
        let post = (Vec3::new(-0.2, 0.0, -0.2), Vec3::new(0.2, 3.0, 0.2));
        let objects = [floor, post];
        let direction = Vec3::new(0.4, -1.0, -0.3).normalize();
        let fit = |x: f32| {
            directional_frustum(direction, &camera(x), 1.5, &objects, &objects, Some(1024))
        };
        let (a, b) = (fit(0.0), fit(0.001));
        let Projection::Orthographic { extent, .. } = a.projection else {
            unreachable!()
        };
        assert_eq!(a.projection, b.projection, "a tiny move keeps the extent");
        // A world point's texel coordinate changes by whole texels (or not at all).
        let p = Vec3::new(0.3, 0.0, 0.7);
        for x in [0.001, 0.05, 0.3] {
            let c = fit(x);
            let Projection::Orthographic { extent: e, .. } = c.projection else {
                unreachable!()
            };
            if e == extent {
                let texel_a = (a.view_proj.project_point3(p).truncate() * 512.0).x;
                let texel_c = (c.view_proj.project_point3(p).truncate() * 512.0).x;
                let shift = texel_c - texel_a;
                assert!(
                    (shift - shift.round()).abs() < 1e-2,
                    "moved by {shift} texels"
                );
            }
        }
        // The snapped fit still covers the visible floor around the post.
        assert!(a.contains(Vec3::new(0.0, 0.0, 0.0)));
        assert!(a.contains(post.1));
    }

    #[test]
    fn cube_faces_cover_every_direction_with_a_guard_band() {
        let light = Light {
            kind: LightKind::Point,
            position: Vec3::new(0.5, 2.0, -1.0),
            ..spot()
        };
        let faces = cube_frustums(&light, 512, 4);
        for k in 0..500 {
            let t = k as f32;
            let dir = Vec3::new((t * 1.3).sin(), (t * 0.7).cos(), (t * 2.9).sin()).normalize();
            let face = cube_face(dir);
            let p = light.position + dir * 3.0;
            let ndc = faces[face].view_proj.project_point3(p);
            // Inside the central region: guard band of 4 texels left on each side.
            let limit = 1.0 - 8.0 / 512.0 + 1e-4;
            assert!(
                ndc.x.abs() <= limit && ndc.y.abs() <= limit,
                "{dir} -> face {face}: {ndc}"
            );
            assert!((0.0..=1.0).contains(&ndc.z));
        }
    }
}
