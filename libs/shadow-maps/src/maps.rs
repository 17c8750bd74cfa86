//! The array textures that hold the atlas pages of every light's shadow maps: depth maps, or
//! colour maps (moments, fluxes) rendered beside a depth scratch.

use zoo_host::GpuContext;
use zoo_host::wgpu;

/// Depth format of the maps.
pub const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Texels of guard band around each cube face (covers bilinear taps across face edges).
pub const CUBE_GUARD: u32 = 2;
/// The two-channel float format for filtered colour maps (moments): `Rg32Float` where the
/// device filters 32-bit floats (`FLOAT32_FILTERABLE`), `Rg16Float` elsewhere.
pub fn filterable_rg_format(device: &wgpu::Device) -> wgpu::TextureFormat {
    if device
        .features()
        .contains(wgpu::Features::FLOAT32_FILTERABLE)
    {
        wgpu::TextureFormat::Rg32Float
    } else {
        wgpu::TextureFormat::Rg16Float
    }
}

/// The four-channel float format for filtered colour maps (higher moments): `Rgba32Float`
/// where the device filters 32-bit floats, `Rgba16Float` elsewhere.
pub fn filterable_rgba_format(device: &wgpu::Device) -> wgpu::TextureFormat {
    if device
        .features()
        .contains(wgpu::Features::FLOAT32_FILTERABLE)
    {
        wgpu::TextureFormat::Rgba32Float
    } else {
        wgpu::TextureFormat::Rgba16Float
    }
}

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
