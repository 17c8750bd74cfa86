//! Parallel-split (cascaded) shadow maps for directional lights (Zhang et al. 2006; seed 000
//! section 13.1): the visible depth range is split by a blend of the logarithmic and uniform
//! schemes, and each split gets an orthographic crop of its slice of the view frustum, reaching
//! back towards the light to every caster that can shadow it.

use std::sync::Arc;

use zoo_host::glam::{Mat4, Vec3, Vec4};
use zoo_host::scene::{Camera, Light, LightKind};

use crate::light_space::{
    Aabb, LightFrustum, Projection, corners, magnitude, resolvable, scene_unit, transformed_bounds,
};
use crate::planning::{LayerPlan, PlanInputs};
use crate::sample_fit::{LightBox, SampleFit, fit_view};

/// The cascade plan: `splits` layers for every directional light (none for other lights),
/// split by [`split_distances`] over `range`, or without one over [`visible_depth_range`].
/// Each split's crop also covers the last `blend` fraction of the split before it, where
/// lookups blend the two. With `samples`, the splits span their depth range and each crop
/// is cut to the box of the samples in its split.
#[derive(Debug, Clone, PartialEq)]
pub struct Cascades {
    pub splits: u32,
    /// Weight of the logarithmic scheme against the uniform one, in [0, 1].
    pub lambda: f32,
    /// Fraction of each split blended into the next, in [0, 1).
    pub blend: f32,
    /// Where the view's samples are (the depth buffer's, for sample-distribution shadow
    /// maps); `None` fits the splits to the objects' boxes and the crops to the slices.
    pub samples: Option<Arc<SampleFit>>,
}

impl Cascades {
    /// The split distances C_0..C_m for `camera` (of `aspect`) over `range` or the scene's
    /// `objects`.
    /// With `stable`, the fitted range is widened to quarter-octave steps of the scene's size (near down, far up)
    /// so that it, and with it every split's crop, changes only now and then as the camera
    /// moves.
    pub fn distances(
        &self,
        camera: &Camera,
        aspect: f32,
        objects: &[Aabb],
        stable: bool,
    ) -> Vec<f32> {
        let range = self.samples.as_ref().and_then(|s| s.range);
        let (mut near, mut far) =
            range.unwrap_or_else(|| visible_depth_range(camera, aspect, objects));
        if stable {
            // Octaves of the scene's size, so a scaled scene gets the same splits, scaled.
            let unit = scene_unit(objects);
            let step = |d: f32, round: fn(f32) -> f32| {
                unit * (round((d / unit).log2() * 4.0) / 4.0).exp2()
            };
            near = step(near, f32::floor).clamp(camera.near, near);
            far = step(far, f32::ceil).clamp(far, camera.far.max(far));
        }
        split_distances(near, far, self.splits, self.lambda)
    }
}

impl LayerPlan for Cascades {
    fn layers(&self, light: &Light) -> u32 {
        if light.kind == LightKind::Directional {
            self.splits.max(1)
        } else {
            0
        }
    }

    fn frustums(
        &self,
        light: &Light,
        resolution: u32,
        inputs: &PlanInputs<'_>,
    ) -> Vec<LightFrustum> {
        if light.kind != LightKind::Directional {
            return Vec::new();
        }
        let aspect = inputs.size.x as f32 / inputs.size.y.max(1) as f32;
        let c = self.distances(inputs.camera, aspect, inputs.objects, inputs.stable);
        let stable = inputs.stable.then_some(resolution);
        (0..c.len() - 1)
            .map(|i| {
                let start = match i {
                    0 => c[0],
                    _ => c[i] - self.blend * (c[i] - c[i - 1]),
                };
                let corners = slice_corners(inputs.camera, aspect, start, c[i + 1]);
                let samples = (self.samples.as_ref())
                    .and_then(|fit| fit.samples_box(light.direction, (start, c[i + 1])));
                match samples {
                    Some(samples) => {
                        let fit = (samples, resolution);
                        fitted_cascade_frustum(light.direction, &corners, fit, inputs.casters)
                    }
                    None => cascade_frustum(light.direction, &corners, inputs.casters, stable),
                }
            })
            .collect()
    }

    fn layer_word(&self, _light: &Light) -> &'static str {
        "split"
    }
}

