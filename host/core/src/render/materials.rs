//! The scene's materials on the GPU (`common/materials.wgsl`, bind group 1 of the passes that
//! draw the scene's geometry: the G-buffer and shadow-map depth passes): each object's texture
//! layers and alpha cutoff, the textures as one mipmapped sRGB array, and a repeating sampler.

use wgpu::util::DeviceExt;

use crate::gpu::{GpuContext, gpu_bytes};
use crate::kit::{bind_group, bind_group_layout, sampler, storage, texture};
use crate::scene::{Scene, TextureUse};

crate::gpu_struct! {
    "common/object_material.wgsl" =>
    /// An object's record in `common/materials.wgsl`: its texture layers (-1: none) and the
    /// coverage below which its mask makes a hole.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct GpuObjectMaterial {
        pub albedo_layer: i32,
        pub mask_layer: i32,
        pub alpha_cutoff: f32,
    }
}

/// The variables of the materials group as `common/materials.wgsl` declares them (a kit test
/// checks).
pub const MATERIAL_VARIABLES: &[&str] =
    &["object_materials", "material_textures", "material_sampler"];

/// The materials' bind group and its layout, built once per scene.
pub struct MaterialBindings {
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    /// The texture array (for passes that bind it in a group of their own).
    pub textures: wgpu::TextureView,
    /// The repeating, linearly filtering sampler of alpha tests and albedo.
    pub sampler: wgpu::Sampler,
}

impl MaterialBindings {
    /// Uploads `scene`'s textures (every mip level) and object materials.
    pub fn new(gpu: &GpuContext, scene: &Scene) -> MaterialBindings {
        let device = &gpu.device;
        // Compute too: ddgi's probe rays read the albedo of what they hit.
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let layout = bind_group_layout(
            device,
            "materials layout",
            &[
                storage(0, stages, true),
                texture(
                    1,
                    stages,
                    wgpu::TextureSampleType::Float { filterable: true },
                    wgpu::TextureViewDimension::D2Array,
                ),
                sampler(2, stages, wgpu::SamplerBindingType::Filtering),
            ],
        );
        let records: Vec<GpuObjectMaterial> = scene
            .objects
            .iter()
            .map(|o| GpuObjectMaterial {
                albedo_layer: o.albedo_texture.map_or(-1, |l| l as i32),
                mask_layer: o.alpha_mask.map_or(-1, |m| m.layer as i32),
                alpha_cutoff: o.alpha_mask.map_or(0.0, |m| m.cutoff),
            })
            .collect();
        let records = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("object materials"),
            contents: &gpu_bytes(&records),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let view = texture_array(gpu, scene).create_view(&wgpu::TextureViewDescriptor {
            label: Some("material textures view"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("material sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let bind_group = bind_group(
            device,
            "materials bind group",
            &layout,
            &[
                records.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
                wgpu::BindingResource::Sampler(&sampler),
            ],
        );
        MaterialBindings {
            layout,
            bind_group,
            textures: view,
            sampler,
        }
    }
}

/// The scene's texture layers with their mip chains (a white 1² layer when there are none; two
/// layers at least, so that the view is an array on every backend).
fn texture_array(gpu: &GpuContext, scene: &Scene) -> wgpu::Texture {
    let textures = &scene.textures;
    let size = textures.size.max(1);
    let layers: Vec<(Vec<u8>, TextureUse)> = if textures.layers.is_empty() {
        vec![(vec![255; 4], TextureUse::Albedo)]
    } else {
        (textures.layers.iter())
            .map(|l| (l.rgba.clone(), l.usage))
            .collect()
    };
    let layer_count = layers.len().max(2) as u32;
    let levels = size.ilog2() + 1;
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("material textures"),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: layer_count,
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (layer, (rgba, usage)) in layers.into_iter().enumerate() {
        let mut level = rgba;
        for mip in 0..levels {
            let side = (size >> mip).max(1);
            gpu.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: mip,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: layer as u32,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                &level,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(side * 4),
                    rows_per_image: Some(side),
                },
                wgpu::Extent3d {
                    width: side,
                    height: side,
                    depth_or_array_layers: 1,
                },
            );
            if side > 1 {
                level = half_size(&level, side, usage);
            }
        }
    }
    texture
}

/// The next mip level of a `side`² RGBA8 level: each texel the mean of four, colour averaged
/// in linear light (the layers are sRGB-encoded) and alpha as stored.
fn half_size(level: &[u8], side: u32, usage: TextureUse) -> Vec<u8> {
    let half = side / 2;
    let decode = |c: u8| crate::scene::shading::srgb_to_linear(f32::from(c) / 255.0);
    let encode = |c: f32| (crate::scene::shading::linear_to_srgb(c) * 255.0).round() as u8;
    let mut out = Vec::with_capacity((half * half * 4) as usize);
    for y in 0..half {
        for x in 0..half {
            let texel = |dx: u32, dy: u32, c: usize| {
                level[(((2 * y + dy) * side + 2 * x + dx) * 4) as usize + c]
            };
            let quad = [(0, 0), (1, 0), (0, 1), (1, 1)];
            for c in 0..4 {
                let linear = c == 3 || usage == TextureUse::Mask;
                let mean = quad
                    .iter()
                    .map(|&(dx, dy)| {
                        let v = texel(dx, dy, c);
                        if linear {
                            f32::from(v) / 255.0
                        } else {
                            decode(v)
                        }
                    })
                    .sum::<f32>()
                    / 4.0;
                out.push(if linear {
                    (mean * 255.0).round() as u8
                } else {
                    encode(mean)
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mips_average_colour_in_linear_light_and_alpha_as_stored() {
        // Black and white texels in a 2² level: the mean of linear 0 and 1 is 0.5, sRGB 188.
        let level = [
            [0, 0, 0, 0],
            [255, 255, 255, 255],
            [0, 0, 0, 0],
            [255, 255, 255, 255],
        ]
        .concat();
        assert_eq!(
            half_size(&level, 2, TextureUse::Albedo),
            [188, 188, 188, 128]
        );
        assert_eq!(half_size(&level, 2, TextureUse::Mask), [128, 128, 128, 128]);
    }
}
