//! The G-buffer: depth-stencil, view depth, normal and albedo, and the pass that fills it.
//!
//! World positions are not stored: each pixel keeps its view-space depth (the distance along
//! the camera's forward axis, as f32 bits in an `R32Uint` target, which every backend can render
//! to) and the position is rebuilt from the ray through the pixel's centre, on the GPU by
//! `load_surface` in `common/gbuffer.wgsl` and on the CPU by [`reconstruct_position`]. That is
//! 4 bytes a pixel instead of 16, within a few ulps of the view depth at any distance. Passes
//! that read the G-buffer do so at full resolution (one pixel of the output per texel).

use glam::{UVec2, Vec3};

use super::frame::{CameraMatrices, FrameBindings};
use super::materials::MaterialBindings;
use super::scene_buffers::SceneBuffers;
use crate::gpu::{GpuContext, PassRecorder, ShaderError, ShaderLibrary};
use crate::scene::Scene;

/// Depth-stencil format shared with techniques that need stencil (planar, shadow volumes).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24PlusStencil8;
/// View-space depth as f32 bits (0 on background).
pub const VIEW_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// World normal (xyz) and shininess / 256 (w).
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// How every G-buffer texture is used: drawn, sampled, copied for readback.
pub const GBUFFER_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);
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
    /// View-space depth bits, from which world positions are rebuilt.
    pub view_depth: wgpu::Texture,
    pub view_depth_view: wgpu::TextureView,
    pub normal: wgpu::Texture,
    pub normal_view: wgpu::TextureView,
    pub albedo: wgpu::Texture,
    pub albedo_view: wgpu::TextureView,
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
}

/// The variables of the G-buffer group as `common/gbuffer.wgsl` declares them (a kit test
/// checks).
pub const GBUFFER_VARIABLES: &[&str] = &["gbuffer_view_depth", "gbuffer_normal", "gbuffer_albedo"];

/// Layout of bind group 1.
pub fn gbuffer_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let texture = |binding, sample_type| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let float = wgpu::TextureSampleType::Float { filterable: false };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gbuffer bind group layout"),
        entries: &[
            texture(0, wgpu::TextureSampleType::Uint),
            texture(1, float),
            texture(2, float),
        ],
    })
}

/// World position of the surface seen at full-resolution `pixel` at view-space `depth` (the
/// mirror of `load_surface` in `common/gbuffer.wgsl`): the camera position plus `depth` times
/// the ray through the pixel's centre scaled to unit view-space depth. Any perspective
/// projection works, off-centre (jittered) ones included.
pub fn reconstruct_position(matrices: &CameraMatrices, pixel: UVec2, depth: f32) -> Vec3 {
    let (size, proj) = (matrices.size.max(UVec2::ONE), matrices.proj);
    let ndc_x = (pixel.x as f32 + 0.5) / size.x as f32 * 2.0 - 1.0;
    let ndc_y = 1.0 - (pixel.y as f32 + 0.5) / size.y as f32 * 2.0;
    // Clip x = p00 x + p20 z with z = -1 on the unit-depth ray, and w = 1.
    let view_ray = Vec3::new(
        (ndc_x + proj.z_axis.x) / proj.x_axis.x,
        (ndc_y + proj.z_axis.y) / proj.y_axis.y,
        -1.0,
    );
    let rotation = glam::Mat3::from_mat4(matrices.view);
    matrices.eye + rotation.transpose() * view_ray * depth
}

fn target(
    device: &wgpu::Device,
    label: &str,
    size: UVec2,
    format: wgpu::TextureFormat,
) -> (wgpu::Texture, wgpu::TextureView) {
    // `render_target` adds the attachment and binding usages.
    crate::gpu::render_target(device, label, size, format, GBUFFER_USAGE)
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
        let (view_depth, view_depth_view) =
            target(device, "gbuffer view depth", size, VIEW_DEPTH_FORMAT);
        let (normal, normal_view) = target(device, "gbuffer normal", size, NORMAL_FORMAT);
        let (albedo, albedo_view) = target(device, "gbuffer albedo", size, ALBEDO_FORMAT);
        let layout = gbuffer_layout(device);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer bind group"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view_depth_view),
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
            view_depth,
            view_depth_view,
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
    /// For double-sided objects (every procedural and OBJ mesh).
    pipeline: wgpu::RenderPipeline,
    /// For single-sided (glTF) materials: back faces culled.
    single_sided: wgpu::RenderPipeline,
}

