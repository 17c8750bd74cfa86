//! The G-buffer: depth-stencil, world position, normal and albedo, and the pass that fills it.

use glam::UVec2;

use super::frame::FrameBindings;
use super::scene_buffers::{SceneBuffers, Vertex};
use crate::gpu::{GpuContext, PassRecorder, ShaderError, ShaderLibrary};
use crate::scene::Scene;

/// Depth-stencil format shared with techniques that need stencil (planar, shadow volumes).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24PlusStencil8;
/// World position (w = 1 on geometry, 0 on background).
pub const POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// World normal (xyz) and shininess / 256 (w).
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Albedo (rgb) and specular strength (a).
pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// G-buffer textures and bind group 1 (`common/gbuffer.wgsl`).
pub struct GBuffer {
    pub size: UVec2,
    pub depth: wgpu::Texture,
    /// Depth and stencil, for attachments.
    pub depth_view: wgpu::TextureView,
    /// Depth aspect only, for sampling.
    pub depth_sample_view: wgpu::TextureView,
    pub position: wgpu::Texture,
    pub position_view: wgpu::TextureView,
    pub normal: wgpu::Texture,
    pub normal_view: wgpu::TextureView,
    pub albedo: wgpu::Texture,
    pub albedo_view: wgpu::TextureView,
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
}

/// Layout of bind group 1.
pub fn gbuffer_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gbuffer bind group layout"),
        entries: &[texture(0), texture(1), texture(2)],
    })
}

fn target(
    device: &wgpu::Device,
    label: &str,
    size: UVec2,
    format: wgpu::TextureFormat,
) -> (wgpu::Texture, wgpu::TextureView) {
    crate::gpu::render_target(device, label, size, format, wgpu::TextureUsages::COPY_SRC)
}

impl GBuffer {
    /// Creates the textures at `size`.
    pub fn new(gpu: &GpuContext, size: UVec2) -> GBuffer {
        let device = &gpu.device;
        let (depth, depth_view) = target(device, "gbuffer depth-stencil", size, DEPTH_FORMAT);
        let depth_sample_view = depth.create_view(&wgpu::TextureViewDescriptor {
            label: Some("gbuffer depth (sampled)"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        let (position, position_view) = target(device, "gbuffer position", size, POSITION_FORMAT);
        let (normal, normal_view) = target(device, "gbuffer normal", size, NORMAL_FORMAT);
        let (albedo, albedo_view) = target(device, "gbuffer albedo", size, ALBEDO_FORMAT);
        let layout = gbuffer_layout(device);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer bind group"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&position_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&normal_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&albedo_view),
                },
            ],
        });
        GBuffer {
            size,
            depth,
            depth_view,
            depth_sample_view,
            position,
            position_view,
            normal,
            normal_view,
            albedo,
            albedo_view,
            layout,
            bind_group,
        }
    }
}

/// The pipeline that fills the G-buffer.
pub struct GBufferPass {
    pipeline: wgpu::RenderPipeline,
}

impl GBufferPass {
    /// Builds the pipeline from `host/gbuffer.wgsl`.
    pub fn new(
        gpu: &GpuContext,
        shaders: &ShaderLibrary,
        frame: &FrameBindings,
    ) -> Result<GBufferPass, ShaderError> {
        let device = &gpu.device;
        let module = shaders.create_module(device, "host/gbuffer.wgsl")?;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer pipeline layout"),
            bind_group_layouts: &[Some(&frame.layout)],
            immediate_size: 0,
        });
        let color = |format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("gbuffer pipeline"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(Vertex::LAYOUT)],
            },
            primitive: wgpu::PrimitiveState {
                // Open meshes (planes, scanned models) must be visible from both sides.
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[
                    color(POSITION_FORMAT),
                    color(NORMAL_FORMAT),
                    color(ALBEDO_FORMAT),
                ],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(GBufferPass { pipeline })
    }

    /// Records the G-buffer pass.
    pub fn record(
        &self,
        recorder: &mut PassRecorder<'_>,
        gbuffer: &GBuffer,
        frame: &FrameBindings,
        scene: &Scene,
        buffers: &SceneBuffers,
    ) {
        let clear = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let attachments = [
            clear(&gbuffer.position_view),
            clear(&gbuffer.normal_view),
            clear(&gbuffer.albedo_view),
        ];
        let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some("G-buffer"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &gbuffer.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0),
                    store: wgpu::StoreOp::Store,
                }),
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &frame.bind_group, &[]);
        buffers.draw_objects(&mut pass, scene, false);
    }
}
