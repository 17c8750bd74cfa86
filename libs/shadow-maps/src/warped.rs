//! Warped single maps against perspective aliasing: light-space perspective shadow maps
//! (LiSPSM, Wimmer, Scherzer and Purgathofer 2004), trapezoidal shadow maps (TSM, Martin and
//! Tan 2004) and perspective shadow maps (PSM, Stamminger and Drettakis 2002; seed 000 sections
//! 7.9 and 13.2). All spend more texels near the viewer by putting a perspective into the
//! light's projection.

use zoo_host::glam::camera::rh::{proj::directx, view::look_to_mat4};
use zoo_host::glam::{Mat4, UVec2, Vec2, Vec3, Vec3Swizzles, Vec4, Vec4Swizzles};
use zoo_host::scene::{Camera, Light, LightKind};

use crate::cascades::slice_corners;
use crate::light_space::{
    Aabb, LightFrustum, corners, magnitude, resolvable, transformed_bounds, up_for,
};

/// Below this sine of the angle between the view and light directions, LiSPSM's warp is
/// dropped: its optimal near distance grows as 1 / sin γ and the map becomes uniform.
pub const MIN_SIN_GAMMA: f32 = 0.02;

/// What a LiSPSM fit chose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LispsmFit {
    pub frustum: LightFrustum,
    /// The warp frustum's near distance n (infinite when the map is uniform).
    pub n: f32,
    /// sin γ of the view and light directions.
    pub sin_gamma: f32,
}

/// LiSPSM's optimal near distance of the warp frustum for a view from `z_n` to `z_f` whose
/// body spans `d` along the warp axis:
/// n = (z_n' + sqrt(z_n'·z_f')) / sin γ with z_n' = z_n / sin γ and z_f' = z_n' + d·sin γ.
/// At sin γ = 1 and d = z_f - z_n this is the paper's n_opt = z_n + sqrt(z_n·z_f).
pub fn lispsm_near(z_n: f32, d: f32, sin_gamma: f32) -> f32 {
    let z_n = z_n / sin_gamma;
    let z_f = z_n + d * sin_gamma;
    (z_n + (z_n * z_f).sqrt()) / sin_gamma
}

/// Bounds of the points in `space`, component-wise.
fn bounds_in(space: Mat4, points: &[Vec3]) -> Aabb {
    transformed_bounds(space, points)
}

/// The light-space body a directional light's map must hold: the view slice's corners, and
/// the same corners moved towards the light (light space looks along -z, so nearer the light
/// is larger z) to the nearest caster over the slice's footprint.
fn light_space_body(light_view: Mat4, slice: &[Vec3; 8], casters: &[Aabb]) -> Vec<Vec3> {
    let points: Vec<Vec3> = slice
        .iter()
        .map(|p| light_view.transform_point3(*p))
        .collect();
    let (lo, hi) = transformed_bounds(Mat4::IDENTITY, &points);
    let mut top = hi.z;
    for caster in casters {
        let (clo, chi) = bounds_in(light_view, &corners(*caster));
        if clo.x <= hi.x && chi.x >= lo.x && clo.y <= hi.y && chi.y >= lo.y && chi.z >= lo.z {
            top = top.max(chi.z);
        }
    }
    let raised: Vec<Vec3> = points.iter().map(|p| Vec3::new(p.x, p.y, top)).collect();
    points.into_iter().chain(raised).collect()
}

