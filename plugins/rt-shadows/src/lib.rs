//! Ray-traced shadows on any adapter: from each pixel's surface, any-hit shadow rays through
//! the scene's bounding volume hierarchy (`zoo-ray-tracing`, traversed in a fragment shader):
//! one ray to each light's centre gives exact hard shadows; several rays to points of the
//! light's disk (a rotated low-discrepancy pattern per pixel) give soft ones.

use zoo_host::prelude::*;
use zoo_ray_tracing::RayTracing;

zoo_host::technique_params! {
    /// Parameters of ray-traced shadows.
    pub struct RtParams {
        /// Shadow rays per pixel and light toward points of the light's disk; 1 traces one ray
        /// to its centre (hard shadows), as do lights without a radius.
        rays_per_pixel: u32 = 4, range(1, 64), step(1);
    }
}

/// `RtLight` in `rt-shadows/shadows.wgsl`: the light and its rays per pixel.
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[bytemuck(crate = "zoo_host::bytemuck")]
#[repr(C)]
struct RtLight {
    light: u32,
    rays: u32,
    _pad: [u32; 2],
}

const SHADER: &str = "rt-shadows/shadows.wgsl";
/// Base name of the per-light passes.
const PASS: &str = "Ray-traced shadows";

/// The pipeline and the hierarchy it traces.
struct Gpu {
    layout: wgpu::BindGroupLayout,
    pass: FullscreenLightPass<RtLight>,
    tracing: Option<RayTracing>,
}

struct RtShadows {
    params: RtParams,
    gpu: Option<Gpu>,
}

impl ShadowTechnique for RtShadows {
    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        if self.gpu.is_none() || changes.lights {
            let layout = zoo_ray_tracing::layout(&ctx.gpu.device);
            let pass = FullscreenLightPass::new(ctx, SHADER, "fs_main", &[&layout])?;
            let tracing = self.gpu.take().and_then(|g| g.tracing);
            self.gpu = Some(Gpu {
                layout,
                pass,
                tracing,
            });
        }
        let gpu = self.gpu.as_mut().expect("built above");
        if gpu.tracing.as_ref().is_none_or(|t| !t.is_for(ctx)) {
            gpu.tracing = Some(RayTracing::new(ctx, &gpu.layout));
        }
        Ok(())
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let rays = self.params.rays_per_pixel;
        let gpu = self.gpu.as_mut().ok_or_else(TechniqueError::not_prepared)?;
        let tracing = gpu
            .tracing
            .as_ref()
            .ok_or_else(TechniqueError::not_prepared)?;
        let per_light = |light: usize| RtLight {
            light: light as u32,
            rays,
            _pad: [0; 2],
        };
        gpu.pass.record_with(ctx, rec, PASS, per_light, |_, pass| {
            pass.set_bind_group(zoo_ray_tracing::GROUP, &tracing.bind_group, &[]);
        });
        Ok(())
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        Ok(self.params.update(values)?)
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = RtParams::from_values(values)?;
    Ok(Box::new(RtShadows { params, gpu: None }))
}

zoo_host::register_technique! {
    id: "rt-shadows",
    name: "Ray-traced shadows",
    description: "Any-hit shadow rays through the scene's BVH in a fragment shader: one to each light (hard) or several to its disk (soft)",
    source: "ray tracing (the judge's visibility on the GPU)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    // The frame's lights and objects and the hierarchy's three buffers, in fragment shaders.
    required_limits: || wgpu::Limits {
        max_storage_buffers_per_shader_stage: 5,
        ..wgpu::Limits::downlevel_defaults()
    },
    params: RtParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::layout::{SizeRule, check_embedded_mirror};

    #[test]
    fn light_uniform_mirrors_the_shader() {
        let mirror = zoo_host::mirror_fields!(RtLight { light, rays, _pad });
        check_embedded_mirror(SHADER, "RtLight", mirror, SizeRule::Equal).unwrap();
    }
}