/// The view depths [near, far] the scene occupies: the camera's clip planes pulled in to the
/// nearest and farthest corners of the boxes of the objects that are not wholly outside a side
/// of the view frustum (`aspect` is its width over height).
pub fn visible_depth_range(camera: &Camera, aspect: f32, objects: &[Aabb]) -> (f32, f32) {
    let view = camera.view();
    let tan_y = (camera.fov_y * 0.5).tan();
    let tan_x = tan_y * aspect;
    let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
    for object in objects {
        let points = corners(*object).map(|c| view.transform_point3(c));
        // Outside when every corner is beyond one side plane (or behind the camera).
        let beyond = |plane: Vec4| points.iter().all(|p| plane.dot(p.extend(1.0)) > 0.0);
        let outside = [
            Vec4::new(1.0, 0.0, tan_x, 0.0),
            Vec4::new(-1.0, 0.0, tan_x, 0.0),
            Vec4::new(0.0, 1.0, tan_y, 0.0),
            Vec4::new(0.0, -1.0, tan_y, 0.0),
            Vec4::new(0.0, 0.0, 1.0, 0.0),
        ]
        .into_iter()
        .any(beyond);
        if outside {
            continue;
        }
        for p in points {
            lo = lo.min(-p.z);
            hi = hi.max(-p.z);
        }
    }
    let near = lo.clamp(camera.near, camera.far);
    let far = hi.min(camera.far).max(near * 1.001);
    (near, far)
}

/// Split distances C_0 = near, ..., C_m = far of `splits` parts:
/// C_i = λ·n·(f/n)^(i/m) + (1 - λ)·(n + (f - n)·i/m). λ = 0 is uniform, λ = 1 logarithmic.
pub fn split_distances(near: f32, far: f32, splits: u32, lambda: f32) -> Vec<f32> {
    let m = splits.max(1);
    (0..=m)
        .map(|i| match i {
            0 => near,
            i if i == m => far,
            i => {
                let t = i as f32 / m as f32;
                let logarithmic = near * (far / near).powf(t);
                let uniform = near + (far - near) * t;
                lambda * logarithmic + (1.0 - lambda) * uniform
            }
        })
        .collect()
}

/// World corners of the slice of the camera's view frustum between view depths `near` and
/// `far` (near corners first).
pub fn slice_corners(camera: &Camera, aspect: f32, near: f32, far: f32) -> [Vec3; 8] {
    let to_world = camera.view().inverse();
    let tan_y = (camera.fov_y * 0.5).tan();
    let tan_x = tan_y * aspect;
    let mut out = [Vec3::ZERO; 8];
    for (i, corner) in out.iter_mut().enumerate() {
        let depth = if i < 4 { near } else { far };
        let x = if i & 1 == 0 { -1.0 } else { 1.0 } * tan_x * depth;
        let y = if i & 2 == 0 { -1.0 } else { 1.0 } * tan_y * depth;
        *corner = to_world.transform_point3(Vec3::new(x, y, -depth));
    }
    out
}

/// The smallest sphere around a slice of a symmetric view frustum (corners as from
/// [`slice_corners`]): its centre lies on the view axis, and its radius depends only on the
/// split distances and the field of view, not on where the camera looks.
pub fn slice_sphere(corners: &[Vec3; 8]) -> (Vec3, f32) {
    let near_centre = corners[..4].iter().copied().sum::<Vec3>() / 4.0;
    let far_centre = corners[4..].iter().copied().sum::<Vec3>() / 4.0;
    let near_radius = corners[0].distance(near_centre);
    let far_radius = corners[4].distance(far_centre);
    let length = resolvable(
        near_centre.distance(far_centre),
        magnitude(near_centre, far_centre),
    );
    let axis = (far_centre - near_centre) / length;
    // Equal distance to a near and a far corner along the axis, kept inside the slice.
    let t = ((length * length + far_radius * far_radius - near_radius * near_radius)
        / (2.0 * length))
        .clamp(0.0, length);
    let centre = near_centre + axis * t;
    let radius = ((length - t).hypot(far_radius)).max(t.hypot(near_radius));
    (centre, radius)
}

