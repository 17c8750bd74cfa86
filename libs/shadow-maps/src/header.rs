//! The per-light header every shadow-map lookup reads: `MapHeader` in
//! `shaders/shadow-maps/receiver.wgsl`, nested first in a technique's per-light uniform.

use crate::planning::LightMaps;

zoo_host::gpu_struct! {
    "shadow-maps/map_header.wgsl" =>
    /// What a lookup needs of one light's maps: its layers, their projection and the normal
    /// offset (`receiver.wgsl` derives texel sizes and receivers from it).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct MapHeader {
        /// Index of the scene light.
        pub light: u32,
        pub first_layer: u32,
        /// 1 (spot, directional) or 6 (point: cube faces).
        pub layer_count: u32,
        /// 1 for perspective layers, 0 for orthographic (and warped) ones.
        pub perspective: u32,
        /// World size of a texel per unit of distance along the layer's axis (perspective) or
        /// absolute (orthographic).
        pub texel_scale: f32,
        /// Lookups move off the surface by this many texels along its normal.
        pub normal_offset: f32,
        /// The layers' near and far planes along their axis.
        pub near: f32,
        pub far: f32,
    }
}

impl MapHeader {
    /// The header of `maps`, with lookups `normal_offset` texels off the surface.
    pub fn new(maps: &LightMaps, normal_offset: f32) -> MapHeader {
        let scale = maps.scale();
        MapHeader {
            light: maps.light as u32,
            first_layer: maps.first_layer,
            layer_count: maps.frustums.len() as u32,
            perspective: u32::from(scale.perspective),
            texel_scale: scale.texel_scale,
            normal_offset,
            near: scale.near,
            far: scale.far,
        }
    }
}
