//! Compute passes with the technique's own bind group: a pipeline built from a library shader
//! and the layout of that group, placed after the host's frame and G-buffer groups (for
//! passes over the screen's surfaces) or alone (for passes over a technique's own data).

use crate::gpu::PassRecorder;
use crate::technique::{RenderContext, TechniqueError};

use super::layouts::{bind_group_layout, pipeline_layout};

/// Where a compute stage's own group goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageGroups {
    /// Group 2, after the frame (0) and G-buffer (1) groups.
    AfterHost,
    /// Group 0, with no host groups.
    Alone,
}

/// A compute pipeline and the layout of its own group; further groups follow it.
pub struct ComputeStage {
    pipeline: wgpu::ComputePipeline,
    /// The layout of the stage's own group, for its bind groups.
    pub layout: wgpu::BindGroupLayout,
    groups: StageGroups,
}

impl ComputeStage {
    /// Builds entry `entry` of library shader `shader`, its own group of `entries` placed as
    /// `groups` says, then `more` groups.
    pub fn new(
        ctx: &RenderContext<'_>,
        shader: &str,
        entry: &str,
        entries: &[wgpu::BindGroupLayoutEntry],
        groups: StageGroups,
        more: &[&wgpu::BindGroupLayout],
    ) -> Result<ComputeStage, TechniqueError> {
        let device = &ctx.gpu.device;
        let module = ctx.shaders.create_module(device, shader)?;
        let label = format!("{shader} {entry}");
        let layout = bind_group_layout(device, &format!("{label} layout"), entries);
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
            pipeline,
            layout,
            groups,
        })
    }

    /// Records one dispatch of `workgroups` in a pass named `name`, with `group` as the
    /// stage's own group and `more` after it.
    pub fn dispatch(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        name: &str,
        group: &wgpu::BindGroup,
        more: &[&wgpu::BindGroup],
        workgroups: [u32; 3],
    ) {
        let mut pass = recorder.compute_pass(name);
        pass.set_pipeline(&self.pipeline);
        let first = match self.groups {
            StageGroups::AfterHost => {
                pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
                pass.set_bind_group(1, &ctx.gbuffer.bind_group, &[]);
                2
            }
            StageGroups::Alone => 0,
        };
        pass.set_bind_group(first, group, &[]);
        for (k, extra) in more.iter().enumerate() {
            pass.set_bind_group(first + 1 + k as u32, *extra, &[]);
        }
        pass.dispatch_workgroups(workgroups[0], workgroups[1], workgroups[2]);
    }
}
