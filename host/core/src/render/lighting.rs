//! The deferred lighting pass, identical for every technique.

use super::frame::FrameBindings;
use super::gbuffer::GBuffer;
use super::visibility::{IndirectTarget, TransmittanceTargets, VisibilityTargets};
use crate::gpu::{GpuContext, PassRecorder, ShaderError, ShaderLibrary};

/// Format of the final image.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// How the output image is used: the lighting and debug passes draw it, the difference pass
/// and the viewer sample it, readback copies it.
pub const OUTPUT_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

/// Pipeline and layout of the lighting pass.
pub struct LightingPass {
    pipeline: wgpu::RenderPipeline,
    inputs_layout: wgpu::BindGroupLayout,
}

impl LightingPass {
    /// Builds the pipeline from `host/lighting.wgsl`.
    pub fn new(
        gpu: &GpuContext,
        shaders: &ShaderLibrary,
        frame: &FrameBindings,
        gbuffer: &GBuffer,
    ) -> Result<LightingPass, ShaderError> {
        let device = &gpu.device;
        let module = shaders.create_module(device, "host/lighting.wgsl")?;
        let texture = |binding, view_dimension| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension,
                multisampled: false,
            },
            count: None,
        };
        let inputs_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lighting inputs layout"),
            entries: &[
                texture(0, wgpu::TextureViewDimension::D2Array),
                texture(1, wgpu::TextureViewDimension::D2),
                texture(2, wgpu::TextureViewDimension::D2Array),
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lighting pipeline layout"),
            bind_group_layouts: &[
                Some(&frame.layout),
                Some(&gbuffer.layout),
                Some(&inputs_layout),
            ],
            immediate_size: 0,
        });
        let pipeline = crate::gpu::fullscreen_pipeline(
            device,
            "lighting pipeline",
            Some(&layout),
            &module,
            "fs_main",
            OUTPUT_FORMAT.into(),
        );
        Ok(LightingPass {
            pipeline,
            inputs_layout,
        })
    }

    /// Bind group of the visibility and indirect inputs.
    pub fn inputs(
        &self,
        gpu: &GpuContext,
        visibility: &VisibilityTargets,
        indirect: &IndirectTarget,
        transmittance: &TransmittanceTargets,
    ) -> wgpu::BindGroup {
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lighting inputs"),
            layout: &self.inputs_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&visibility.array_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&indirect.view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&transmittance.array_view),
                },
            ],
        })
    }

    /// Records the lighting pass into `output`.
    pub fn record(
        &self,
        recorder: &mut PassRecorder<'_>,
        output: &wgpu::TextureView,
        frame: &FrameBindings,
        gbuffer: &GBuffer,
        inputs: &wgpu::BindGroup,
    ) {
        let attachments = [crate::gpu::color_attachment(
            output,
            wgpu::LoadOp::Clear(wgpu::Color::BLACK),
        )];
        let mut pass = recorder.render_pass(&crate::gpu::color_pass("Lighting", &attachments));
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &frame.bind_group, &[]);
        pass.set_bind_group(1, &gbuffer.bind_group, &[]);
        pass.set_bind_group(2, inputs, &[]);
        pass.draw(0..3, 0..1);
    }
}
