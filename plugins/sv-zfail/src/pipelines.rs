//! The technique's GPU objects: the volume generator and pipelines, the counter ring and the
//! debug targets.

use zoo_host::gpu::readback::ReadbackRing;
use zoo_host::render::visibility::VISIBILITY_FORMAT;
use zoo_host::{RenderContext, TechniqueError, wgpu};
use zoo_shadow_volumes::{
    ARGS_BYTES, VOLUME_VERTEX_LAYOUT, VolumeGenerator, stencil_state, volume_depth_stencil,
    volume_primitive,
};

use crate::SvParams;

pub(crate) const SLOT: u64 = 256;
pub(crate) const COUNTS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Uint;
pub(crate) const OVERLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Stencil levels the count view distinguishes, shown as ids 1..=10: counts 1..=8, then 255 and
/// 254 (-1 and -2 wrapped); any other non-zero count is id 11.
pub(crate) const COUNT_LEVELS: [u32; 10] = [1, 2, 3, 4, 5, 6, 7, 8, 255, 254];

/// The compute generator and every render pipeline of the technique.
pub(crate) struct Pipelines {
    pub(crate) generator: VolumeGenerator,
    pub(crate) volume: wgpu::RenderPipeline,
    pub(crate) resolve: wgpu::RenderPipeline,
    pub(crate) overlay: wgpu::RenderPipeline,
    pub(crate) count_equal: wgpu::RenderPipeline,
    pub(crate) count_any: wgpu::RenderPipeline,
    pub(crate) count_layout: wgpu::BindGroupLayout,
}

/// Buffers that live as long as the lights do.
pub(crate) struct Buffers {
    /// Draw arguments and silhouette counters per light, read back a frame or two late.
    pub(crate) stats: std::sync::Mutex<ReadbackRing>,
    pub(crate) levels_bind_group: wgpu::BindGroup,
}

/// Targets of the debug views.
pub(crate) struct DebugTargets {
    pub(crate) counts: (wgpu::Texture, wgpu::TextureView),
    pub(crate) overlay: (wgpu::Texture, wgpu::TextureView),
}

