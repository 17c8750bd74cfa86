//! Shows a G-buffer channel, a visibility slot or a technique resource instead of the final image.

use crate::gpu::gpu_struct::round_up;
use crate::gpu::{GpuContext, GpuType, PassRecorder, ShaderError, ShaderLibrary, gpu_bytes};
use crate::technique::{ViewMapping, VolumeAxis, VolumeSlice};

crate::gpu_struct! {
    "host/view_params.wgsl" =>
    /// The uniform of `host/debug_view.wgsl`.
    #[derive(Debug, Clone, Copy)]
    struct ViewParams {
        /// 0 colour, 1 single channel, 2 depth (raw), 3 depth linearised with near/far,
        /// 4 integer, 5 single channel of float bits.
        mode: u32,
        channel: u32,
        min_value: f32,
        max_value: f32,
        near: f32,
        far: f32,
        /// Alpha of the output: 1 full screen, less when blended over the final image.
        opacity: f32,
        /// 3D sources: the axis across which the slice is taken (0 x, 1 y, 2 z) and its texel.
        slice_axis: u32,
        slice_index: u32,
    }
}

/// The sampled type of the texture being shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceKind {
    Float,
    Depth,
    Uint,
}

/// A texture to show and how.
pub struct DebugSource<'a> {
    pub view: &'a wgpu::TextureView,
    pub mapping: ViewMapping,
    /// Linearise perspective depth with these (near, far) planes.
    pub linearize: Option<(f32, f32)>,
    /// For a 3D view: the slice to show.
    pub slice: Option<VolumeSlice>,
}

/// Pipelines of the debug view, one per source kind.
pub struct DebugViewPass {
    float: wgpu::RenderPipeline,
    depth: wgpu::RenderPipeline,
    uint: wgpu::RenderPipeline,
    volume: wgpu::RenderPipeline,
    params: wgpu::Buffer,
}

/// Format the debug view writes: the output image's. The shader decodes sRGB first, so a
/// full-screen view stores its values as bytes; an overlay blends with the final image in
/// linear light (the blend of an sRGB target), as the image's own colours would.
pub const DEBUG_TARGET_FORMAT: wgpu::TextureFormat = super::lighting::OUTPUT_FORMAT;

impl DebugViewPass {
    /// Builds the pipelines from `host/debug_view.wgsl`.
    pub fn new(gpu: &GpuContext, shaders: &ShaderLibrary) -> Result<DebugViewPass, ShaderError> {
        let device = &gpu.device;
        let module = shaders.create_module(device, "host/debug_view.wgsl")?;
        // Alpha carries the opacity: 1 for a full-screen view, less for an overlay.
        let target = wgpu::ColorTargetState {
            format: DEBUG_TARGET_FORMAT,
            blend: Some(wgpu::BlendState::ALPHA_BLENDING),
            write_mask: wgpu::ColorWrites::COLOR,
        };
        let pipeline = |entry: &str, layout: Option<&wgpu::PipelineLayout>| {
            crate::gpu::fullscreen_pipeline(
                device,
                &format!("debug view pipeline ({entry})"),
                layout,
                &module,
                entry,
                target.clone(),
            )
        };
        // Depth is bound as unfilterable float, which a derived layout would not choose.
        let depth_group = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("debug view depth bind group layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let depth_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("debug view depth pipeline layout"),
            bind_group_layouts: &[Some(&depth_group)],
            immediate_size: 0,
        });
        Ok(DebugViewPass {
            float: pipeline("fs_float", None),
            depth: pipeline("fs_depth", Some(&depth_layout)),
            uint: pipeline("fs_uint", None),
            volume: pipeline("fs_volume", None),
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("debug view params"),
                // Whole 16-byte slots, as a uniform block holds it everywhere.
                size: round_up(ViewParams::SIZE, 16) as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
        })
    }

    /// Records a pass that draws `source` into `target` (the output image): full-screen when
    /// `overlay_opacity` is `None`, otherwise blended over what `target` holds.
    pub fn record(
        &self,
        gpu: &GpuContext,
        recorder: &mut PassRecorder<'_>,
        target: &wgpu::TextureView,
        source: &DebugSource<'_>,
        overlay_opacity: Option<f32>,
    ) {
        let (kind, params) = match source.mapping {
            ViewMapping::Color { min, max } => (SourceKind::Float, (0, 0, min, max)),
            ViewMapping::Channel { channel, min, max } => {
                (SourceKind::Float, (1, channel.min(3), min, max))
            }
            ViewMapping::Depth { min, max } => (
                SourceKind::Depth,
                (if source.linearize.is_some() { 3 } else { 2 }, 0, min, max),
            ),
            ViewMapping::Integer => (SourceKind::Uint, (4, 0, 0.0, 1.0)),
            ViewMapping::FloatBits { channel, min, max } => {
                (SourceKind::Uint, (5, channel.min(3), min, max))
            }
        };
        let (near, far) = source.linearize.unwrap_or((0.0, 1.0));
        let (slice_axis, slice_index) = source.slice.map_or((0, 0), |slice| {
            let axis = match slice.axis {
                VolumeAxis::X => 0,
                VolumeAxis::Y => 1,
                VolumeAxis::Z => 2,
            };
            (axis, slice.index)
        });
        let values = ViewParams {
            mode: params.0,
            channel: params.1,
            min_value: params.2,
            max_value: params.3,
            near,
            far,
            opacity: overlay_opacity.unwrap_or(1.0).clamp(0.0, 1.0),
            slice_axis,
            slice_index,
        };
        gpu.queue
            .write_buffer(&self.params, 0, &gpu_bytes(&[values]));
        let (pipeline, binding) = match (kind, source.slice) {
            (SourceKind::Float, Some(_)) => (&self.volume, 4),
            (SourceKind::Float, None) => (&self.float, 1),
            (SourceKind::Depth, _) => (&self.depth, 2),
            (SourceKind::Uint, _) => (&self.uint, 3),
        };
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("debug view bind group"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding,
                    resource: wgpu::BindingResource::TextureView(source.view),
                },
            ],
        });
        let (label, load) = match overlay_opacity {
            None => ("Debug view", wgpu::LoadOp::Clear(wgpu::Color::BLACK)),
            Some(_) => ("Debug overlay", wgpu::LoadOp::Load),
        };
        let attachments = [crate::gpu::color_attachment(target, load)];
        let mut pass = recorder.render_pass(&crate::gpu::color_pass(label, &attachments));
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