/// An orthographic frustum for a directional light travelling along `direction` around the
/// view-frustum slice `corners`, its near plane moved towards the light to the nearest caster
/// whose box overlaps the crop.
///
/// With `stable_texels` = Some(resolution) the crop is the slice's bounding sphere, its extent
/// quantised (steps of 1/64 of a power of two of the casters' overall size) and its centre snapped to whole texels, so the
/// crop does not change as the camera turns and moves by whole texels as it walks: shadow
/// edges do not shimmer. Without, the crop is the tight box around the slice.
pub fn cascade_frustum(
    direction: Vec3,
    corners: &[Vec3; 8],
    casters: &[Aabb],
    stable_texels: Option<u32>,
) -> LightFrustum {
    let view = fit_view(direction);
    let (mut lo, mut hi) = transformed_bounds(view, corners);
    let (mut centre, extent);
    if let Some(resolution) = stable_texels {
        let (sphere_centre, radius) = slice_sphere(corners);
        // Powers of two of the scene's size, so a scaled scene gets the same crops, scaled.
        let unit = scene_unit(casters);
        let diameter = resolvable(2.0 * radius, magnitude(lo, hi));
        let quantum = unit * 2f32.powf((diameter / unit).log2().floor()) / 64.0;
        // Two texels of margin: snapping moves the sphere by up to half a texel.
        extent = ((2.0 * radius) / quantum).ceil() * quantum * (1.0 + 2.0 / resolution as f32);
        let texel = extent / resolution as f32;
        centre = view.transform_point3(sphere_centre);
        centre.x = (centre.x / texel).round() * texel;
        centre.y = (centre.y / texel).round() * texel;
        lo.z = centre.z - radius;
        hi.z = centre.z + radius;
    } else {
        extent = resolvable((hi.x - lo.x).max(hi.y - lo.y), magnitude(lo, hi)) * 1.01;
        centre = (lo + hi) * 0.5;
    }
    let stable = stable_texels.is_some();
    reaching_casters(view, (lo, hi), (centre, extent), (casters, stable))
}

/// The crop of a split fitted to its samples (`samples`: their light-space box from
/// [`fit_view`]; the map's resolution): the slice's box cut to the samples', widened by
/// [`FIT_MARGIN_TEXELS`] on every side for normal offsets and filter taps. It is never
/// stabilised: along the vista walk, extents on a ladder and centres snapped to texels made the
/// crops coarser and flicker more (0.0110 to 0.0121) than fitted crops (0.0099). Casters
/// reach it as in [`cascade_frustum`], whose tight crop it falls back to where
/// the boxes do not meet.
pub fn fitted_cascade_frustum(
    direction: Vec3,
    corners: &[Vec3; 8],
    (samples, resolution): (LightBox, u32),
    casters: &[Aabb],
) -> LightFrustum {
    let view = fit_view(direction);
    let (slice_lo, slice_hi) = transformed_bounds(view, corners);
    let (lo, hi) = (slice_lo.max(samples.0), slice_hi.min(samples.1));
    if lo.cmpgt(hi).any() {
        return cascade_frustum(direction, corners, casters, None);
    }
    let side = resolvable((hi.x - lo.x).max(hi.y - lo.y), magnitude(lo, hi));
    let extent = side / (1.0 - 2.0 * FIT_MARGIN_TEXELS / resolution.max(64) as f32);
    reaching_casters(view, (lo, hi), ((lo + hi) * 0.5, extent), (casters, false))
}

/// Texels a fitted crop keeps beyond its samples on every side.
pub const FIT_MARGIN_TEXELS: f32 = 8.0;

