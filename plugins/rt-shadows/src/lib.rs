//! Ray-traced shadows on any adapter: from each pixel's surface, any-hit shadow rays through
//! the scene's bounding volume hierarchy (`zoo-ray-tracing`, traversed in a fragment shader):
//! one ray to each light's centre gives exact hard shadows; several rays to points of the
//! light's disk (a rotated low-discrepancy pattern per pixel) give soft ones, smoothed by an
//! edge-aware spatial filter guided by the G-buffer's depth and normals.

use zoo_host::prelude::*;
use zoo_ray_tracing::RayTracing;

zoo_host::technique_params! {
    /// Parameters of ray-traced shadows.
    pub struct RtParams {
        /// Shadow rays per pixel and light toward points of the light's disk; 1 traces one ray
        /// to its centre (hard shadows), as do lights without a radius.
        rays_per_pixel: u32 = 4, range(1, 64), step(1);
        /// Radius in pixels of the filter that smooths soft shadows' noise (0: off); lights
        /// traced with one ray are left as they are.
        denoise_radius: u32 = 2, range(0, 8), step(1);
    }
}

/// `RtLight` in `rt-shadows/light.wgsl`: the light, its rays per pixel, its visibility slot
/// and the filter's radius for it.
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[bytemuck(crate = "zoo_host::bytemuck")]
#[repr(C)]
struct RtLight {
    light: u32,
    rays: u32,
    layer: u32,
    channel: u32,
    denoise_radius: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

const TRACE_SHADER: &str = "rt-shadows/shadows.wgsl";
const DENOISE_SHADER: &str = "rt-shadows/denoise.wgsl";
/// Base names of the per-light passes.
const TRACE_PASS: &str = "Ray-traced shadows";
const DENOISE_PASS: &str = "Denoise";

/// A copy of the visibility slots as traced, read by the filter while it writes the slots.
struct Traced {
    texture: wgpu::Texture,
    group: wgpu::BindGroup,
}

/// The pipelines and the hierarchy they trace.
struct Gpu {
    tracing_layout: wgpu::BindGroupLayout,
    trace: FullscreenLightPass<RtLight>,
    traced_layout: wgpu::BindGroupLayout,
    denoise: FullscreenLightPass<RtLight>,
    tracing: Option<RayTracing>,
    traced: Option<Traced>,
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>) -> TechniqueResult<Gpu> {
        let device = &ctx.gpu.device;
        let tracing_layout = zoo_ray_tracing::layout(device);
        let trace = FullscreenLightPass::new(ctx, TRACE_SHADER, "fs_main", &[&tracing_layout])?;
        let traced_layout = kit::bind_group_layout(
            device,
            "rt-shadows traced visibility layout",
            &[kit::texture(
                0,
                wgpu::ShaderStages::FRAGMENT,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2Array,
            )],
        );
        let denoise =
            FullscreenLightPass::new(ctx, DENOISE_SHADER, "fs_denoise", &[&traced_layout])?;
        Ok(Gpu {
            tracing_layout,
            trace,
            traced_layout,
            denoise,
            tracing: None,
            traced: None,
        })
    }

    /// The copy of the slots, made again when the slots' texture changed shape.
    fn traced(&mut self, ctx: &RenderContext<'_>) -> &Traced {
        let slots = &ctx.visibility.texture;
        if self
            .traced
            .as_ref()
            .is_none_or(|t| t.texture.size() != slots.size())
        {
            let texture = ctx.gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("rt-shadows traced visibility"),
                size: slots.size(),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: slots.format(),
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some("rt-shadows traced visibility view"),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            });
            let group = kit::bind_group(
                &ctx.gpu.device,
                "rt-shadows traced visibility",
                &self.traced_layout,
                &[wgpu::BindingResource::TextureView(&view)],
            );
            self.traced = Some(Traced { texture, group });
        }
        self.traced.as_ref().expect("made above")
    }
}

struct RtShadows {
    params: RtParams,
    gpu: Option<Gpu>,
}

impl ShadowTechnique for RtShadows {
    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        if self.gpu.is_none() {
            self.gpu = Some(Gpu::new(ctx)?);
        }
        let gpu = self.gpu.as_mut().expect("built above");
        if changes.scene || gpu.tracing.as_ref().is_none_or(|t| !t.is_for(ctx)) {
            gpu.tracing = Some(RayTracing::new(ctx, &gpu.tracing_layout)?);
        }
        Ok(())
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let (rays, radius) = (self.params.rays_per_pixel, self.params.denoise_radius);
        let gpu = self.gpu.as_mut().ok_or_else(TechniqueError::not_prepared)?;
        // Soft lights are filtered; hard ones (one ray, or no radius) are exact as traced.
        let soft = |light: usize| rays > 1 && ctx.lights[light].radius > 0.0;
        let per_light = |light: usize| {
            let (layer, channel) = ctx.visibility.slots.slot(light);
            RtLight {
                light: light as u32,
                rays,
                layer,
                channel,
                denoise_radius: if soft(light) { radius } else { 0 },
                _pad0: 0,
                _pad1: 0,
                _pad2: 0,
            }
        };
        let tracing = gpu
            .tracing
            .as_ref()
            .ok_or_else(TechniqueError::not_prepared)?;
        gpu.trace
            .record_with(ctx, rec, TRACE_PASS, per_light, |_, pass| {
                pass.set_bind_group(zoo_ray_tracing::GROUP, &tracing.bind_group, &[]);
            });
        if radius == 0 || !(0..ctx.lights.len()).any(soft) {
            return Ok(());
        }
        let traced = gpu.traced(ctx);
        let slots = &ctx.visibility.texture;
        rec.encoder().copy_texture_to_texture(
            slots.as_image_copy(),
            traced.texture.as_image_copy(),
            slots.size(),
        );
        let group = traced.group.clone();
        gpu.denoise
            .record_with(ctx, rec, DENOISE_PASS, per_light, |_, pass| {
                pass.set_bind_group(3, &group, &[]);
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
        let mirror = zoo_host::mirror_fields!(RtLight {
            light,
            rays,
            layer,
            channel,
            denoise_radius,
            _pad0,
            _pad1,
            _pad2
        });
        check_embedded_mirror("rt-shadows/light.wgsl", "RtLight", mirror, SizeRule::Equal).unwrap();
    }
}
