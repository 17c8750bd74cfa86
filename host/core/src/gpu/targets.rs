//! Small constructors for render targets and pass attachments.

use glam::UVec2;

/// A single-layer 2D texture of `size` usable as a render attachment and for sampling (plus
/// `extra` usages), and its default view.
pub fn render_target(
    device: &wgpu::Device,
    label: &str,
    size: UVec2,
    format: wgpu::TextureFormat,
    extra: wgpu::TextureUsages,
) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size.x,
            height: size.y,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | extra,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some(&format!("{label} view")),
        ..Default::default()
    });
    (texture, view)
}

/// A colour attachment that loads (or clears) `view` and stores the result.
pub fn color_attachment(
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load,
            store: wgpu::StoreOp::Store,
        },
    })
}

/// A depth-stencil attachment with read-only depth and a stored stencil (loaded or cleared),
/// as stencil techniques use the G-buffer's depth-stencil.
pub fn stencil_attachment(
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<u32>,
) -> Option<wgpu::RenderPassDepthStencilAttachment<'_>> {
    Some(wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: None,
        stencil_ops: Some(wgpu::Operations {
            load,
            store: wgpu::StoreOp::Store,
        }),
    })
}

/// Clears to `color` when `first` (the first pass writing a target this frame), else loads.
pub fn clear_first(first: bool, color: wgpu::Color) -> wgpu::LoadOp<wgpu::Color> {
    if first {
        wgpu::LoadOp::Clear(color)
    } else {
        wgpu::LoadOp::Load
    }
}
