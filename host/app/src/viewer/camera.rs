//! The viewer's camera: orbit around a pivot or fly with WASD, and named bookmarks.

use serde::{Deserialize, Serialize};
use zoo_host::glam::{Vec2, Vec3};
use zoo_host::scene::Camera;

/// How mouse drags and keys move the camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum CameraMode {
    /// Drag rotates around the pivot, the wheel zooms.
    Orbit,
    /// Drag looks around, WASD moves, Q/E go down/up, Shift is faster, the wheel sets speed.
    Fly,
}

/// Radians per dragged point.
const ROTATE_PER_POINT: f32 = 0.01;
/// Pitch stays short of straight up or down so the view never flips.
const MAX_PITCH: f32 = 1.5;

/// Movement requested by the keyboard in one frame, each axis in -1..=1.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FlyInput {
    pub forward: f32,
    pub right: f32,
    pub up: f32,
    /// Shift held: four times faster.
    pub boost: bool,
}

/// The camera as position, heading and the distance to the pivot it orbits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraController {
    pub mode: CameraMode,
    pub position: Vec3,
    /// Heading around +Y; 0 looks along +Z.
    pub yaw: f32,
    /// Elevation of the view direction.
    pub pitch: f32,
    /// Distance from the position to the pivot along the view direction.
    pub distance: f32,
    /// Fly speed in world units per second.
    pub speed: f32,
    pub fov_y: f32,
    pub near: f32,
    pub far: f32,
}

impl CameraController {
    /// A controller showing `camera`, in orbit mode, flying at a speed suited to `extent`
    /// (the scene's diagonal).
    pub fn new(camera: &Camera, extent: f32) -> CameraController {
        let mut controller = CameraController {
            mode: CameraMode::Orbit,
            position: camera.position,
            yaw: 0.0,
            pitch: 0.0,
            distance: 1.0,
            speed: (extent * 0.25).max(0.1),
            fov_y: camera.fov_y,
            near: camera.near,
            far: camera.far,
        };
        controller.look_at(camera.position, camera.target);
        controller
    }

    /// Places the camera at `position` looking at (and orbiting) `target`.
    pub fn look_at(&mut self, position: Vec3, target: Vec3) {
        let offset = target - position;
        let distance = offset.length();
        let forward = if distance > 1e-6 {
            offset / distance
        } else {
            Vec3::Z
        };
        self.position = position;
        self.distance = distance.max(1e-3);
        self.yaw = forward.x.atan2(forward.z);
        self.pitch = forward
            .y
            .clamp(-1.0, 1.0)
            .asin()
            .clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(sy * cp, sp, cy * cp)
    }

    /// Unit vector to the right of the view, horizontal.
    pub fn right(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        Vec3::new(-cy, 0.0, sy)
    }

    /// The point orbit mode rotates around.
    pub fn pivot(&self) -> Vec3 {
        self.position + self.forward() * self.distance
    }

    /// The camera to render with.
    pub fn camera(&self) -> Camera {
        Camera {
            position: self.position,
            target: self.pivot(),
            fov_y: self.fov_y,
            near: self.near,
            far: self.far,
        }
    }

    /// A mouse drag of `delta` points: orbits around the pivot or looks around.
    pub fn drag(&mut self, delta: Vec2) {
        let pivot = self.pivot();
        self.yaw -= delta.x * ROTATE_PER_POINT;
        self.pitch = (self.pitch - delta.y * ROTATE_PER_POINT).clamp(-MAX_PITCH, MAX_PITCH);
        if self.mode == CameraMode::Orbit {
            self.position = pivot - self.forward() * self.distance;
        }
    }

    /// Mouse wheel by `points`: zooms toward the pivot (orbit) or changes speed (fly).
    pub fn scroll(&mut self, points: f32) {
        if points == 0.0 {
            return;
        }
        let factor = (1.0 - points * 0.002).clamp(0.5, 2.0);
        match self.mode {
            CameraMode::Orbit => {
                let pivot = self.pivot();
                self.distance = (self.distance * factor).max(0.05);
                self.position = pivot - self.forward() * self.distance;
            }
            CameraMode::Fly => self.speed = (self.speed / factor).clamp(0.01, 1000.0),
        }
    }

