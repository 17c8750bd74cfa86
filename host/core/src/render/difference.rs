//! The A/B difference image: two rendered images of the same view compared per pixel.

use glam::UVec2;

use super::lighting::OUTPUT_FORMAT;
use crate::gpu::gpu_struct::round_up;
use crate::gpu::{
    GpuContext, GpuType, ShaderError, ShaderLibrary, gpu_bytes, readback, render_target,
};

crate::gpu_struct! {
    "host/difference_params.wgsl" =>
    /// The uniform of `host/difference.wgsl`.
    #[derive(Debug, Clone, Copy)]
    struct DifferenceParams {
        gain: f32,
        context: f32,
    }
}

/// Renders |B - A| in luminance: red where A is darker (A shadows more), blue where B is
/// darker, amplified by a gain, over a dim copy of A.
pub struct ImageDifference {
    pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    output: Option<(UVec2, wgpu::Texture, wgpu::TextureView)>,
}

impl ImageDifference {
    /// Builds the pipeline from `host/difference.wgsl`.
    pub fn new(gpu: &GpuContext, shaders: &ShaderLibrary) -> Result<ImageDifference, ShaderError> {
        let device = &gpu.device;
        let module = shaders.create_module(device, "host/difference.wgsl")?;
        let pipeline = crate::gpu::fullscreen_pipeline(
            device,
            "A/B difference pipeline",
            None,
            &module,
            "fs_difference",
            OUTPUT_FORMAT.into(),
        );
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("A/B difference params"),
            // A whole 16-byte slot, as a uniform block holds it everywhere.
            size: round_up(DifferenceParams::SIZE, 16) as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(ImageDifference {
            pipeline,
            params,
            output: None,
        })
    }

    /// Compares `a` and `b` (views of two output images of `size`) with `gain` and submits
    /// the work. The result is [`Self::view`].
    pub fn update(
        &mut self,
        gpu: &GpuContext,
        a: &wgpu::TextureView,
        b: &wgpu::TextureView,
        size: UVec2,
        gain: f32,
    ) {
        if self.output.as_ref().is_none_or(|(s, _, _)| *s != size) {
            let (texture, view) = render_target(
                &gpu.device,
                "A/B difference image",
                size,
                OUTPUT_FORMAT,
                wgpu::TextureUsages::COPY_SRC,
            );
            self.output = Some((size, texture, view));
        }
        let (_, _, target) = self.output.as_ref().expect("created above");
        let values = DifferenceParams {
            gain,
            context: 0.25,
        };
        gpu.queue
            .write_buffer(&self.params, 0, &gpu_bytes(&[values]));
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("A/B difference bind group"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(a),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(b),
                },
            ],
        });
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("A/B difference encoder"),
            });
        {
            let attachments = [crate::gpu::color_attachment(
                target,
                wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            )];
            let mut pass =
                encoder.begin_render_pass(&crate::gpu::color_pass("A/B difference", &attachments));
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
    }

    /// The last difference image, if any.
    pub fn view(&self) -> Option<&wgpu::TextureView> {
        self.output.as_ref().map(|(_, _, view)| view)
    }

    /// Reads the last difference image back (sRGB RGBA8).
    pub fn read(&self, gpu: &GpuContext) -> Option<image::RgbaImage> {
        let (size, texture, _) = self.output.as_ref()?;
        let bytes = readback::read_texture(gpu, texture, 0, wgpu::TextureAspect::All, 4);
        image::RgbaImage::from_raw(size.x, size.y, bytes)
    }
}