/// The matrix that maps the points (after `warp` and the perspective division) onto the map:
/// x and y to [-1, 1], z to [0, 1] with the side nearest the light (largest z) at 0.
fn fit_to_map(warp: Mat4, body: &[Vec3]) -> Mat4 {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for c in body {
        let p = warp.project_point3(*c);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let size = (hi - lo).max(Vec3::splat(1e-6));
    // x' = 2(x - lo.x)/size.x - 1, y' likewise, z' = (hi.z - z)/size.z, applied before the
    // division (so multiplied by w).
    Mat4::from_cols(
        Vec4::new(2.0 / size.x, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 / size.y, 0.0, 0.0),
        Vec4::new(0.0, 0.0, -1.0 / size.z, 0.0),
        Vec4::new(
            -2.0 * lo.x / size.x - 1.0,
            -2.0 * lo.y / size.y - 1.0,
            hi.z / size.z,
            1.0,
        ),
    ) * warp
}

/// A LiSPSM map for a directional light travelling along `direction`, seen by `camera` over
/// view depths [near, far] (with `casters` that can shadow it): in light space (looking along the light, y along the view
/// direction projected onto the map plane) a perspective warp along y, its centre `n`
/// (see [`lispsm_near`], times `strength`'s inverse) before the body, then fitted to the map.
/// Uniform when sin γ < [`MIN_SIN_GAMMA`].
#[allow(clippy::too_many_arguments)]
pub fn lispsm_frustum(
    direction: Vec3,
    camera: &Camera,
    aspect: f32,
    (near, far): (f32, f32),
    casters: &[Aabb],
    strength: f32,
) -> LispsmFit {
    let view_dir = (camera.target - camera.position).normalize_or(Vec3::NEG_Z);
    let sin_gamma = view_dir.cross(direction).length();
    let along_view = view_dir - direction * view_dir.dot(direction);
    // The map's y axis follows the view until light and view are parallel, so the map does
    // not turn when the warp is dropped below MIN_SIN_GAMMA.
    let up = if sin_gamma >= 1e-4 {
        along_view.normalize()
    } else {
        up_for(direction)
    };
    let light_view = look_to_mat4(camera.position, direction, up);
    let slice = slice_corners(camera, aspect, near, far);
    let body = light_space_body(light_view, &slice, casters);
    let (lo, hi) = transformed_bounds(Mat4::IDENTITY, &body);
    if sin_gamma < MIN_SIN_GAMMA || strength <= 0.0 {
        return LispsmFit {
            frustum: LightFrustum::warped(
                light_view,
                fit_to_map(Mat4::IDENTITY, &body) * light_view,
            ),
            n: f32::INFINITY,
            sin_gamma,
        };
    }
    let d = resolvable(hi.y - lo.y, magnitude(lo, hi));
    let n = lispsm_near(near, d, sin_gamma) / strength;
    let f = n + d;
    // The warp's centre of projection: n before the body along y, at the camera laterally.
    let centre = Vec3::new(0.0, lo.y - n, (lo.z + hi.z) * 0.5);
    // Perspective along +y: w = y - centre.y, y' / w covers [-1, 1] over [n, f].
    let (a, b) = ((f + n) / (f - n), -2.0 * f * n / (f - n));
    let warp = Mat4::from_cols(
        Vec4::new(1.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, a, 0.0, 1.0),
        Vec4::new(0.0, 0.0, 1.0, 0.0),
        Vec4::new(0.0, b, 0.0, 0.0),
    ) * Mat4::from_translation(-centre);
    let light_to_map = fit_to_map(warp, &body);
    LispsmFit {
        frustum: LightFrustum::warped(light_view, light_to_map * light_view),
        n,
        sin_gamma,
    }
}

/// What a TSM fit chose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TsmFit {
    pub frustum: LightFrustum,
    /// The trapezoid's distance η from its top edge to its apex, the centre of the warp
    /// (infinite when the map is uniform), and its height λ from top to base.
    pub eta: f32,
    pub lambda: f32,
}

/// The share of the map's rows the focus region gets (the paper's "80 % rule").
pub const TSM_FOCUS_SHARE: f32 = 0.8;

/// TSM's distance η from the trapezoid's top edge to its apex, for a trapezoid of height
/// `lambda` whose first `delta` (the focus region) must take [`TSM_FOCUS_SHARE`] of the
/// map's rows: with rows v(s) = s (λ + η) / (λ (s + η)) for a distance s from the top edge,
/// v(δ) = 0.8 gives η = 0.2 λ δ / (0.8 λ − δ) (the paper's ξ = −0.6). Infinite (a uniform map)
/// when the focus region already takes that share.
pub fn tsm_eta(lambda: f32, delta: f32) -> f32 {
    let rest = TSM_FOCUS_SHARE * lambda - delta;
    if rest <= 1e-6 * lambda {
        return f32::INFINITY;
    }
    (1.0 - TSM_FOCUS_SHARE) * lambda * delta / rest
}

