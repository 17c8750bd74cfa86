//! Terse bind group layout entries and pipeline layouts with the host's groups first.

use crate::technique::RenderContext;

/// A uniform buffer at `binding` (no dynamic offset).
pub fn uniform(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    buffer(binding, visibility, wgpu::BufferBindingType::Uniform)
}

/// A storage buffer at `binding`.
pub fn storage(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    buffer(
        binding,
        visibility,
        wgpu::BufferBindingType::Storage { read_only },
    )
}

fn buffer(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A sampled texture at `binding`.
pub fn texture(
    binding: u32,
    visibility: wgpu::ShaderStages,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

/// A sampler at `binding`.
pub fn sampler(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::SamplerBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Sampler(ty),
        count: None,
    }
}

/// A bind group of `layout` with `resources` at bindings 0, 1, 2, ...
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
        .iter()
        .enumerate()
        .map(|(binding, resource)| wgpu::BindGroupEntry {
            binding: binding as u32,
            resource: resource.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A bind group layout of `entries` (from [`uniform`], [`storage`], [`texture`], [`sampler`]).
pub fn bind_group_layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries,
    })
}

/// A pipeline layout of the frame (group 0) and G-buffer (group 1) layouts followed by a
/// technique's own `groups` (2, 3, ...).
pub fn pipeline_layout(
    ctx: &RenderContext<'_>,
    label: &str,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::PipelineLayout {
    let mut layouts = vec![Some(&ctx.frame.layout), Some(&ctx.gbuffer.layout)];
    layouts.extend(groups.iter().map(|g| Some(*g)));
    ctx.gpu
        .device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        })
}

/// A full-screen pipeline (`common/fullscreen.wgsl`'s vertex stage, fragment `entry` of
/// `module`) that writes visibility slots (see [`super::slot`]), with the host's groups and
/// then `groups`.
pub fn slot_fullscreen_pipeline(
    ctx: &RenderContext<'_>,
    label: &str,
    module: &wgpu::ShaderModule,
    entry: &str,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::RenderPipeline {
    SlotPipeline {
        label,
        module,
        entry,
        groups,
        more_targets: &[],
        depth_stencil: None,
    }
    .build(ctx)
}

/// Two versions of `pipeline` (its `more_targets` ignored) whose fragment also writes
/// `diagnostics` targets (locations 1, 2, ...): `[0]` leaves them untouched, `[1]` writes them,
/// for the light a debug view shows.
pub fn diagnostics_pipelines(
    ctx: &RenderContext<'_>,
    pipeline: SlotPipeline<'_>,
    diagnostics: &[wgpu::TextureFormat],
) -> [wgpu::RenderPipeline; 2] {
    [wgpu::ColorWrites::empty(), wgpu::ColorWrites::ALL].map(|write_mask| {
        let targets: Vec<_> = diagnostics
            .iter()
            .map(|&format| {
                Some(wgpu::ColorTargetState {
                    format,
                    blend: None,
                    write_mask,
                })
            })
            .collect();
        let label = format!(
            "{} (diagnostics {})",
            pipeline.label,
            !write_mask.is_empty()
        );
        SlotPipeline {
            label: &label,
            module: pipeline.module,
            entry: pipeline.entry,
            groups: pipeline.groups,
            more_targets: &targets,
            depth_stencil: pipeline.depth_stencil.clone(),
        }
        .build(ctx)
    })
}

/// A full-screen pipeline that writes visibility slots, in full: the host's groups and then
/// `groups`, colour targets after the slot, and a depth-stencil state (for passes that write
/// depth or test the stencil of a depth-stencil attachment).
pub struct SlotPipeline<'a> {
    pub label: &'a str,
    /// Holds `common/fullscreen.wgsl`'s vertex stage and fragment `entry`.
    pub module: &'a wgpu::ShaderModule,
    pub entry: &'a str,
    pub groups: &'a [&'a wgpu::BindGroupLayout],
    pub more_targets: &'a [Option<wgpu::ColorTargetState>],
    pub depth_stencil: Option<wgpu::DepthStencilState>,
}

impl SlotPipeline<'_> {
    /// Creates the pipeline.
    pub fn build(&self, ctx: &RenderContext<'_>) -> wgpu::RenderPipeline {
        let layout = pipeline_layout(ctx, &format!("{} layout", self.label), self.groups);
        let mut targets = vec![Some(super::slot_target())];
        targets.extend_from_slice(self.more_targets);
        ctx.gpu
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(self.label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: self.module,
                    entry_point: Some("fullscreen_vs"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: self.depth_stencil.clone(),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: self.module,
                    entry_point: Some(self.entry),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
    }
}
