//! Keyframed camera and light paths, interpolated with centripetal-free (uniform) Catmull-Rom
//! splines through the keys.

use glam::Vec3;

use crate::{Camera, CameraKey, Light, LightKind, LightPathDesc, PathsDesc};

/// Uniform Catmull-Rom through `p1`..`p2` with neighbours `p0`, `p3`, at `t` in [0, 1].
pub fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, t: f32) -> Vec3 {
    let t2 = t * t;
    let t3 = t2 * t;
    0.5 * ((2.0 * p1)
        + (p2 - p0) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
}

/// Samples keyed values at `time` (clamped to the key range); keys are sorted by time.
fn sample<K>(
    keys: &[K],
    time: f32,
    key_time: impl Fn(&K) -> f32,
    value: impl Fn(&K) -> Vec3,
) -> Option<Vec3> {
    let last = keys.len().checked_sub(1)?;
    let time = time.clamp(key_time(&keys[0]), key_time(&keys[last]));
    let i = (0..last)
        .find(|&i| time <= key_time(&keys[i + 1]))
        .unwrap_or(last.saturating_sub(1));
    if last == 0 {
        return Some(value(&keys[0]));
    }
    let (t0, t1) = (key_time(&keys[i]), key_time(&keys[i + 1]));
    let t = if t1 > t0 {
        (time - t0) / (t1 - t0)
    } else {
        0.0
    };
    let p = |k: usize| value(&keys[k.min(last)]);
    Some(catmull_rom(
        p(i.saturating_sub(1)),
        p(i),
        p(i + 1),
        p(i + 2),
        t,
    ))
}

/// Time span covered by the paths (0 when there are no keys).
pub fn duration(paths: &PathsDesc) -> (f32, f32) {
    let times = paths.camera.iter().map(|k| k.time).chain(
        paths
            .lights
            .iter()
            .flat_map(|l| l.keys.iter().map(|k| k.time)),
    );
    times
        .fold(None, |acc: Option<(f32, f32)>, t| {
            Some(acc.map_or((t, t), |(lo, hi)| (lo.min(t), hi.max(t))))
        })
        .unwrap_or((0.0, 0.0))
}

/// The camera at `time` on its path (or `camera` unchanged without camera keys).
pub fn camera_at(camera: &Camera, keys: &[CameraKey], time: f32) -> Camera {
    let position = sample(keys, time, |k| k.time, |k| k.position);
    let target = sample(keys, time, |k| k.time, |k| k.target);
    match (position, target) {
        (Some(position), Some(target)) if position.distance(target) > 1e-6 => Camera {
            position,
            target,
            ..*camera
        },
        _ => *camera,
    }
}

/// The lights at `time`: keyed lights move (position, or direction for directional lights).
pub fn lights_at(lights: &[Light], paths: &[LightPathDesc], time: f32) -> Vec<Light> {
    let mut out = lights.to_vec();
    for path in paths {
        let Some(light) = out.get_mut(path.light) else {
            continue;
        };
        let Some(value) = sample(&path.keys, time, |k| k.time, |k| k.value) else {
            continue;
        };
        match light.kind {
            LightKind::Directional => {
                if let Some(d) = value.try_normalize() {
                    light.direction = d;
                }
            }
            _ => light.position = value,
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f32, x: f32) -> CameraKey {
        CameraKey {
            time,
            position: Vec3::new(x, 1.0, 5.0),
            target: Vec3::ZERO,
        }
    }

    #[test]
    fn catmull_rom_passes_through_the_keys_and_is_linear_on_a_line() {
        let keys = [key(0.0, 0.0), key(1.0, 1.0), key(2.0, 2.0), key(3.0, 3.0)];
        let camera = Camera {
            position: Vec3::ZERO,
            target: Vec3::Z,
            fov_y: 1.0,
            near: 0.1,
            far: 10.0,
        };
        for k in &keys {
            assert!((camera_at(&camera, &keys, k.time).position - k.position).length() < 1e-5);
        }
        // Evenly spaced collinear keys: the spline stays on the line, at the linear position.
        let mid = camera_at(&camera, &keys, 1.5).position;
        assert!((mid - Vec3::new(1.5, 1.0, 5.0)).length() < 1e-5, "{mid}");
        // Clamped outside the key range.
        assert_eq!(camera_at(&camera, &keys, -3.0).position, keys[0].position);
        assert_eq!(camera_at(&camera, &keys, 9.0).position, keys[3].position);
        // No keys: unchanged.
        assert_eq!(camera_at(&camera, &[], 1.0), camera);
    }

    #[test]
    fn curve_is_smooth_through_a_corner() {
        // Tangent at a key is (p_{i+1} - p_{i-1}) / 2 on both sides.
        let (before_start, p0, p1, p2, p3) = (
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::Y,
        );
        let h = 1e-3;
        // The segment ending at p1 and the one starting there meet with the same tangent.
        let end = catmull_rom(before_start, p0, p1, p2, 1.0);
        assert!((end - p1).length() < 1e-6);
        let before = (end - catmull_rom(before_start, p0, p1, p2, 1.0 - h)) / h;
        let after = (catmull_rom(p0, p1, p2, p3, h) - catmull_rom(p0, p1, p2, p3, 0.0)) / h;
        assert!((before - after).length() < 1e-2, "{before} vs {after}");
        assert!((after - (p2 - p0) * 0.5).length() < 1e-2);
    }
}
