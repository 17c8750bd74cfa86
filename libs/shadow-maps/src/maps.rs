//! The array textures that hold the atlas pages of every light's shadow maps: depth maps, or
//! colour maps (moments, fluxes) rendered beside a depth scratch.

use zoo_host::GpuContext;
use zoo_host::wgpu;

/// Depth format of the maps.
pub const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Texels of guard band around each cube face (covers bilinear taps across face edges).
pub const CUBE_GUARD: u32 = 2;
/// The two-channel format of colour maps (moments): 32-bit floats stored as their bits, on
/// every device. Not every device renders into or filters 32-bit float textures (GL without
/// `EXT_color_buffer_float`, WebGPU without `float32-filterable`), while every one renders
/// 32-bit integers; the passes write `bitcast<u32>` of their floats and lookups filter the
/// texels in the shader (`shaders/shadow-maps/color_lookup.wgsl`), so every backend holds and
/// filters the same moments.
pub const MOMENTS_RG_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
/// The four-channel format of colour maps (higher moments), stored like
/// [`MOMENTS_RG_FORMAT`].
pub const MOMENTS_RGBA_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// `layers` square maps (atlas pages) of `resolution` texels in one array texture (depth or
/// colour).
pub struct MapArray {
    pub resolution: u32,
    /// Layers in use (the texture may hold a spare one on GL, see
    /// `zoo_host::gpu::array_layers`).
    pub layers: u32,
    pub texture: wgpu::Texture,
    /// One 2D view per layer, for attachments and debug views.
    pub layer_views: Vec<wgpu::TextureView>,
    /// All layers in use, for lookups.
    pub array_view: wgpu::TextureView,
}

impl MapArray {
    /// Creates a depth array ([`MAP_FORMAT`]; `label` names the texture and its views).
    pub fn new(gpu: &GpuContext, label: &str, resolution: u32, layers: u32) -> MapArray {
        Self::with_format(gpu, label, resolution, layers, MAP_FORMAT)
    }

    /// Creates an array of `format` (a depth format, or a colour format for moment or flux
    /// maps), usable as render attachment and sampled texture.
    pub fn with_format(
        gpu: &GpuContext,
        label: &str,
        resolution: u32,
        layers: u32,
        format: wgpu::TextureFormat,
    ) -> MapArray {
        let allocated = zoo_host::gpu::array_layers(gpu, resolution, resolution, layers);
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: resolution,
                height: resolution,
                depth_or_array_layers: allocated,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let layer_views = (0..layers)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("{label} layer {layer}")),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some(&format!("{label} (array)")),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            array_layer_count: Some(layers),
            ..Default::default()
        });
        MapArray {
            resolution,
            layers,
            texture,
            layer_views,
            array_view,
        }
    }
}
