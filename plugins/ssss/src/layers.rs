//! Lights into screen-space layers by greedy graph colouring (seed 001 §5).
//!
//! Two lights whose influence can meet on a visible surface must not share a layer: their
//! shadows are blurred together in screen space, one channel per layer. A light's influence
//! is the bounding sphere of its range (a spot cone's tighter sphere when the cone is narrow);
//! two visible lights are joined when their spheres intersect and the bounding sphere of the
//! intersection touches the view frustum, so moving the camera away from where two lights
//! overlap lets them share a layer. Lights whose influence is off screen are culled (no maps,
//! no layer of their own). A directional light reaches every surface: it is joined to every
//! visible light and so keeps a layer alone.
//!
//! Colouring takes lights in decreasing order of degree (Welsh and Powell), each into the
//! lowest layer none of its neighbours holds: at most Δ + 1 layers. The seed orders by
//! increasing degree; its own sample code ends up in index order.

use zoo_host::glam::{Mat4, Vec3, Vec4};
use zoo_host::scene::{Light, LightKind};
use zoo_shadow_maps::culling::{frustum_planes, sphere_intersects};

/// Where a light can shine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Influence {
    /// Everywhere (directional lights).
    Everywhere,
    /// Inside a sphere.
    Sphere { centre: Vec3, radius: f32 },
}

/// The bounding sphere of a light's influence: its range sphere, or for a spot cone of half
/// angle at most 45° the smaller sphere through its apex and rim.
pub fn influence(light: &Light) -> Influence {
    match light.kind {
        LightKind::Directional => Influence::Everywhere,
        LightKind::Point => Influence::Sphere {
            centre: light.position,
            radius: light.range,
        },
        LightKind::Spot => {
            let half_angle = light.spot_angle;
            if half_angle <= std::f32::consts::FRAC_PI_4 {
                let radius = light.range / (2.0 * half_angle.cos());
                Influence::Sphere {
                    centre: light.position + light.direction.normalize_or_zero() * radius,
                    radius,
                }
            } else {
                Influence::Sphere {
                    centre: light.position,
                    radius: light.range,
                }
            }
        }
    }
}

/// A sphere holding the intersection of two spheres, or `None` when they do not meet.
pub fn intersection_bound(a: (Vec3, f32), b: (Vec3, f32)) -> Option<(Vec3, f32)> {
    let ((ca, ra), (cb, rb)) = (a, b);
    let d = ca.distance(cb);
    if d >= ra + rb {
        return None;
    }
    let smaller = if ra <= rb { a } else { b };
    if d + ra.min(rb) <= ra.max(rb) || d <= 0.0 {
        return Some(smaller);
    }
    // The plane of the circle where the surfaces meet, at `along` from `ca`.
    let along = (d * d + ra * ra - rb * rb) / (2.0 * d);
    if along < 0.0 || along > d {
        return Some(smaller);
    }
    let radius = (ra * ra - along * along).max(0.0).sqrt();
    Some((ca + (cb - ca) / d * along, radius))
}

/// The layer of each light and the layer count.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Layers {
    /// Per scene light: its layer, or `None` when it is culled (its influence is off screen).
    pub of_light: Vec<Option<u32>>,
    /// Layers in use.
    pub count: u32,
}

impl Layers {
    /// The lights in `layer`.
    pub fn members(&self, layer: u32) -> impl Iterator<Item = usize> + '_ {
        (0..self.of_light.len()).filter(move |&i| self.of_light[i] == Some(layer))
    }
}

/// Whether the influences of two visible lights can meet inside the view.
fn joined(a: Influence, b: Influence, planes: &[Vec4; 6]) -> bool {
    match (a, b) {
        (
            Influence::Sphere {
                centre: ca,
                radius: ra,
            },
            Influence::Sphere {
                centre: cb,
                radius: rb,
            },
        ) => intersection_bound((ca, ra), (cb, rb))
            .is_some_and(|(c, r)| sphere_intersects(planes, c, r)),
        _ => true,
    }
}