impl Pipelines {
    /// Builds every pipeline; the volume pass takes its biases and counting from `params`.
    pub(crate) fn new(
        ctx: &RenderContext<'_>,
        params: &SvParams,
    ) -> Result<Pipelines, TechniqueError> {
        let device = &ctx.gpu.device;
        let stencil_module = ctx.shaders.create_module(device, "sv-zfail/stencil.wgsl")?;
        let generator = VolumeGenerator::new(ctx, "sv-zfail")?;

        let count_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sv-zfail count level layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(4),
                },
                count: None,
            }],
        });
        let frame_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("sv-zfail render pipeline layout"),
            bind_group_layouts: &[Some(&ctx.frame.layout)],
            immediate_size: 0,
        });
        let count_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sv-zfail count pipeline layout"),
                bind_group_layouts: &[Some(&ctx.frame.layout), Some(&count_layout)],
                immediate_size: 0,
            });

        let keep = wgpu::StencilOperation::Keep;
        let face = |compare, pass_op, depth_fail_op| wgpu::StencilFaceState {
            compare,
            fail_op: keep,
            depth_fail_op,
            pass_op,
        };
        let target = |format, write_mask, blend| {
            Some(wgpu::ColorTargetState {
                format,
                blend,
                write_mask,
            })
        };
        let volume_primitive = volume_primitive();
        let bias = wgpu::DepthBiasState {
            constant: params.depth_bias as i32,
            slope_scale: params.slope_bias,
            clamp: 0.0,
        };
        let volume = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("sv-zfail volume stencil pipeline"),
            layout: Some(&frame_layout),
            vertex: wgpu::VertexState {
                module: &stencil_module,
                entry_point: Some("vs_volume"),
                compilation_options: Default::default(),
                buffers: &[Some(VOLUME_VERTEX_LAYOUT)],
            },
            primitive: volume_primitive,
            depth_stencil: Some(volume_depth_stencil(params.counting, bias)),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &stencil_module,
                entry_point: Some("fs_volume"),
                compilation_options: Default::default(),
                targets: &[target(VISIBILITY_FORMAT, wgpu::ColorWrites::empty(), None)],
            }),
            multiview_mask: None,
            cache: None,
        });
        let test = |compare| face(compare, keep, keep);
        let fullscreen = |label: &str,
                          layout: &wgpu::PipelineLayout,
                          entry: &str,
                          compare,
                          targets: &[Option<wgpu::ColorTargetState>]| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &stencil_module,
                    entry_point: Some("fullscreen_vs"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: Some(stencil_state(
                    wgpu::CompareFunction::Always,
                    test(compare),
                    test(compare),
                    Default::default(),
                )),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &stencil_module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let resolve = fullscreen(
            "sv-zfail resolve pipeline",
            &frame_layout,
            "fs_shadowed",
            wgpu::CompareFunction::NotEqual,
            &[Some(zoo_host::kit::slot_target())],
        );
        let debug_targets = |count_writes, overlay_writes, blend| {
            [
                target(COUNTS_FORMAT, count_writes, None),
                target(OVERLAY_FORMAT, overlay_writes, blend),
            ]
        };
        let count_targets = debug_targets(wgpu::ColorWrites::ALL, wgpu::ColorWrites::empty(), None);
        let count_equal = fullscreen(
            "sv-zfail stencil count pipeline (equal)",
            &count_pipeline_layout,
            "fs_count",
            wgpu::CompareFunction::Equal,
            &count_targets,
        );
        let count_any = fullscreen(
            "sv-zfail stencil count pipeline (any)",
            &count_pipeline_layout,
            "fs_count",
            wgpu::CompareFunction::NotEqual,
            &count_targets,
        );
        let additive = wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::REPLACE,
        };
        let overlay = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("sv-zfail volume overlay pipeline"),
            layout: Some(&frame_layout),
            vertex: wgpu::VertexState {
                module: &stencil_module,
                entry_point: Some("vs_volume"),
                compilation_options: Default::default(),
                buffers: &[Some(VOLUME_VERTEX_LAYOUT)],
            },
            primitive: volume_primitive,
            depth_stencil: Some(stencil_state(
                wgpu::CompareFunction::Always,
                test(wgpu::CompareFunction::Always),
                test(wgpu::CompareFunction::Always),
                Default::default(),
            )),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &stencil_module,
                entry_point: Some("fs_volume_debug"),
                compilation_options: Default::default(),
                targets: &debug_targets(
                    wgpu::ColorWrites::empty(),
                    wgpu::ColorWrites::ALL,
                    Some(additive),
                ),
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(Pipelines {
            generator,
            volume,
            resolve,
            overlay,
            count_equal,
            count_any,
            count_layout,
        })
    }
}

impl Buffers {
    /// The counter ring for the current lights and the count levels for the debug view.
    pub(crate) fn new(ctx: &RenderContext<'_>, pipelines: &Pipelines) -> Buffers {
        let device = &ctx.gpu.device;
        let stats = std::sync::Mutex::new(ReadbackRing::new(
            device,
            "sv-zfail workload counters",
            ctx.lights.len() as u64 * ARGS_BYTES,
            3,
        ));
        let level_data: Vec<u32> = std::iter::once(11)
            .chain(COUNT_LEVELS.iter().enumerate().map(|(i, _)| i as u32 + 1))
            .flat_map(|value| std::iter::once(value).chain(std::iter::repeat_n(0, 63)))
            .collect();
        let levels = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("sv-zfail count levels"),
                contents: bytemuck::cast_slice(&level_data),
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        let levels_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sv-zfail count levels bind group"),
            layout: &pipelines.count_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &levels,
                    offset: 0,
                    size: wgpu::BufferSize::new(4),
                }),
            }],
        });
        Buffers {
            stats,
            levels_bind_group,
        }
    }
}

impl DebugTargets {
    /// Stencil counts and the volume overlay at `size`.
    pub(crate) fn new(device: &wgpu::Device, size: zoo_host::glam::UVec2) -> DebugTargets {
        let make = |label: &str, format| {
            zoo_host::gpu::render_target(device, label, size, format, wgpu::TextureUsages::empty())
        };
        DebugTargets {
            counts: make("sv-zfail stencil counts", COUNTS_FORMAT),
            overlay: make("sv-zfail volumes overlay", OVERLAY_FORMAT),
        }
    }
}
