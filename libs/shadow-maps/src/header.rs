//! The per-light header every shadow-map lookup reads: `MapHeader` in
//! `shaders/shadow-maps/receiver.wgsl`, nested first in a technique's per-light uniform.

use crate::planning::LightMaps;

/// What a lookup needs of one light's maps: its layers, their projection and the normal
/// offset (the WGSL `MapHeader`; `receiver.wgsl` derives texel sizes and receivers from it).
#[derive(Debug, Clone, Copy, PartialEq, zoo_host::bytemuck::Pod, zoo_host::bytemuck::Zeroable)]
#[bytemuck(crate = "zoo_host::bytemuck")]
#[repr(C)]
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
    pub near: f32,
    pub far: f32,
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

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::layout::{SizeRule, check_mirror};

    #[test]
    fn map_header_mirrors_the_shader() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose_source("test.wgsl", "#import \"shadow-maps/receiver.wgsl\"\n")
            .unwrap()
            .source;
        let (size, fields) = zoo_host::mirror_fields!(MapHeader {
            light,
            first_layer,
            layer_count,
            perspective,
            texel_scale,
            normal_offset,
            near,
            far
        });
        check_mirror(&source, "MapHeader", size, &fields, SizeRule::Equal).unwrap();
    }
}