/// The orthographic crop of `extent` around `centre` (light space of `view`) over receivers
/// between `lo` and `hi`, its near plane pulled back to every caster over the crop; with
/// `stable`, its depth range moves outward in coarse steps.
fn reaching_casters(
    view: Mat4,
    (lo, hi): (Vec3, Vec3),
    (centre, extent): (Vec3, f32),
    (casters, stable): (&[Aabb], bool),
) -> LightFrustum {
    let half = extent * 0.5;
    let mut nearest = hi.z;
    for caster in casters {
        let (clo, chi) = transformed_bounds(view, &crate::light_space::corners(*caster));
        let overlaps = clo.x <= centre.x + half
            && chi.x >= centre.x - half
            && clo.y <= centre.y + half
            && chi.y >= centre.y - half;
        // Anything over the crop that is not wholly beyond the slice can shadow it.
        if overlaps && chi.z >= lo.z {
            nearest = nearest.max(chi.z);
        }
    }
    let margin = resolvable(nearest - lo.z, magnitude(lo, hi).max(nearest.abs())) * 0.01;
    let (mut near, mut far) = (-nearest - margin, -lo.z + margin);
    if stable {
        let step = extent / 16.0;
        near = (near / step).floor() * step;
        far = (far / step).ceil() * step;
    }
    let view = Mat4::from_translation(Vec3::new(-centre.x, -centre.y, 0.0)) * view;
    LightFrustum::new(view, Projection::Orthographic { extent, near, far })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.0, 1.7, 0.0),
            target: Vec3::new(0.3, 1.2, -20.0),
            fov_y: 55f32.to_radians(),
            near: 0.1,
            far: 800.0,
        }
    }

    #[test]
    fn splits_follow_the_practical_scheme() {
        let (n, f) = (0.1, 500.0);
        for m in 1..=8 {
            for lambda in [0.0, 0.3, 0.5, 1.0] {
                let c = split_distances(n, f, m, lambda);
                assert_eq!(c.len() as u32, m + 1);
                assert_eq!((c[0], c[m as usize]), (n, f), "endpoints exactly n and f");
                assert!(c.windows(2).all(|w| w[0] < w[1]), "monotone: {c:?}");
            }
        }
        let uniform = split_distances(n, f, 4, 0.0);
        let logarithmic = split_distances(n, f, 4, 1.0);
        for i in 1..4 {
            let t = i as f32 / 4.0;
            assert!((uniform[i] - (n + (f - n) * t)).abs() < 1e-3);
            assert!((logarithmic[i] / (n * (f / n).powf(t)) - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn visible_range_hugs_the_objects() {
        let c = Camera {
            position: Vec3::new(0.0, 0.0, 10.0),
            target: Vec3::ZERO,
            fov_y: 1.0,
            near: 0.1,
            far: 1000.0,
        };
        let boxes = [(Vec3::splat(-1.0), Vec3::splat(1.0))];
        let (n, f) = visible_depth_range(&c, 1.0, &boxes);
        assert!((n - 9.0).abs() < 1e-4 && (f - 11.0).abs() < 1e-4, "{n} {f}");
        // A box around the camera reaches the near plane; nothing in front keeps far > near.
        let (n, _) = visible_depth_range(&c, 1.0, &[(Vec3::splat(-20.0), Vec3::splat(20.0))]);
        assert_eq!(n, 0.1);
        let (n, f) = visible_depth_range(&c, 1.0, &[]);
        assert!(f > n);
        // A box beside the view, or behind the camera, does not count.
        let beside = (Vec3::new(400.0, -1.0, -40.0), Vec3::new(401.0, 1.0, 9999.0));
        let behind = (Vec3::new(-1.0, -1.0, 20.0), Vec3::new(1.0, 1.0, 21.0));
        assert_eq!(
            visible_depth_range(&c, 1.0, &[beside, behind, boxes[0]]),
            visible_depth_range(&c, 1.0, &boxes)
        );
    }

    fn inside(frustum: &LightFrustum, p: Vec3) -> bool {
        let q = frustum.view_proj.project_point3(p);
        q.x.abs() <= 1.0 + 1e-5 && q.y.abs() <= 1.0 + 1e-5 && (-1e-5..=1.0 + 1e-5).contains(&q.z)
    }

    #[test]
    fn stable_splits_and_crops_scale_with_the_scene() {
        // Quantised to the scene's size: the same scene at any scale gets the same splits and
        // crops, scaled.
        let direction = Vec3::new(0.82, -0.32, -0.48).normalize();
        let fit = |s: f32| {
            let camera = camera().scaled(s);
            let ground = (
                Vec3::new(-300.0, -1.0, -300.0) * s,
                Vec3::new(300.0, 0.0, 300.0) * s,
            );
            let cascades = Cascades {
                splits: 4,
                lambda: 0.5,
                blend: 0.0,
                samples: None,
            };
            let d = cascades.distances(&camera, 1.5, &[ground], true);
            let corners = slice_corners(&camera, 1.5, d[0], d[1]);
            let f = cascade_frustum(direction, &corners, &[ground], Some(1024));
            let Projection::Orthographic { extent, .. } = f.projection else {
                unreachable!()
            };
            let mut out: Vec<f32> = d.iter().map(|x| x / s).collect();
            out.push(extent / s);
            out
        };
        let unit = fit(1.0);
        for s in [0.01, 0.37, 100.0, 10_000.0] {
            for (a, b) in unit.iter().zip(fit(s)) {
                assert!(
                    (a - b).abs() <= 1e-4 * a.abs().max(1.0),
                    "{a} and {b} at scale {s}"
                );
            }
        }
    }

    #[test]
    fn every_crop_holds_its_slice_and_the_casters_between_it_and_the_light() {
        let direction = Vec3::new(0.82, -0.32, -0.48).normalize();
        let c = camera();
        let splits = split_distances(0.1, 500.0, 4, 0.5);
        // A tall caster far up the light's path from the first slice.
        let slice = slice_corners(&c, 1.5, splits[0], splits[1]);
        let centre = slice.iter().copied().sum::<Vec3>() / 8.0;
        let up_light = centre - direction * 30.0;
        let caster = (up_light - Vec3::splat(0.5), up_light + Vec3::splat(0.5));
        for stable in [None, Some(1024)] {
            for w in splits.windows(2) {
                let corners = slice_corners(&c, 1.5, w[0], w[1]);
                let f = cascade_frustum(direction, &corners, &[caster], stable);
                for corner in corners {
                    assert!(inside(&f, corner), "slice corner outside ({stable:?})");
                }
            }
            let first = cascade_frustum(direction, &slice, &[caster], stable);
            // The caster lies between the slice and the light: in the map, nearer the light.
            assert!(inside(&first, up_light), "caster outside ({stable:?})");
        }
    }

    #[test]
    fn stable_crops_move_only_by_whole_texels() {
        let direction = Vec3::new(0.82, -0.32, -0.48).normalize();
        let resolution = 1024;
        let frustum = |c: &Camera| {
            let corners = slice_corners(c, 1.5, 0.1, 12.0);
            cascade_frustum(direction, &corners, &[], Some(resolution))
        };
        let base = camera();
        let reference = frustum(&base);
        let Projection::Orthographic { extent, .. } = reference.projection else {
            unreachable!()
        };
        let texel = extent / resolution as f32;
        let mut unchanged = 0;
        for k in 0..50 {
            // Moves and turns well under a texel.
            let offset =
                Vec3::new((k as f32 * 0.37).sin(), 0.0, (k as f32 * 0.71).cos()) * 0.2 * texel;
            let mut c = base;
            c.position += offset;
            c.target += offset + Vec3::new(0.0, 0.0, (k as f32 * 0.13).sin() * 1e-3);
            let moved = frustum(&c);
            let Projection::Orthographic { extent: e, .. } = moved.projection else {
                unreachable!()
            };
            assert_eq!(e, extent, "the extent does not follow small moves");
            // The texel grid stays put: the origin moves by whole texels in x and y.
            let shift = (moved.view_proj.project_point3(Vec3::ZERO)
                - reference.view_proj.project_point3(Vec3::ZERO))
                * 0.5
                * resolution as f32;
            assert!((shift.x - shift.x.round()).abs() < 5e-3, "x shift {shift}");
            assert!((shift.y - shift.y.round()).abs() < 5e-3, "y shift {shift}");
            unchanged += usize::from(moved.view_proj.abs_diff_eq(reference.view_proj, 1e-6));
        }
        assert!(
            unchanged >= 25,
            "only {unchanged} of 50 sub-texel moves left the crop unchanged"
        );
        // A walk of many texels moves the grid by whole texels too (no drift).
        let mut c = base;
        let walk = Vec3::new(37.3, 0.0, -11.6) * texel;
        c.position += walk;
        c.target += walk;
        let moved = frustum(&c);
        let shift = (moved.view_proj.project_point3(Vec3::ZERO)
            - reference.view_proj.project_point3(Vec3::ZERO))
            * 0.5
            * resolution as f32;
        assert!(shift.length() > 10.0, "the crop followed the walk: {shift}");
        assert!((shift.x - shift.x.round()).abs() < 5e-3, "x shift {shift}");
        assert!((shift.y - shift.y.round()).abs() < 5e-3, "y shift {shift}");
    }

    #[test]
    fn casters_wholly_between_a_thin_split_and_the_light_are_kept() {
        let direction = Vec3::new(0.82, -0.32, -0.48).normalize();
        let c = camera();
        let corners = slice_corners(&c, 1.5, 0.1, 1.0);
        let centre = corners.iter().copied().sum::<Vec3>() / 8.0;
        // 60 m up the light's path: far above the slice's top in light space.
        let up_light = centre - direction * 60.0;
        let caster = (up_light - Vec3::splat(0.2), up_light + Vec3::splat(0.2));
        for stable in [None, Some(1024)] {
            let f = cascade_frustum(direction, &corners, &[caster], stable);
            assert!(inside(&f, up_light), "caster cut off ({stable:?})");
        }
    }
}
