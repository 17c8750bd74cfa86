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
    }
}
