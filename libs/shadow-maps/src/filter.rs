//! The shadow-map filters as one choice: [`Filter`] for parameters, [`MapFilter`] (the WGSL
//! `MapFilter` of `shaders/shadow-maps/filters.wgsl`) in a light's lookup uniform, and
//! [`MapFilters`], which reads the shader's `FILTER_*` codes so no number is kept twice.

use zoo_host::ShaderLibrary;
use zoo_host::gpu::layout::ChoiceCodes;
use zoo_host::prelude::*;

use crate::FilterParams;

/// The library shader that declares the filters and their codes (`filters.wgsl`), composed
/// with a map access (the filters call the importer's taps, so they do not stand alone).
const FILTERS: &str = "shadow-maps/header_lookup.wgsl";

zoo_host::param_choice! {
    /// How shadow-map comparisons are filtered: one tap, the hardware's bilinear 2x2, an N x N
    /// grid (odd kernels centred on a texel, even ones between four; 4x4, 8x8 and 16x16 as in
    /// seed 000, 11x11 and 23x23 as in seed 001's Table 1), a rotated Poisson disc, PCSS
    /// (penumbrae sized by the blocker distance), stochastic PCF (four taps of the Poisson
    /// disc's area, moved every frame: noisy alone, the disc's filtering on average over
    /// frames), or shadow-map ray tracing (SMRT: rays from the receiver to points of the
    /// light's area, each marched through the map as a height field).
    pub enum Filter {
        None, Hardware2x2, Pcf3x3, Pcf4x4, Pcf5x5, Pcf7x7, Pcf8x8, Pcf9x9, Pcf11x11, Pcf16x16,
        Pcf23x23, Poisson, Pcss, Stochastic, Smrt
    }
}

zoo_host::gpu_struct! {
    "shadow-maps/map_filter.wgsl" =>
    /// One light's filter as a lookup reads it (`shadow-maps/filters.wgsl`).
    #[derive(Debug, Clone, Copy, PartialEq, Default)]
    pub struct MapFilter {
        /// The shader's code of the [`Filter`].
        pub mode: u32,
        /// Poisson disc radius, in texels.
        pub kernel_texels: f32,
        /// Largest PCSS blocker search and penumbra radius, in texels.
        pub search_texels: f32,
        /// Radius (point, spot) or tangent of the angular radius (directional), for PCSS and
        /// SMRT.
        pub light_size: f32,
        /// SMRT's rays a receiver, and samples along each ray.
        pub rays: u32,
        pub ray_samples: u32,
        /// Where SMRT's samples start, in texels of the map from the receiver.
        pub ray_start_texels: f32,
        /// How far behind the map's depth a sample must lie to be occluded, in texels of the
        /// map at the receiver times the receiver's slope towards the light (plus one).
        pub ray_bias_texels: f32,
    }
}

/// SMRT's samples start this many texels from the receiver (nearer, the receiver's own texels
/// would shadow it).
const SMRT_START_TEXELS: f32 = 1.0;
/// SMRT's depth slack, in texels times (1 + the receiver's slope): a texel of a surface tilted
/// from the light spans that much depth.
const SMRT_BIAS_TEXELS: f32 = 1.0;

/// The filters' shader codes, read from the shader library in use.
#[derive(Debug, Clone)]
pub struct MapFilters(ChoiceCodes);

impl MapFilters {
    /// Reads the `FILTER_*` constants of `shadow-maps/filters.wgsl`.
    pub fn read(shaders: &ShaderLibrary) -> TechniqueResult<MapFilters> {
        let source = shaders.compose(FILTERS)?.source;
        ChoiceCodes::read(&source, "FILTER", Filter::NAMES)
            .map(MapFilters)
            .map_err(|e| TechniqueError::Other(format!("{FILTERS}: {e}")))
    }

    /// The filter `p` chooses, for a light of `light_size` (see [`crate::light_size`]).
    pub fn filter(&self, p: &FilterParams, light_size: f32) -> MapFilter {
        MapFilter {
            mode: self.0.code(p.filter.index()),
            kernel_texels: p.kernel_radius,
            search_texels: p.pcss_max_texels,
            light_size,
            rays: p.smrt_rays,
            ray_samples: p.smrt_samples,
            ray_start_texels: SMRT_START_TEXELS,
            ray_bias_texels: SMRT_BIAS_TEXELS,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn every_filter_has_a_distinct_shader_code() {
        let filters = MapFilters::read(&ShaderLibrary::embedded()).unwrap();
        let mut codes: Vec<u32> = Filter::NAMES
            .iter()
            .enumerate()
            .map(|(i, _)| filters.0.code(i))
            .collect();
        codes.sort();
        codes.dedup();
        assert_eq!(codes.len(), Filter::NAMES.len());
    }
}
