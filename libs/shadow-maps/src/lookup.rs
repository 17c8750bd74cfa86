//! The bind group lookups read a [`crate::ShadowMapSet`]'s maps through.
//!
//! - Colour maps (moments): the maps (`texture_2d_array<u32>`, the bits of 32-bit floats,
//!   filtered in the shader) at binding 0, the layer cameras (storage, 256-byte `LayerCamera` slots) at
//!   1.
//! - Depth maps: the layout of `shaders/shadow-maps/depth_lookup.wgsl` (group 3): the maps with
//!   linear and nearest comparison samplers, the layer cameras, the maps as plain floats, and
//!   the maps again for the nearest sampler (GLSL pairs each texture with one sampler).

use zoo_host::kit::{
    Joinable, NamedGroup, bind_group, bind_group_layout, sampler, storage, texture,
};
use zoo_host::wgpu;

use crate::maps::MapArray;

/// The variables of the depth maps' lookup group as `depth_lookup.wgsl` declares them.
const DEPTH_VARIABLES: &[&str] = &[
    "depth_maps",
    "depth_compare_linear",
    "depth_compare_nearest",
    "layer_cameras",
    "depth_values",
    "depth_maps_nearest",
];
/// The variables of the colour maps' lookup group as `color_lookup.wgsl` declares them.
const COLOR_VARIABLES: &[&str] = &["color_maps", "layer_cameras"];

/// Layout, samplers and the current bind group.
pub(crate) struct LookupGroup {
    label: String,
    depth: bool,
    pub(crate) layout: wgpu::BindGroupLayout,
    samplers: Vec<wgpu::Sampler>,
    pub(crate) group: Option<wgpu::BindGroup>,
}

impl LookupGroup {
    /// The layout for depth maps (`depth`) or colour maps.
    pub(crate) fn new(device: &wgpu::Device, label: &str, depth: bool) -> LookupGroup {
        let stage = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let array = wgpu::TextureViewDimension::D2Array;
        let sampler_of = |name: &str, filter, compare| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(&format!("{label} {name} sampler")),
                mag_filter: filter,
                min_filter: filter,
                compare,
                ..Default::default()
            })
        };
        let (entries, samplers) = if depth {
            let comparison = wgpu::SamplerBindingType::Comparison;
            let less_equal = Some(wgpu::CompareFunction::LessEqual);
            (
                vec![
                    texture(0, stage, wgpu::TextureSampleType::Depth, array),
                    sampler(1, stage, comparison),
                    sampler(2, stage, comparison),
                    storage(3, stage, true),
                    texture(
                        4,
                        stage,
                        wgpu::TextureSampleType::Float { filterable: false },
                        array,
                    ),
                    texture(5, stage, wgpu::TextureSampleType::Depth, array),
                ],
                vec![
                    sampler_of("linear compare", wgpu::FilterMode::Linear, less_equal),
                    sampler_of("nearest compare", wgpu::FilterMode::Nearest, less_equal),
                ],
            )
        } else {
            (
                vec![
                    texture(0, stage, wgpu::TextureSampleType::Uint, array),
                    storage(1, stage, true),
                ],
                Vec::new(),
            )
        };
        LookupGroup {
            label: label.to_string(),
            depth,
            layout: bind_group_layout(device, &format!("{label} lookup layout"), &entries),
            samplers,
            group: None,
        }
    }

    /// The variables of the group, in binding order.
    fn names(&self) -> &'static [&'static str] {
        if self.depth {
            DEPTH_VARIABLES
        } else {
            COLOR_VARIABLES
        }
    }

    /// The group as stages share it, or join it with variables of their own.
    pub(crate) fn shared(&self) -> Joinable<NamedGroup<'_>> {
        Joinable(NamedGroup {
            names: self.names(),
            layout: &self.layout,
            group: self.group.as_ref(),
        })
    }

    /// The group's resources over `maps` and `cameras`, by variable name in binding order.
    pub(crate) fn resources<'r>(
        &'r self,
        maps: &'r MapArray,
        cameras: &'r wgpu::Buffer,
    ) -> Vec<(&'static str, wgpu::BindingResource<'r>)> {
        let view = || wgpu::BindingResource::TextureView(&maps.array_view);
        let values = if self.depth {
            vec![
                view(),
                wgpu::BindingResource::Sampler(&self.samplers[0]),
                wgpu::BindingResource::Sampler(&self.samplers[1]),
                cameras.as_entire_binding(),
                view(),
                view(),
            ]
        } else {
            vec![view(), cameras.as_entire_binding()]
        };
        self.names().iter().copied().zip(values).collect()
    }

    /// Rebuilds the bind group over `maps` and `cameras`.
    pub(crate) fn bind(&mut self, device: &wgpu::Device, maps: &MapArray, cameras: &wgpu::Buffer) {
        let resources: Vec<_> = (self.resources(maps, cameras).into_iter())
            .map(|(_, resource)| resource)
            .collect();
        let label = format!("{} lookup", self.label);
        let group = bind_group(device, &label, &self.layout, &resources);
        self.group = Some(group);
    }
}

#[cfg(test)]
mod tests {
    use zoo_host::gpu::layout::wgsl_struct;
    use zoo_host::kit::reflect::declared_variables;

    #[test]
    fn the_variable_names_are_the_shaders() {
        let library = zoo_host::ShaderLibrary::embedded();
        for (shader, names) in [
            ("shadow-maps/depth_lookup.wgsl", super::DEPTH_VARIABLES),
            ("shadow-maps/color_lookup.wgsl", super::COLOR_VARIABLES),
        ] {
            let text = format!("#import \"{shader}\"\n");
            let (_, module) = library.validate_source("test.wgsl", &text).unwrap();
            assert_eq!(declared_variables(&module, 3), names, "{shader}");
        }
    }

    #[test]
    fn lookup_camera_slots_are_the_depth_pass_stride() {
        let library = zoo_host::ShaderLibrary::embedded();
        // Shared modules are checked through a shader that imports them.
        let source = library
            .compose_source("test.wgsl", "#import \"shadow-maps/depth_lookup.wgsl\"\n")
            .unwrap()
            .source;
        let slot = wgsl_struct(&source, "CameraSlot").unwrap();
        assert_eq!(slot.size as u64, crate::CAMERA_STRIDE);
        assert_eq!(slot.members[0], ("camera".to_string(), 0));
    }
}