/// A TSM map for a directional light travelling along `direction`, seen by `camera` over view
/// depths [near, far] (with `casters` that can shadow it): in light space, the view slice's
/// outline is bounded by a trapezoid whose top and base edges are perpendicular to the line
/// from the near plane's centre to the far plane's, and whose sides meet at an apex placed
/// ([`tsm_eta`]) so that the first `focus` of the depth range (the focus region) takes 80 % of
/// the map's rows; the projective map of the trapezoid onto the square warps the light's
/// projection. Uniform when the view looks along the light (the line has no length).
#[allow(clippy::too_many_arguments)]
pub fn tsm_frustum(
    direction: Vec3,
    camera: &Camera,
    aspect: f32,
    (near, far): (f32, f32),
    casters: &[Aabb],
    focus: f32,
) -> TsmFit {
    let light_view = look_to_mat4(camera.position, direction, up_for(direction));
    let slice = slice_corners(camera, aspect, near, far);
    let body = light_space_body(light_view, &slice, casters);
    let outline: Vec<Vec2> = (slice.iter())
        .map(|p| light_view.transform_point3(*p).xy())
        .collect();
    let centre = |points: &[Vec2]| points.iter().copied().sum::<Vec2>() / points.len() as f32;
    let (near_centre, far_centre) = (centre(&outline[..4]), centre(&outline[4..]));
    let uniform = TsmFit {
        frustum: LightFrustum::warped(light_view, fit_to_map(Mat4::IDENTITY, &body) * light_view),
        eta: f32::INFINITY,
        lambda: 0.0,
    };
    let axis = far_centre - near_centre;
    let (lo, hi) = transformed_bounds(Mat4::IDENTITY, &body);
    if axis.length() <= 1e-3 * resolvable(hi.x - lo.x, magnitude(lo, hi)) {
        return uniform;
    }
    let u = axis.normalize();
    let along = |p: Vec2| (p - near_centre).dot(u);
    let top = outline
        .iter()
        .map(|p| along(*p))
        .fold(f32::INFINITY, f32::min);
    let base = outline
        .iter()
        .map(|p| along(*p))
        .fold(f32::NEG_INFINITY, f32::max);
    let lambda = base - top;
    // The focus region ends at the view depth `focus` of the way from near to far.
    let view_dir = (camera.target - camera.position).normalize_or(Vec3::NEG_Z);
    let focus_depth = near + focus.clamp(0.0, 1.0) * (far - near);
    let focus_point = light_view.transform_point3(camera.position + view_dir * focus_depth);
    let delta = (along(focus_point.xy()) - top).clamp(0.0, lambda);
    // A focus region at the top edge would put the apex on it (w = 0 there): keep it a
    // hundredth of the trapezoid away.
    let eta = tsm_eta(lambda, delta).max(0.01 * lambda);
    if !eta.is_finite() {
        return TsmFit { lambda, ..uniform };
    }
    // Apex q on the centre line, η before the top edge; a = distance along u from q, b across.
    let q = near_centre + u * (top - eta);
    let across = Vec2::new(-u.y, u.x);
    let slope = |p: Vec2| (p - q).dot(across) / (p - q).dot(u);
    let low = outline
        .iter()
        .map(|p| slope(*p))
        .fold(f32::INFINITY, f32::min);
    let high = outline
        .iter()
        .map(|p| slope(*p))
        .fold(f32::NEG_INFINITY, f32::max);
    let (mid, half) = ((low + high) * 0.5, ((high - low) * 0.5).max(1e-6));
    // x' = (b / a - mid) / half, y' = α − β / a over the trapezoid: −1 at its top (a = η), 1 at
    // its base (a = η + λ); in homogeneous coordinates with w = a.
    let beta = 2.0 * eta * (eta + lambda) / lambda;
    let alpha = 1.0 + 2.0 * eta / lambda;
    let a = Vec4::new(u.x, u.y, 0.0, -q.dot(u));
    let b = Vec4::new(across.x, across.y, 0.0, -q.dot(across));
    let rows = [(b - a * mid) / half, a * alpha - Vec4::W * beta, Vec4::Z, a];
    let warp = Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
    TsmFit {
        frustum: LightFrustum::warped(light_view, fit_to_map(warp, &body) * light_view),
        eta,
        lambda,
    }
}

/// What a PSM fit chose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PsmFit {
    pub frustum: LightFrustum,
    /// How far the virtual camera slid back to keep casters behind the viewer.
    pub slide: f32,
    /// The light lies behind the viewer: in post-perspective space depth order is inverted.
    pub inverted: bool,
    /// The light stayed directional in post-perspective space (parallel to the view plane).
    pub directional: bool,
}

/// A PSM map for a directional or spot `light`: the camera's post-perspective space of a
/// virtual camera holds the map. The virtual camera slides back along the view direction so
/// that every caster that can shadow the view lies beyond its near plane, which is at least
/// `min_near_fraction` of far and at least as far as those casters reach behind the viewer
/// (so the view is not squashed against the far plane). A
/// directional light becomes a point light there, or stays directional when it is parallel to
/// the view plane; a light behind the viewer lands on the far side with its depth order
/// inverted, and is mapped with reversed depth. `None` when the light falls inside the
/// view's post-perspective box (one map cannot cover it).
#[allow(clippy::too_many_arguments)]
pub fn psm_frustum(
    light: &Light,
    camera: &Camera,
    aspect: f32,
    (near, far): (f32, f32),
    objects: &[Aabb],
    casters: &[Aabb],
    min_near_fraction: f32,
) -> Option<PsmFit> {
    let slice = slice_corners(camera, aspect, near, far);
    let casters = shadowing_casters(light, &receiver_box(&slice, objects), casters);
    let (virtual_camera, slide) =
        slid_back_camera(camera, (near, far), &casters, min_near_fraction);
    let post = virtual_camera.projection(aspect) * virtual_camera.view();
    let homogeneous = match light.kind {
        LightKind::Directional => (-light.direction).extend(0.0),
        _ => light.position.extend(1.0),
    };
    let l = post * homogeneous;
    let receivers: Vec<Vec3> = slice.iter().map(|p| post.project_point3(*p)).collect();
    let blockers: Vec<Vec3> = casters
        .iter()
        .flat_map(|b| corners(*b))
        .map(|p| post * p.extend(1.0))
        .filter(|q| q.w > 0.0)
        .map(|q| q.xyz() / q.w)
        .collect();
    // World axes across the light, for measuring texel sizes.
    let world_view = look_to_mat4(Vec3::ZERO, light.direction, up_for(light.direction));
    let scale = l.xyz().length().max(1e-12);
    // Nearly parallel to the view plane the light's post-perspective position runs off to
    // infinity (and with it the precision of a perspective fit): treat it as directional.
    if l.w.abs() < 1e-3 * scale {
        let to_map = parallel_fit(-l.xyz() / scale, &receivers, &blockers);
        return Some(PsmFit {
            frustum: LightFrustum::warped(world_view, to_map * post),
            slide,
            inverted: false,
            directional: true,
        });
    }
    let inverted = l.w < 0.0;
    let view_proj = point_fit(l.xyz() / l.w, &receivers, &blockers, inverted)? * post;
    if lands_on_a_sliver(view_proj, &slice) {
        return None;
    }
    Some(PsmFit {
        frustum: LightFrustum::warped(world_view, view_proj),
        slide,
        inverted,
        directional: false,
    })
}

