//! Compute passes with the technique's own bind group, declared by the shader: the group's
//! layout and the workgroup size are read from the WGSL ([`super::reflect`]), resources are
//! bound by their variable names (checked against the declarations), and dispatches cover an
//! extent of invocations. The group goes after the host's frame and G-buffer groups (passes
//! over the screen's surfaces) or alone (passes over a technique's own data).

use crate::gpu::{PassRecorder, ShaderError};
use crate::technique::{RenderContext, TechniqueError};

use super::layouts::{bind_group_layout, pipeline_layout};
use super::reflect::{ReflectedStage, match_resources, reflect_compute, workgroups_over};

/// Where a compute stage's own group goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageGroups {
    /// Group 2, after the frame (0) and G-buffer (1) groups.
    AfterHost,
    /// Group 0, with no host groups.
    Alone,
}

impl StageGroups {
    /// The index of the stage's own group.
    pub fn own_group(self) -> u32 {
        match self {
            StageGroups::AfterHost => 2,
            StageGroups::Alone => 0,
        }
    }
}

/// A compute pipeline, the layout of its own group as the shader declares it, and its
/// workgroup size; further groups follow the own one.
pub struct ComputeStage {
    /// `shader entry`: names the pipeline and the stage's errors.
    label: String,
    pipeline: wgpu::ComputePipeline,
    /// The layout of the stage's own group.
    layout: wgpu::BindGroupLayout,
    reflected: ReflectedStage,
    groups: StageGroups,
}

impl ComputeStage {
    /// Builds entry `entry` of library shader `shader`, with its own group read from the
    /// shader and placed as `groups` says, then `more` groups.
    pub fn new(
        ctx: &RenderContext<'_>,
        shader: &str,
        entry: &str,
        groups: StageGroups,
        more: &[&wgpu::BindGroupLayout],
    ) -> Result<ComputeStage, TechniqueError> {
        let device = &ctx.gpu.device;
        let label = format!("{shader} {entry}");
        let (ir, info) = ctx.shaders.reflect(shader)?;
        let reflected =
            reflect_compute(&ir, &info, entry, groups.own_group()).map_err(|message| {
                ShaderError::Pipeline {
                    label: label.clone(),
                    message,
                }
            })?;
        let module = ctx.shaders.create_module(device, shader)?;
        let entries: Vec<_> = reflected.bindings.iter().map(|b| b.entry).collect();
        let layout = bind_group_layout(device, &format!("{label} layout"), &entries);
        let mut own = vec![&layout];
        own.extend_from_slice(more);
        let layout_label = format!("{label} pipeline layout");
        let pipeline_layout = match groups {
            StageGroups::AfterHost => pipeline_layout(ctx, &layout_label, &own),
            StageGroups::Alone => {
                let own: Vec<Option<&wgpu::BindGroupLayout>> =
                    own.iter().map(|l| Some(*l)).collect();
                device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(&layout_label),
                    bind_group_layouts: &own,
                    immediate_size: 0,
                })
            }
        };
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(&label),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        });
        Ok(ComputeStage {
            label,
            pipeline,
            layout,
            reflected,
            groups,
        })
    }

    /// The stage's own bind group over `resources`, each named as its WGSL variable: every
    /// variable the entry point uses must be given, once, with a resource of its kind.
    pub fn bind(
        &self,
        ctx: &RenderContext<'_>,
        label: &str,
        resources: &[(&str, wgpu::BindingResource<'_>)],
    ) -> Result<wgpu::BindGroup, TechniqueError> {
        let entries = match_resources(&self.reflected, resources).map_err(|message| {
            ShaderError::Pipeline {
                label: format!("{label} (for {})", self.label),
                message,
            }
        })?;
        Ok(ctx
            .gpu
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout: &self.layout,
                entries: &entries,
            }))
    }

    /// Records one dispatch of enough workgroups to cover `extent` invocations, in a pass
    /// named `name`, with `group` as the stage's own group and `more` after it.
    pub fn dispatch(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        name: &str,
        group: &wgpu::BindGroup,
        more: &[&wgpu::BindGroup],
        extent: [u32; 3],
    ) {
        let mut pass = recorder.compute_pass(name);
        pass.set_pipeline(&self.pipeline);
        let first = self.groups.own_group();
        if self.groups == StageGroups::AfterHost {
            pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
            pass.set_bind_group(1, &ctx.gbuffer.bind_group, &[]);
        }
        pass.set_bind_group(first, group, &[]);
        for (k, extra) in more.iter().enumerate() {
            pass.set_bind_group(first + 1 + k as u32, *extra, &[]);
        }
        let [x, y, z] = workgroups_over(extent, self.reflected.workgroup_size);
        pass.dispatch_workgroups(x, y, z);
    }
}