/// Colours `lights` for a camera with world-to-clip matrix `view_proj`.
pub fn assign_layers(lights: &[Light], view_proj: Mat4) -> Layers {
    let planes = frustum_planes(view_proj);
    let influences: Vec<Influence> = lights.iter().map(influence).collect();
    let visible: Vec<usize> = (0..lights.len())
        .filter(|&i| match influences[i] {
            Influence::Everywhere => true,
            Influence::Sphere { centre, radius } => sphere_intersects(&planes, centre, radius),
        })
        .collect();
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); lights.len()];
    for (k, &i) in visible.iter().enumerate() {
        for &j in &visible[k + 1..] {
            if joined(influences[i], influences[j], &planes) {
                neighbours[i].push(j);
                neighbours[j].push(i);
            }
        }
    }
    let mut order = visible.clone();
    order.sort_by_key(|&i| (std::cmp::Reverse(neighbours[i].len()), i));
    let mut of_light = vec![None; lights.len()];
    let mut count = 0;
    let mut taken = Vec::new();
    for i in order {
        taken.clear();
        taken.resize(count as usize + 1, false);
        for &j in &neighbours[i] {
            if let Some(layer) = of_light[j] {
                taken[layer as usize] = true;
            }
        }
        let layer = taken.iter().position(|t| !t).unwrap_or(taken.len()) as u32;
        of_light[i] = Some(layer);
        count = count.max(layer + 1);
    }
    Layers { of_light, count }
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::glam::camera::rh::proj::directx;

    fn point(x: f32, z: f32, range: f32) -> Light {
        Light {
            kind: LightKind::Point,
            position: Vec3::new(x, 1.0, z),
            direction: Vec3::NEG_Y,
            radiance: Vec3::ONE,
            range,
            spot_angle: 0.5,
            spot_softness: 0.1,
            radius: 0.1,
        }
    }

    fn camera(eye: Vec3, target: Vec3) -> Mat4 {
        directx::perspective(1.0, 1.5, 0.1, 100.0)
            * zoo_host::glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y)
    }

    /// Every pair in one layer must not be joined.
    fn assert_proper(lights: &[Light], layers: &Layers, view_proj: Mat4) {
        let planes = frustum_planes(view_proj);
        for layer in 0..layers.count {
            let members: Vec<usize> = layers.members(layer).collect();
            for (k, &a) in members.iter().enumerate() {
                for &b in &members[k + 1..] {
                    assert!(
                        !joined(influence(&lights[a]), influence(&lights[b]), &planes),
                        "lights {a} and {b} overlap on screen but share layer {layer}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_intersection_bound_holds_the_lens() {
        let a = (Vec3::ZERO, 2.0);
        let b = (Vec3::new(3.0, 0.0, 0.0), 1.5);
        let (c, r) = intersection_bound(a, b).unwrap();
        // Sample points in both spheres: all inside the bound.
        for i in 0..4000 {
            let t = i as f32;
            let p = Vec3::new(
                1.0 + 1.0 * (t * 0.37).sin(),
                1.6 * (t * 0.71).cos(),
                1.6 * (t * 1.13).sin(),
            );
            if p.distance(a.0) <= a.1 && p.distance(b.0) <= b.1 {
                assert!(p.distance(c) <= r + 1e-4, "{p} outside ({c}, {r})");
            }
        }
        assert!(r < 1.5);
        assert_eq!(intersection_bound(a, (Vec3::new(4.0, 0.0, 0.0), 1.5)), None);
        // One sphere inside the other: the smaller.
        let inner = (Vec3::new(0.5, 0.0, 0.0), 0.5);
        assert_eq!(intersection_bound(a, inner), Some(inner));
    }

    #[test]
    fn overlapping_lights_never_share_and_the_sun_is_alone() {
        let view_proj = camera(Vec3::new(0.0, 20.0, 20.0), Vec3::ZERO);
        let mut lights: Vec<Light> = (0..64)
            .map(|i| point((i % 8) as f32 * 2.5 - 9.0, (i / 8) as f32 * 2.5 - 9.0, 3.0))
            .collect();
        lights.push(Light {
            kind: LightKind::Directional,
            ..point(0.0, 0.0, f32::INFINITY)
        });
        let layers = assign_layers(&lights, view_proj);
        assert_proper(&lights, &layers, view_proj);
        let sun = layers.of_light[64].unwrap();
        assert_eq!(layers.members(sun).collect::<Vec<_>>(), vec![64]);
        // Range 3 on a 2.5 grid: neighbours up to two cells away overlap; far fewer layers
        // than lights are needed.
        assert!(layers.count < 20, "{} layers", layers.count);
        assert!(layers.count >= 5);
    }

    #[test]
    fn a_camera_move_that_separates_two_lights_lets_them_share() {
        // Spheres of radius 3 around x = -2 and x = 2 meet near the origin.
        let lights = [point(-2.0, 0.0, 3.0), point(2.0, 0.0, 3.0)];
        let looking_at_overlap = camera(Vec3::new(0.0, 2.0, 8.0), Vec3::new(0.0, 1.0, 0.0));
        let layers = assign_layers(&lights, looking_at_overlap);
        assert_ne!(layers.of_light[0], layers.of_light[1]);
        assert_eq!(layers.count, 2);
        // Looking down from above at x = 4.2 to 6 sees only the right light's far side.
        let away = camera(Vec3::new(5.5, 4.0, 0.0), Vec3::new(5.5, 0.0, -0.01));
        let layers = assign_layers(&lights, away);
        assert_eq!(
            layers.of_light[0], None,
            "the left light is off screen: culled"
        );
        let aside = camera(Vec3::new(0.0, 1.0, 30.0), Vec3::new(0.0, 1.0, 40.0));
        let layers = assign_layers(&lights, aside);
        assert_eq!(layers.count, 0, "looking away from both");
    }

    #[test]
    fn lights_visible_apart_share_when_their_overlap_is_off_screen() {
        // Two lights whose spheres meet only behind the camera.
        let lights = [point(-4.5, 0.0, 5.0), point(4.5, 0.0, 5.0)];
        // A wide lens (115 degrees) just in front of where they meet, looking away.
        let eye = Vec3::new(0.0, 1.0, -2.5);
        let view_proj = directx::perspective(2.0, 1.5, 0.1, 100.0)
            * zoo_host::glam::camera::rh::view::look_at_mat4(eye, eye - Vec3::Z, Vec3::Y);
        let planes = frustum_planes(view_proj);
        let bound = intersection_bound((lights[0].position, 5.0), (lights[1].position, 5.0));
        let (c, r) = bound.unwrap();
        assert!(
            !sphere_intersects(&planes, c, r),
            "the overlap is behind the camera"
        );
        let layers = assign_layers(&lights, view_proj);
        assert!(layers.of_light.iter().all(|l| *l == Some(0)), "{layers:?}");
    }
}
