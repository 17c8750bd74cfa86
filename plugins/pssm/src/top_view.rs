//! The "split frusta" debug view: a top view of the camera's split slices and each split's
//! light box, drawn on the CPU. Distances from the camera are compressed logarithmically so
//! near splits of a few metres and far ones of hundreds show together.

use zoo_host::glam::{Mat4, Vec2, Vec3};
use zoo_host::scene::Camera;
use zoo_shadow_maps::LightMaps;
use zoo_shadow_maps::cascades::slice_corners;

/// Side of the image in pixels.
pub const SIZE: u32 = 384;

const COLOURS: [[u8; 3]; 8] = [
    [242, 77, 64],
    [77, 217, 77],
    [77, 128, 255],
    [242, 217, 51],
    [217, 89, 242],
    [51, 230, 230],
    [255, 153, 51],
    [179, 179, 179],
];

/// The 12 edges of a box given by 8 corners indexed by bits (x, y, z).
const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// Maps world points to image pixels: the camera at the bottom centre looking up the image,
/// distances compressed as ln(1 + r / r0).
struct Mapping {
    origin: Vec3,
    right: Vec3,
    forward: Vec3,
    r0: f32,
    scale: f32,
}

impl Mapping {
    fn pixel(&self, p: Vec3) -> Vec2 {
        let d = p - self.origin;
        let flat = Vec2::new(d.dot(self.right), d.dot(self.forward));
        let r = flat.length();
        let squeezed = if r > 0.0 {
            flat / r * (1.0 + r / self.r0).ln() * self.scale
        } else {
            Vec2::ZERO
        };
        Vec2::new(
            SIZE as f32 * 0.5 + squeezed.x,
            SIZE as f32 * 0.92 - squeezed.y,
        )
    }
}

/// RGBA pixels of the top view of `lights`' splits at `distances`.
pub fn draw(camera: &Camera, aspect: f32, lights: &[LightMaps], distances: &[f32]) -> Vec<u8> {
    let mut image = vec![0u8; (SIZE * SIZE * 4) as usize];
    for pixel in image.chunks_exact_mut(4) {
        pixel.copy_from_slice(&[18, 20, 26, 255]);
    }
    let forward = (camera.target - camera.position) * Vec3::new(1.0, 0.0, 1.0);
    let forward = forward.try_normalize().unwrap_or(Vec3::NEG_Z);
    let far = distances
        .last()
        .copied()
        .unwrap_or(camera.far)
        .max(camera.near);
    let r0 = distances.get(1).copied().unwrap_or(far).max(camera.near) * 0.25;
    let mapping = Mapping {
        origin: camera.position,
        right: forward.cross(Vec3::Y),
        forward,
        r0,
        scale: SIZE as f32 * 0.85 / (1.0 + 1.6 * far / r0).ln(),
    };
    let mut line = |a: Vec3, b: Vec3, colour: [u8; 3]| {
        for k in 0..=160 {
            let p = mapping.pixel(a.lerp(b, k as f32 / 160.0));
            let (x, y) = (p.x.round() as i64, p.y.round() as i64);
            if (0..SIZE as i64).contains(&x) && (0..SIZE as i64).contains(&y) {
                let i = ((y as u32 * SIZE + x as u32) * 4) as usize;
                image[i..i + 3].copy_from_slice(&colour);
            }
        }
    };
    for light in lights {
        for (split, frustum) in light.frustums.iter().enumerate() {
            let colour = COLOURS[split % COLOURS.len()];
            let dim = colour.map(|c| c / 2);
            // The light's box: its clip-space cube back in world space.
            let to_world: Mat4 = frustum.view_proj.inverse();
            let corners: Vec<Vec3> = (0..8)
                .map(|i| {
                    let x = if i & 1 == 0 { -1.0 } else { 1.0 };
                    let y = if i & 2 == 0 { -1.0 } else { 1.0 };
                    let z = if i & 4 == 0 { 0.0 } else { 1.0 };
                    to_world.project_point3(Vec3::new(x, y, z))
                })
                .collect();
            for (a, b) in EDGES {
                line(corners[a], corners[b], dim);
            }
            // The split's slice of the view frustum.
            if split + 1 < distances.len() {
                let slice = slice_corners(camera, aspect, distances[split], distances[split + 1]);
                for (a, b) in EDGES {
                    line(slice[a], slice[b], colour);
                }
            }
        }
    }
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_camera_sits_at_the_bottom_and_far_points_go_up() {
        let mapping = Mapping {
            origin: Vec3::ZERO,
            right: Vec3::X,
            forward: Vec3::NEG_Z,
            r0: 1.0,
            scale: 10.0,
        };
        let camera = mapping.pixel(Vec3::ZERO);
        let near = mapping.pixel(Vec3::new(0.0, 0.0, -2.0));
        let far = mapping.pixel(Vec3::new(0.0, 0.0, -200.0));
        assert_eq!(camera.x, SIZE as f32 * 0.5);
        assert!(far.y < near.y && near.y < camera.y);
        // Logarithmic: 100 times farther is far less than 100 times higher up.
        assert!((camera.y - far.y) < 10.0 * (camera.y - near.y));
        let right = mapping.pixel(Vec3::new(3.0, 0.0, 0.0));
        assert!(right.x > camera.x);
    }
}
