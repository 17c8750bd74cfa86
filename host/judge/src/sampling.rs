//! Stratified sampling of light disks.

use glam::Vec2;

/// Maps the unit square to the unit disk, keeping strata compact (Shirley and Chiu's
/// concentric mapping).
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let a = 2.0 * u - Vec2::ONE;
    if a == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if a.x.abs() > a.y.abs() {
        (a.x, std::f32::consts::FRAC_PI_4 * (a.y / a.x))
    } else {
        (
            a.y,
            std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4 * (a.x / a.y),
        )
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// `n x n` jittered samples of the unit disk, decorrelated across pixels by `seed`.
pub fn stratified_disk(n: u32, seed: u32) -> impl Iterator<Item = Vec2> {
    (0..n * n).map(move |k| {
        let (i, j) = (k % n, k / n);
        let jitter = Vec2::new(hash01(seed, 2 * k), hash01(seed, 2 * k + 1));
        concentric_disk((Vec2::new(i as f32, j as f32) + jitter) / n as f32)
    })
}

/// A deterministic pseudo-random number in [0, 1) from two integers.
fn hash01(a: u32, b: u32) -> f32 {
    let mut x = a.wrapping_mul(0x9E37_79B9) ^ b.wrapping_mul(0x85EB_CA6B);
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_cover_the_disk_uniformly() {
        let samples: Vec<Vec2> = stratified_disk(16, 7).collect();
        assert_eq!(samples.len(), 256);
        assert!(samples.iter().all(|s| s.length() <= 1.0 + 1e-6));
        // Uniform area density: a quarter of the samples inside radius 1/2, half right of x = 0.
        let inner = samples.iter().filter(|s| s.length() < 0.5).count();
        assert!((inner as f32 / 256.0 - 0.25).abs() < 0.03, "{inner}");
        let right = samples.iter().filter(|s| s.x > 0.0).count();
        assert!((right as f32 / 256.0 - 0.5).abs() < 0.03, "{right}");
        let mean = samples.iter().copied().sum::<Vec2>() / 256.0;
        assert!(mean.length() < 0.02, "{mean}");
    }
}
