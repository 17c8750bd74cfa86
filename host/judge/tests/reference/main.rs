//! The reference judge's integration tests in one test binary: closed-form shadows
//! (`analytic`), the one-bounce reference (`indirect`), instances traced as their copies
//! (`instances`), the leak measure's unlit surfaces (`leak`), alpha-masked casters (`masks`),
//! ray origins at any scale (`origins`) and whole scenes rendered at any scale (`scale`, on
//! the GPU).

mod analytic;
mod indirect;
mod instances;
mod leak;
mod masks;
mod origins;
mod scale;

use glam::Vec3;

/// Small deterministic generator (an LCG with an xorshift output).
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let x = self.0 ^ (self.0 >> 33);
        ((x >> 40) as u32) as f32 / (1u32 << 24) as f32
    }
    pub(crate) fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    pub(crate) fn direction(&mut self) -> Vec3 {
        loop {
            let d = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if d.length() > 0.1 && d.length() <= 1.0 {
                break d.normalize();
            }
        }
    }
}