impl GBufferPass {
    /// Builds the pipeline from `host/gbuffer.wgsl`.
    pub fn new(
        gpu: &GpuContext,
        shaders: &ShaderLibrary,
        frame: &FrameBindings,
        materials: &MaterialBindings,
    ) -> Result<GBufferPass, ShaderError> {
        let device = &gpu.device;
        let module = shaders.create_module(device, "host/gbuffer.wgsl")?;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer pipeline layout"),
            bind_group_layouts: &[Some(&frame.layout), Some(&materials.layout)],
            immediate_size: 0,
        });
        let color = |format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        };
        let pipeline = |label, cull_mode| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &SceneBuffers::VERTEX_LAYOUTS,
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode,
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
                        color(VIEW_DEPTH_FORMAT),
                        color(NORMAL_FORMAT),
                        color(ALBEDO_FORMAT),
                    ],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        Ok(GBufferPass {
            // Open meshes (planes, scanned models) must be visible from both sides.
            pipeline: pipeline("gbuffer pipeline", None),
            single_sided: pipeline("gbuffer single-sided pipeline", Some(wgpu::Face::Back)),
        })
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
            clear(&gbuffer.view_depth_view),
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
        pass.set_bind_group(1, &buffers.materials.bind_group, &[]);
        buffers.draw_objects_where(&mut pass, scene, |_, o| o.double_sided);
        if scene.objects.iter().any(|o| !o.double_sided) {
            pass.set_pipeline(&self.single_sided);
            buffers.draw_objects_where(&mut pass, scene, |_, o| !o.double_sided);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Camera;
    use glam::Vec4Swizzles;

    #[test]
    fn reconstructed_positions_lie_on_the_pixel_ray_at_the_stored_depth() {
        let camera = Camera {
            position: Vec3::new(6.0, 4.8, 7.5),
            target: Vec3::new(-0.5, 1.4, -0.5),
            fov_y: 50f32.to_radians(),
            near: 0.1,
            far: 600.0,
        };
        let size = UVec2::new(320, 200);
        let centred = CameraMatrices::new(&camera, size);
        // A jittered (off-centre) projection, as temporal anti-aliasing would use.
        let mut jittered = centred;
        jittered.proj.z_axis.x += 0.37 * 2.0 / size.x as f32;
        jittered.proj.z_axis.y -= 0.21 * 2.0 / size.y as f32;
        for matrices in [centred, jittered] {
            check_rays(&matrices);
        }
    }

    fn check_rays(matrices: &CameraMatrices) {
        let (view, proj, size) = (matrices.view, matrices.proj, matrices.size);
        for (pixel, depth) in [
            (UVec2::new(0, 0), 1.0),
            (UVec2::new(160, 100), 12.5),
            (UVec2::new(319, 199), 0.2),
            (UVec2::new(37, 151), 480.0),
        ] {
            let p = reconstruct_position(matrices, pixel, depth);
            let view_space = view * p.extend(1.0);
            assert!(
                (-view_space.z - depth).abs() <= 1e-5 * depth,
                "{pixel} {depth}"
            );
            let clip = proj * view_space;
            let ndc = clip.xy() / clip.w;
            let screen = glam::Vec2::new(
                (ndc.x + 1.0) * 0.5 * size.x as f32,
                (1.0 - ndc.y) * 0.5 * size.y as f32,
            );
            let centre = pixel.as_vec2() + 0.5;
            assert!(
                screen.distance(centre) < 1e-3,
                "{pixel}: {screen} vs {centre}"
            );
        }
    }
}