/// PSM's virtual camera: `camera` slid back along its view direction until every one of
/// `casters` lies beyond its near plane, which is at least `min_near_fraction` of `far`;
/// with how far it slid.
fn slid_back_camera(
    camera: &Camera,
    (near, far): (f32, f32),
    casters: &[Aabb],
    min_near_fraction: f32,
) -> (Camera, f32) {
    let forward = (camera.target - camera.position).normalize_or(Vec3::NEG_Z);
    let view = camera.view();
    let nearest = casters
        .iter()
        .flat_map(|b| corners(*b))
        .map(|c| -view.transform_point3(c).z)
        .fold(near, f32::min);
    let virtual_near = near.max(min_near_fraction * far).max(-nearest);
    let slide = (virtual_near - nearest).max(0.0);
    let virtual_camera = Camera {
        position: camera.position - forward * slide,
        target: camera.target - forward * slide,
        near: virtual_near,
        far: far + slide,
        ..*camera
    };
    (virtual_camera, slide)
}

/// The map of a light that is directional in post-perspective space, travelling along
/// `travel`: an orthographic fit around the `receivers` that reaches back to the
/// `blockers` (all post-perspective).
fn parallel_fit(travel: Vec3, receivers: &[Vec3], blockers: &[Vec3]) -> Mat4 {
    let pp_view = look_to_mat4(Vec3::ZERO, travel, up_for(travel));
    let (lo, hi) = bounds_in(pp_view, receivers);
    let near_z = blockers
        .iter()
        .map(|p| pp_view.transform_point3(*p).z)
        .fold(hi.z, f32::max);
    let box_corners = corners((lo, Vec3::new(hi.x, hi.y, near_z)));
    fit_to_map(Mat4::IDENTITY, &box_corners) * pp_view
}

/// The map of a light at `eye` in post-perspective space: a cone around the `receivers`
/// whose depth range takes in the `blockers` in front of it, with reversed depth when the
/// light is `inverted` (behind the viewer). `None` when the light lies among the receivers.
fn point_fit(eye: Vec3, receivers: &[Vec3], blockers: &[Vec3], inverted: bool) -> Option<Mat4> {
    let centre = receivers.iter().copied().sum::<Vec3>() / receivers.len() as f32;
    let radius = receivers
        .iter()
        .map(|p| p.distance(centre))
        .fold(0.0, f32::max);
    let distance = eye.distance(centre);
    if distance <= radius * 1.01 {
        return None;
    }
    let axis = (centre - eye) / distance;
    let pp_view = look_to_mat4(eye, axis, up_for(axis));
    let depth = |p: &Vec3| -pp_view.transform_point3(*p).z;
    let receiver_depths = receivers.iter().map(depth);
    let (r_near, r_far) =
        receiver_depths.fold((f32::INFINITY, 0.0f32), |(a, b), d| (a.min(d), b.max(d)));
    let blocker_depths: Vec<f32> = blockers.iter().map(depth).filter(|d| *d > 0.0).collect();
    let half_angle = (radius / distance).asin() * 1.02;
    let projection = if inverted {
        // Occluders lie beyond the receivers from here: store the farthest (reversed depth).
        let far_d = blocker_depths.iter().copied().fold(r_far, f32::max) * 1.01;
        let near_d = (r_near * 0.99).max(far_d * 1e-4);
        directx::perspective(2.0 * half_angle, 1.0, far_d, near_d)
    } else {
        let near_d = blocker_depths
            .iter()
            .copied()
            .fold(r_near, f32::min)
            .max(r_far * 1e-4)
            * 0.99;
        directx::perspective(2.0 * half_angle, 1.0, near_d, r_far * 1.01)
    };
    Some(projection * pp_view)
}

