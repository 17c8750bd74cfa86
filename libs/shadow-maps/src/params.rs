//! Parameter groups the shadow-map techniques share, declared once: a light's map (resolution,
//! slope bias, normal offset) and how lookups filter it. A technique uses them with
//! `use map: MapParams;` in its `technique_params!`; their keys read as its own.

use crate::Filter;

zoo_host::technique_params! {
    /// A light's shadow map: resolution and bias.
    pub struct MapParams {
        /// Shadow-map resolution in texels per side (clamped to the device and memory budget).
        map_size: u32 = 2048, range(256, 8192), step(256);
        /// Slope-scaled depth bias of the depth pass (times the polygon's depth slope). Too
        /// little shows shadow acne (each texel keeps one depth for a patch of a sloped surface,
        /// which then shadows itself in stripes); too much detaches shadows from their casters
        /// (peter-panning).
        slope_bias: f32 = 1.5, range(0.0, 10.0), step(0.1), flags(rebuild);
        /// Normal offset: lookups move off the surface by this many shadow-map texels
        /// (measured at the receiver). None, with no slope bias, shows shadow acne on every lit
        /// surface; too much moves lookups past thin casters' contact (peter-panning).
        normal_offset: f32 = 1.5, range(0.0, 8.0), step(0.1);
    }
}

zoo_host::technique_params! {
    /// How shadow-map lookups are filtered.
    pub struct FilterParams {
        /// Filter: none, hardware 2x2, N x N grid PCF, rotated Poisson disc, PCSS, or
        /// stochastic PCF (four taps of the Poisson disc, moved every frame).
        filter: Filter = Filter::Pcf3x3;
        /// Poisson (and stochastic) disc radius in texels.
        kernel_radius: f32 = 2.0, range(0.5, 16.0), step(0.5);
        /// Largest PCSS blocker search and penumbra radius, in texels.
        pcss_max_texels: f32 = 24.0, range(2.0, 64.0), step(1.0);
        /// SMRT: rays from each receiver to points of the light's area (more: less noise).
        smrt_rays: u32 = 16, range(1, 64), step(1);
        /// SMRT: samples along each ray, denser near the receiver.
        smrt_samples: u32 = 8, range(2, 32), step(1);
    }
}

impl FilterParams {
    /// How far from the receiver, in texels, the filter's taps read (the largest grid offset,
    /// disc radius or PCSS search, and one more texel for bilinear taps): the reach of the map
    /// around a receiver that must be present (virtual maps mark the pages within it). SMRT's
    /// rays reach as far as their light's size takes them; PCSS's reach bounds the part of them
    /// read at the receiver's resolution (past it, a virtual map's coarser levels).
    pub fn reach_texels(&self) -> f32 {
        let grid = |n: u32| 0.5 * (n - 1) as f32 + 1.0;
        match self.filter {
            Filter::None | Filter::Hardware2x2 => 1.0,
            Filter::Pcf3x3 => grid(3),
            Filter::Pcf4x4 => grid(4),
            Filter::Pcf5x5 => grid(5),
            Filter::Pcf7x7 => grid(7),
            Filter::Pcf8x8 => grid(8),
            Filter::Pcf9x9 => grid(9),
            Filter::Pcf11x11 => grid(11),
            Filter::Pcf16x16 => grid(16),
            Filter::Pcf23x23 => grid(23),
            Filter::Poisson | Filter::Stochastic => self.kernel_radius + 1.0,
            Filter::Pcss | Filter::Smrt => self.pcss_max_texels + 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::params::TechniqueParams;

    #[test]
    fn the_reach_covers_every_tap() {
        let mut p = FilterParams::from_values(&zoo_host::params::defaults(&FilterParams::schema()))
            .unwrap();
        assert_eq!(p.reach_texels(), 2.0);
        p.filter = Filter::Pcf4x4;
        // Taps at -1.5 .. 1.5 texels, bilinear: 2.5.
        assert_eq!(p.reach_texels(), 2.5);
        p.filter = Filter::Pcf23x23;
        assert_eq!(p.reach_texels(), 12.0);
        p.filter = Filter::Pcss;
        p.pcss_max_texels = 24.0;
        assert_eq!(p.reach_texels(), 25.0);
        p.filter = Filter::Smrt;
        assert_eq!(p.reach_texels(), 25.0);
        p.filter = Filter::Poisson;
        p.kernel_radius = 3.0;
        assert_eq!(p.reach_texels(), 4.0);
    }
}
