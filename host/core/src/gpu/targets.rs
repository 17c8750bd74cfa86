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

/// A pipeline that draws the full-screen triangle of `common/fullscreen.wgsl`
/// (`fullscreen_vs`, three vertices, no buffers) with fragment entry `entry` of `module` into
/// one colour `target`. `layout: None` derives the bind group layouts from the shader.
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: Option<&wgpu::PipelineLayout>,
    module: &wgpu::ShaderModule,
    entry: &str,
    target: wgpu::ColorTargetState,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("fullscreen_vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets: &[Some(target)],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A render pass writing only the colour `attachments` (no depth, queries or timestamps).
pub fn color_pass<'a>(
    label: &'a str,
    attachments: &'a [Option<wgpu::RenderPassColorAttachment<'a>>],
) -> wgpu::RenderPassDescriptor<'a> {
    wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: attachments,
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    }
}

/// Layers to allocate for a `width` x `height` array texture of `layers` layers that is viewed
/// as `D2Array`. wgpu's GL backend picks the GL texture target from the size alone (one layer
/// makes a 2D texture, a square multiple of six layers a cube map), and a view of another
/// dimension then fails; there the array gets a spare layer. Other backends get `layers`.
pub fn array_layers(gpu: &crate::GpuContext, width: u32, height: u32, layers: u32) -> u32 {
    if gpu.info.backend != wgpu::Backend::Gl {
        return layers;
    }
    let mut padded = layers.max(2);
    if width == height && padded.is_multiple_of(6) {
        padded += 1;
    }
    padded
}