/// Whether the view's `slice` lands on a sliver of the map `view_proj` makes, as it does
/// where the light grazes the view's squashed post-perspective box: no better than a
/// uniform map, and its depth slopes defeat biasing. (The map's coordinates are after the
/// perspective division.)
fn lands_on_a_sliver(view_proj: Mat4, slice: &[Vec3]) -> bool {
    let mapped: Vec<Vec3> = slice.iter().map(|p| view_proj.project_point3(*p)).collect();
    let (lo, hi) = transformed_bounds(Mat4::IDENTITY, &mapped);
    (hi.x - lo.x).min(2.0) * (hi.y - lo.y).min(2.0) < 4.0 * MIN_MAP_USE
}

/// How coarse `frustum`'s map (of `resolution` texels a side) is where the view sees it: the
/// largest ratio of a map texel's world size, across the light's rays, to a screen pixel's
/// (of a `size` view), over a 5×5×5 lattice of the `receivers` box at points the camera sees
/// and the light reaches. Points the map does not cover count as infinitely coarse; lower is
/// sharper. For choosing between fits of one light.
pub fn worst_texel_to_pixel(
    frustum: &LightFrustum,
    light: &Light,
    camera: &Camera,
    size: UVec2,
    resolution: u32,
    receivers: &[Vec3; 8],
) -> f32 {
    let aspect = size.x as f32 / size.y.max(1) as f32;
    let view = camera.view();
    let view_proj = camera.projection(aspect) * view;
    let (lo, hi) = transformed_bounds(Mat4::IDENTITY, receivers);
    let pixel_per_depth = 2.0 * (camera.fov_y * 0.5).tan() / size.y.max(1) as f32;
    let texels_per_unit = resolution as f32 * 0.5;
    let lattice = (0..125).map(|i| {
        let t = Vec3::new((i % 5) as f32, (i / 5 % 5) as f32, (i / 25) as f32) / 4.0;
        lo + (hi - lo) * t
    });
    let mut worst = 0.0f32;
    for p in lattice {
        let clip = view_proj * p.extend(1.0);
        let seen = clip.w > 0.0
            && clip.xy().abs().cmple(Vec2::splat(clip.w)).all()
            && (0.0..=clip.w).contains(&clip.z);
        if !seen || !light.reaches(p) {
            continue;
        }
        let ray = match light.kind {
            LightKind::Directional => light.direction,
            _ => (p - light.position).normalize_or(light.direction),
        };
        let pixel = pixel_per_depth * -view.transform_point3(p).z;
        let map = |q: Vec3| {
            let c = frustum.view_proj * q.extend(1.0);
            (c.w > 0.0).then(|| c.xyz() / c.w)
        };
        let Some(centre) = map(p).filter(|m| m.xy().abs().cmple(Vec2::ONE).all()) else {
            return f32::INFINITY;
        };
        let up = up_for(ray);
        let across = [
            ray.cross(up).normalize(),
            ray.cross(ray.cross(up)).normalize(),
        ];
        for axis in across {
            let moved = match map(p + axis * pixel) {
                Some(m) => (m.xy() - centre.xy()).length() * texels_per_unit,
                None => return f32::INFINITY,
            };
            worst = worst.max(1.0 / moved.max(1e-12));
        }
    }
    worst
}

/// The smallest fraction of a PSM map the view may cover before the fit gives up.
pub const MIN_MAP_USE: f32 = 0.05;

/// The box of the view `slice` that holds objects: the slice's box clipped to the objects'.
pub fn receiver_box(slice: &[Vec3; 8], objects: &[Aabb]) -> [Vec3; 8] {
    let (lo, hi) = transformed_bounds(Mat4::IDENTITY, slice);
    let all = objects.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(a, b), o| (a.min(o.0), b.max(o.1)),
    );
    let clipped = (lo.max(all.0), hi.min(all.1));
    corners(if clipped.0.cmple(clipped.1).all() {
        clipped
    } else {
        (lo, hi)
    })
}