    /// Moves by the keyboard for `seconds` (fly mode only; the pivot moves along).
    pub fn fly(&mut self, input: FlyInput, seconds: f32) {
        if self.mode != CameraMode::Fly {
            return;
        }
        let direction =
            self.forward() * input.forward + self.right() * input.right + Vec3::Y * input.up;
        let boost = if input.boost { 4.0 } else { 1.0 };
        self.position += direction.normalize_or_zero() * self.speed * boost * seconds.min(0.25);
    }
}

/// A named camera placement, saved with the viewer settings per scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bookmark {
    pub name: String,
    pub position: [f32; 3],
    pub target: [f32; 3],
}

impl Bookmark {
    /// Records where `controller` is now.
    pub fn of(name: &str, controller: &CameraController) -> Bookmark {
        Bookmark {
            name: name.to_string(),
            position: controller.position.to_array(),
            target: controller.pivot().to_array(),
        }
    }

    /// Moves `controller` here (keeping its mode, speed and lens).
    pub fn apply(&self, controller: &mut CameraController) {
        controller.look_at(Vec3::from(self.position), Vec3::from(self.target));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(3.0, 4.0, 5.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            fov_y: 0.8,
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn starts_exactly_at_the_scene_camera() {
        let c = CameraController::new(&camera(), 10.0).camera();
        assert!(c.position.abs_diff_eq(camera().position, 1e-5));
        assert!(c.target.abs_diff_eq(camera().target, 1e-5), "{c:?}");
    }

    #[test]
    fn orbiting_keeps_the_pivot_and_distance() {
        let mut c = CameraController::new(&camera(), 10.0);
        let pivot = c.pivot();
        let distance = c.position.distance(pivot);
        c.drag(Vec2::new(40.0, -25.0));
        c.scroll(0.0);
        assert!(c.pivot().abs_diff_eq(pivot, 1e-4));
        assert!((c.position.distance(pivot) - distance).abs() < 1e-4);
        // Zooming moves toward the pivot.
        c.scroll(100.0);
        assert!(c.position.distance(pivot) < distance);
        assert!(c.pivot().abs_diff_eq(pivot, 1e-4));
    }

    #[test]
    fn flying_looks_in_place_and_moves_along_the_view() {
        let mut c = CameraController::new(&camera(), 10.0);
        c.mode = CameraMode::Fly;
        let start = c.position;
        c.drag(Vec2::new(30.0, 10.0));
        assert_eq!(c.position, start, "looking around does not move the camera");
        let forward = c.forward();
        c.speed = 4.0;
        let input = FlyInput {
            forward: 1.0,
            ..Default::default()
        };
        c.fly(input, 0.25);
        assert!(c.position.abs_diff_eq(start + forward, 1e-5));
        // A stalled frame moves at most a quarter second's worth.
        let here = c.position;
        c.fly(input, 3.0);
        assert!(c.position.abs_diff_eq(here + forward, 1e-5));
        c.speed = 2.0;
        // Right is perpendicular to forward and horizontal; Shift is four times faster.
        assert!(c.right().dot(forward).abs() < 1e-6 && c.right().y == 0.0);
        let before = c.position;
        c.fly(
            FlyInput {
                right: 1.0,
                boost: true,
                ..Default::default()
            },
            0.25,
        );
        assert!(c.position.abs_diff_eq(before + c.right() * 2.0, 1e-5));
        // Orbit mode ignores the keys.
        c.mode = CameraMode::Orbit;
        let here = c.position;
        c.fly(input, 1.0);
        assert_eq!(c.position, here);
    }

    #[test]
    fn dragging_right_turns_the_view_right() {
        let mut c = CameraController::new(&camera(), 10.0);
        c.mode = CameraMode::Fly;
        let right = c.right();
        let before = c.forward();
        c.drag(Vec2::new(20.0, 0.0));
        assert!((c.forward() - before).dot(right) > 0.0);
    }

    #[test]
    fn bookmarks_restore_the_placement() {
        let mut c = CameraController::new(&camera(), 10.0);
        let mark = Bookmark::of("start", &c);
        c.drag(Vec2::new(100.0, 50.0));
        c.scroll(-300.0);
        mark.apply(&mut c);
        let restored = c.camera();
        assert!(restored.position.abs_diff_eq(camera().position, 1e-4));
        assert!(restored.target.abs_diff_eq(camera().target, 1e-4));
    }
}