/// The parts of `casters` that can shadow the receivers in `receivers` (box corners): each box
/// clipped to the box around the receivers and their sweep towards the light (to the
/// casters' extent for a directional light, to the light itself otherwise).
pub fn shadowing_casters(light: &Light, receivers: &[Vec3; 8], casters: &[Aabb]) -> Vec<Aabb> {
    let slice = receivers;
    let all = casters.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), b| (lo.min(b.0), hi.max(b.1)),
    );
    let mut points: Vec<Vec3> = slice.to_vec();
    match light.kind {
        LightKind::Directional => {
            let towards = -light.direction;
            for p in slice {
                // Distance along `towards` to leave the casters' box.
                let exit = (0..3)
                    .map(|k| {
                        let d = towards[k];
                        if d > 1e-9 {
                            (all.1[k] - p[k]) / d
                        } else if d < -1e-9 {
                            (all.0[k] - p[k]) / d
                        } else {
                            f32::INFINITY
                        }
                    })
                    .fold(f32::INFINITY, f32::min)
                    .max(0.0);
                if exit.is_finite() {
                    points.push(*p + towards * exit);
                }
            }
        }
        _ => points.push(light.position),
    }
    let (vlo, vhi) = transformed_bounds(Mat4::IDENTITY, &points);
    casters
        .iter()
        .map(|(lo, hi)| (lo.max(vlo), hi.min(vhi)))
        .filter(|(lo, hi)| lo.cmple(*hi).all())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.0, 1.7, 0.0),
            target: Vec3::new(0.0, 1.2, -20.0),
            fov_y: 55f32.to_radians(),
            near: 0.1,
            far: 200.0,
        }
    }

    fn ground() -> Aabb {
        (
            Vec3::new(-300.0, -0.1, -300.0),
            Vec3::new(300.0, 0.0, 300.0),
        )
    }

    fn inside(frustum: &LightFrustum, p: Vec3) -> bool {
        let clip = frustum.view_proj * p.extend(1.0);
        let q = clip.xyz() / clip.w;
        clip.w > 0.0
            && q.x.abs() <= 1.0 + 1e-4
            && q.y.abs() <= 1.0 + 1e-4
            && (-1e-4..=1.0 + 1e-4).contains(&q.z)
    }

    #[test]
    fn lispsm_near_distance_follows_the_paper() {
        // sin γ = 1, d = z_f - z_n: n_opt = z_n + sqrt(z_n z_f).
        let (z_n, z_f) = (1.0f32, 100.0f32);
        let n = lispsm_near(z_n, z_f - z_n, 1.0);
        assert!((n - (z_n + (z_n * z_f).sqrt())).abs() < 1e-4, "{n}");
        // Shallower angles push the warp away: n grows without bound as sin γ -> 0.
        let ns: Vec<f32> = [1.0, 0.5, 0.1, 0.01]
            .map(|s| lispsm_near(z_n, 99.0, s))
            .to_vec();
        assert!(ns.windows(2).all(|w| w[1] > w[0]), "{ns:?}");
    }

    #[test]
    fn lispsm_holds_the_view_and_the_casters_towards_the_light() {
        let c = camera();
        let direction = Vec3::new(0.8, -0.5, 0.1).normalize();
        let caster_centre = Vec3::new(-30.0, 18.0, -10.0);
        let caster = (caster_centre - Vec3::ONE, caster_centre + Vec3::ONE);
        let fit = lispsm_frustum(direction, &c, 1.5, (0.1, 200.0), &[caster], 1.0);
        assert!(fit.n.is_finite() && fit.sin_gamma > 0.9);
        // Visible ground points from 1 m to 190 m are inside.
        for z in [1.0, 5.0, 40.0, 190.0] {
            for x in [-0.3, 0.0, 0.3] {
                let p = Vec3::new(x * z, 0.0, -z);
                assert!(inside(&fit.frustum, p), "ground at {p}");
            }
        }
        assert!(
            inside(&fit.frustum, caster_centre),
            "caster towards the light"
        );
        // The warp spends texels near the viewer: finer texels at 2 m than a uniform map.
        let uniform = lispsm_frustum(direction, &c, 1.5, (0.1, 200.0), &[caster], 0.0);
        let at = Vec3::new(0.0, 0.0, -2.0);
        let (warped, flat) = (
            fit.frustum.texel_world_size(at, 2048),
            uniform.frustum.texel_world_size(at, 2048),
        );
        assert!(
            warped < 0.5 * flat,
            "texel at 2 m: warped {warped}, uniform {flat}"
        );
    }

    #[test]
    fn tsm_gives_the_focus_region_eighty_percent_of_the_rows() {
        // η from the paper's ξ = −0.6: (λδ + λδξ) / (λ − 2δ − λξ).
        let (lambda, delta, xi) = (10.0f32, 3.0f32, -0.6f32);
        let paper = (lambda * delta + lambda * delta * xi) / (lambda - 2.0 * delta - lambda * xi);
        assert!((tsm_eta(lambda, delta) - paper).abs() < 1e-4);
        assert!(tsm_eta(lambda, 0.85 * lambda).is_infinite());
        let c = camera();
        let direction = Vec3::new(0.8, -0.5, 0.1).normalize();
        let caster_centre = Vec3::new(-30.0, 18.0, -10.0);
        let caster = (caster_centre - Vec3::ONE, caster_centre + Vec3::ONE);
        let focus = 0.1;
        let fit = tsm_frustum(direction, &c, 1.5, (0.1, 200.0), &[caster], focus);
        assert!(fit.eta.is_finite() && fit.lambda > 0.0, "{fit:?}");
        for z in [1.0, 5.0, 40.0, 190.0] {
            for x in [-0.3, 0.0, 0.3] {
                let p = Vec3::new(x * z, 0.0, -z);
                assert!(inside(&fit.frustum, p), "ground at {p}");
            }
        }
        assert!(
            inside(&fit.frustum, caster_centre),
            "caster towards the light"
        );
        // The rows of the map's near edge and of the focus depth: 80 % of the way apart, in
        // the map's row direction (along the view on the map), as the near plane's centre is
        // to the far plane's.
        let view_dir = (c.target - c.position).normalize();
        let row = |d: f32| map(&fit.frustum, c.position + view_dir * d).truncate();
        let (first, focused, last) = (row(0.1), row(0.1 + focus * 199.9), row(200.0));
        let share = (focused - first).length() / (last - first).length();
        assert!(
            (share - TSM_FOCUS_SHARE).abs() < 0.05,
            "focus share {share}"
        );
        // So texels near the viewer are finer than a uniform map's.
        let uniform = lispsm_frustum(direction, &c, 1.5, (0.1, 200.0), &[caster], 0.0);
        let at = Vec3::new(0.0, 0.0, -2.0);
        let (warped, flat) = (
            fit.frustum.texel_world_size(at, 2048),
            uniform.frustum.texel_world_size(at, 2048),
        );
        assert!(
            warped < 0.5 * flat,
            "texel at 2 m: TSM {warped}, uniform {flat}"
        );
    }

    #[test]
    fn tsm_becomes_uniform_when_light_and_view_align() {
        let c = camera();
        let direction = (c.target - c.position).normalize();
        let fit = tsm_frustum(direction, &c, 1.5, (0.1, 200.0), &[], 0.3);
        assert!(fit.eta.is_infinite());
        for z in [1.0, 190.0] {
            assert!(inside(&fit.frustum, c.position + direction * z));
        }
    }

    #[test]
    fn lispsm_becomes_uniform_when_light_and_view_align() {
        let c = camera();
        let direction = (c.target - c.position).normalize();
        let fit = lispsm_frustum(direction, &c, 1.5, (0.1, 200.0), &[], 1.0);
        assert!(fit.n.is_infinite());
        let uniform = lispsm_frustum(direction, &c, 1.5, (0.1, 200.0), &[], 0.0);
        assert_eq!(fit.frustum.view_proj, uniform.frustum.view_proj);
    }

    /// A directional light travelling along `direction`.
    fn sun(direction: Vec3) -> Light {
        Light {
            kind: LightKind::Directional,
            position: Vec3::ZERO,
            direction,
            radiance: Vec3::ONE,
            range: 0.0,
            spot_angle: 0.0,
            spot_softness: 0.0,
            radius: 0.0,
        }
    }

    /// Map position and depth of `p`.
    fn map(frustum: &LightFrustum, p: Vec3) -> Vec3 {
        let clip = frustum.view_proj * p.extend(1.0);
        clip.xyz() / clip.w
    }

    #[test]
    fn psm_keeps_a_caster_behind_the_viewer() {
        let c = camera();
        // A low sun from the left and behind the viewer: its rays pass behind the viewer
        // before they reach the view.
        let light = sun(Vec3::new(0.9, -0.4, -0.15).normalize());
        // A receiver point in view, and a caster on its light ray behind the viewer.
        let receiver = Vec3::new(2.0, 0.0, -6.0);
        let blocker = receiver - light.direction * 60.0;
        assert!(
            blocker.z > c.position.z + 2.0,
            "behind the viewer: {blocker}"
        );
        let caster = (blocker - Vec3::splat(0.3), blocker + Vec3::splat(0.3));
        let fit = psm_frustum(
            &light,
            &c,
            1.5,
            (0.1, 200.0),
            &[caster, ground()],
            &[caster, ground()],
            0.002,
        )
        .expect("the light is outside the view's box");
        assert!(fit.slide > 0.0, "the virtual camera slid back");
        assert!(
            fit.inverted,
            "a light behind the viewer inverts the depth order"
        );
        assert!(inside(&fit.frustum, receiver) && inside(&fit.frustum, blocker));
        let (r, b) = (map(&fit.frustum, receiver), map(&fit.frustum, blocker));
        assert!(
            (r.truncate() - b.truncate()).length() < 1e-3,
            "same map texel: {r} {b}"
        );
        assert!(
            b.z < r.z,
            "the caster is nearer the light in the map: {b} {r}"
        );
    }

    #[test]
    fn psm_gives_up_where_one_map_cannot_hold_the_view() {
        // A sun straight behind the viewer lands just past the far plane, inside the view's
        // post-perspective footprint: it would need a field of view near 180 degrees.
        let c = camera();
        let light = sun(Vec3::new(0.0, -0.4, -1.0).normalize());
        let fit = psm_frustum(
            &light,
            &c,
            1.5,
            (0.1, 200.0),
            &[ground()],
            &[ground()],
            0.002,
        );
        assert!(fit.is_none());
    }

    #[test]
    fn psm_orders_depth_along_a_light_in_front() {
        let c = camera();
        let light = sun(Vec3::new(0.9, -0.4, 0.3).normalize());
        let receiver = Vec3::new(1.0, 0.0, -12.0);
        let blocker = receiver - light.direction * 3.0;
        let caster = (blocker - Vec3::splat(0.2), blocker + Vec3::splat(0.2));
        let fit = psm_frustum(
            &light,
            &c,
            1.5,
            (0.1, 200.0),
            &[caster, ground()],
            &[caster, ground()],
            0.002,
        )
        .unwrap();
        assert!(!fit.inverted);
        let (r, b) = (map(&fit.frustum, receiver), map(&fit.frustum, blocker));
        assert!((r.truncate() - b.truncate()).length() < 1e-3);
        assert!(b.z < r.z);
    }

    #[test]
    fn coarseness_is_the_same_at_any_scale_and_infinite_where_the_map_does_not_reach() {
        let light = sun(Vec3::new(0.5, -0.8, -0.3).normalize());
        let base = camera();
        let size = UVec2::new(320, 200);
        let coarseness_at = |s: f32, resolution: u32| {
            let c = base.scaled(s);
            let scaled = [(ground().0 * s, ground().1 * s)];
            let fit = psm_frustum(
                &light,
                &c,
                1.6,
                (0.1 * s, 60.0 * s),
                &scaled,
                &scaled,
                0.002,
            )
            .expect("the sun warps");
            let slice = slice_corners(&c, 1.6, 0.1 * s, 60.0 * s);
            let receivers = receiver_box(&slice, &scaled);
            worst_texel_to_pixel(&fit.frustum, &light, &c, size, resolution, &receivers)
        };
        let base_value = coarseness_at(1.0, 1024);
        assert!(base_value.is_finite() && base_value > 0.0);
        let relative = |a: f32| (a / base_value - 1.0).abs();
        assert!(relative(coarseness_at(100.0, 1024)) < 1e-3);
        let nowhere = LightFrustum::warped(Mat4::IDENTITY, Mat4::from_translation(Vec3::X * 10.0));
        let slice = slice_corners(&base, 1.6, 0.1, 60.0);
        let receivers = receiver_box(&slice, &[ground()]);
        let uncovered = worst_texel_to_pixel(&nowhere, &light, &base, size, 1024, &receivers);
        assert_eq!(uncovered, f32::INFINITY);
    }

    #[test]
    fn psm_fits_the_same_view_at_every_scale() {
        // A spot light and a sun over a caster on the ground: the fit (and whether PSM warps at
        // all) must not depend on the scene's units.
        let base = camera();
        let spot = Light {
            kind: LightKind::Spot,
            position: Vec3::new(-3.0, 5.0, -4.0),
            direction: Vec3::new(0.4, -1.0, -0.2).normalize(),
            range: 40.0,
            spot_angle: 0.8,
            ..sun(Vec3::NEG_Y)
        };
        let caster = (Vec3::new(-1.0, 0.0, -7.0), Vec3::new(0.0, 2.0, -6.0));
        for light in [spot, sun(Vec3::new(0.5, -0.8, -0.3).normalize())] {
            let fit_at = |s: f32| {
                let c = Camera {
                    position: base.position * s,
                    target: base.target * s,
                    near: base.near * s,
                    far: base.far * s,
                    ..base
                };
                let l = Light {
                    position: light.position * s,
                    range: light.range * s,
                    ..light
                };
                let scaled = |(lo, hi): Aabb| (lo * s, hi * s);
                let boxes = [scaled(caster), scaled(ground())];
                psm_frustum(&l, &c, 1.5, (0.1 * s, 60.0 * s), &boxes, &boxes, 0.002)
                    .map(|f| f.frustum.view_proj * Mat4::from_scale(Vec3::splat(s)))
            };
            let unit = fit_at(1.0).expect("PSM warps this view");
            for s in [1e-3, 0.01, 100.0, 1e4] {
                let fit = fit_at(s).unwrap_or_else(|| panic!("no fit at scale {s}"));
                // Homogeneous matrices agree up to a common factor: compare normalised.
                let norm = |m: Mat4| m * (1.0 / m.w_axis.length());
                let (a, b) = (norm(unit), norm(fit));
                assert!(
                    a.abs_diff_eq(b, 1e-3),
                    "{:?} at scale {s}: {b:?} against {a:?}",
                    light.kind
                );
            }
        }
    }
}
