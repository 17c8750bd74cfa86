//! Variance shadow maps (Donnelly and Lauritzen 2006): each light's casters store the first two
//! moments of their light depth in a filterable float map, blurred by a separable Gaussian;
//! lookups bound the lit fraction of the filter region with Chebyshev's inequality, and a
//! light-bleeding reduction cuts the bound's loose tail where casters overlap. Maps, fitting and
//! the blur come from the shadow-map library (spot cones, directional boxes, point cubes).

use zoo_host::kit::light_pass_name;
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_shadow_maps::{ColorOutput, DepthState, LayerBlur, ShadowMapSet, filterable_rg_format};

zoo_host::technique_params! {
    /// Parameters of variance shadow maps.
    pub struct VsmParams {
        /// Moment-map resolution in texels per side (clamped to the device and memory budget).
        map_size: u32 = 2048, range(256, 8192), step(256);
        /// Gaussian blur of the moments, in taps on each side (0: bilinear filtering only).
        blur_radius: u32 = 2, range(0, 16), step(1);
        /// Smallest variance, in squared light-depth units (0 to 1 over the map; at least 1e-4
        /// with 16-bit moments).
        min_variance: f32 = 0.000001, range(0.0, 0.001), step(0.000001);
        /// Light-bleeding reduction: bounds below it become 0 and the rest is rescaled.
        bleeding_reduction: f32 = 0.2, range(0.0, 0.95), step(0.05);
        /// Lookups move off the surface by this many map texels along the normal.
        normal_offset: f32 = 1.0, range(0.0, 8.0), step(0.1);
        /// Keep directional maps stable as the camera moves (no shimmering edges).
        stable_fit: bool = true;
    }
}

/// `VsmLight` in `vsm/lookup.wgsl`.
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[bytemuck(crate = "zoo_host::bytemuck")]
#[repr(C)]
struct VsmLight {
    first_layer: u32,
    layer_count: u32,
    light: u32,
    perspective: u32,
    texel_scale: f32,
    normal_offset: f32,
    min_variance: f32,
    bleeding_reduction: f32,
}

const LOOKUP: &str = "VSM lookup";
const MOMENTS: &str = "VSM moments";
const BLUR: &str = "VSM blur";

/// Pipelines and maps, built at the first `prepare`.
struct Gpu {
    maps: ShadowMapSet,
    blur: LayerBlur,
    lookup: FullscreenLightPass<VsmLight>,
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>, format: wgpu::TextureFormat) -> TechniqueResult<Gpu> {
        // Texels no caster covers hold the far plane: depth 1, squared depth 1.
        let output = ColorOutput {
            shader: "vsm/moments.wgsl",
            entry: "fs_moments",
            format,
            clear: wgpu::Color::WHITE,
        };
        let maps = ShadowMapSet::new(ctx, "vsm moments", DepthState::default(), Some(output))?;
        let lookup_layout = maps.lookup_layout();
        Ok(Gpu {
            lookup: FullscreenLightPass::new(ctx, "vsm/lookup.wgsl", "fs_vsm", &[lookup_layout])?,
            blur: LayerBlur::new(ctx, "vsm blur", format)?,
            maps,
        })
    }
}

struct Vsm {
    params: VsmParams,
    gpu: Option<Gpu>,
}

impl ShadowTechnique for Vsm {
    fn passes(&self) -> Vec<PassInfo> {
        let Some(gpu) = &self.gpu else {
            return Vec::new();
        };
        let mut names = gpu.maps.pass_names(MOMENTS);
        if self.params.blur_radius > 0 {
            names.extend(LayerBlur::pass_names(gpu.maps.lights(), BLUR));
        }
        let lookups = gpu
            .maps
            .lights()
            .iter()
            .map(|l| light_pass_name(LOOKUP, l.light));
        names
            .into_iter()
            .chain(lookups)
            .map(PassInfo::render)
            .collect()
    }

    fn resources(&self) -> Vec<ResourceInfo> {
        let Some(maps) = self.gpu.as_ref().map(|g| &g.maps) else {
            return Vec::new();
        };
        let moments = maps
            .maps()
            .map(|m| ResourceInfo::texture("moments", &m.texture, true));
        let cameras = maps
            .cameras()
            .map(|c| ResourceInfo::buffer("layer cameras", c, "LayerCamera"));
        moments.into_iter().chain(cameras).collect()
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        if self.gpu.is_none() {
            let format = filterable_rg_format(&ctx.gpu.device);
            self.gpu = Some(Gpu::new(ctx, format)?);
        }
        let gpu = self.gpu.as_mut().expect("built above");
        gpu.maps
            .prepare(ctx, changes, self.params.map_size, self.params.stable_fit);
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let gpu = self.gpu.as_mut().ok_or_else(TechniqueError::not_prepared)?;
        let (Some(maps), Some(group)) = (gpu.maps.maps(), gpu.maps.lookup_group()) else {
            return Err(TechniqueError::not_prepared());
        };
        gpu.maps.record(ctx, recorder, MOMENTS)?;
        let lights = gpu.maps.lights();
        gpu.blur
            .record(ctx, recorder, maps, lights, self.params.blur_radius, BLUR);
        let p = &self.params;
        // Half floats hold E[z²] - E[z]² only to about 1e-4 near depth 1.
        let half = maps.texture.format() == wgpu::TextureFormat::Rg16Float;
        let floor = if half { 1e-4 } else { 0.0 };
        let uniform = |light: usize| {
            let scale = lights[light].scale(maps.resolution);
            VsmLight {
                first_layer: lights[light].first_layer,
                layer_count: lights[light].frustums.len() as u32,
                light: light as u32,
                perspective: u32::from(scale.perspective),
                texel_scale: scale.texel_scale,
                normal_offset: p.normal_offset,
                min_variance: p.min_variance.max(floor),
                bleeding_reduction: p.bleeding_reduction,
            }
        };
        let bind = |_, pass: &mut wgpu::RenderPass<'_>| pass.set_bind_group(3, group, &[]);
        gpu.lookup.record_with(ctx, recorder, LOOKUP, uniform, bind);
        Ok(())
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        // Everything, map size included, applies at the next `prepare`.
        self.params = VsmParams::from_values(values)?;
        Ok(ParamUpdate::Applied)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let maps = &self.gpu.as_ref()?.maps;
        let view = &maps.maps()?.layer_views[maps.lights().first()?.first_layer as usize];
        let mapping = ViewMapping::Channel {
            channel: 0,
            min: 0.0,
            max: 1.0,
        };
        (resource == "moments").then_some(DebugImage { view, mapping })
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = VsmParams::from_values(values)?;
    Ok(Box::new(Vsm { params, gpu: None }))
}

zoo_host::register_technique! {
    id: "vsm",
    name: "Variance shadow maps",
    description: "Blurred depth moments per light (spot, directional, point cube); Chebyshev bound with light-bleeding reduction",
    source: "seed 000 section 13.3 (Donnelly and Lauritzen 2006)",
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    optional_features: || wgpu::Features::FLOAT32_FILTERABLE,
    params: VsmParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::layout::{SizeRule, check_mirror};

    #[test]
    fn vsm_light_mirrors_the_shader() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose("vsm/lookup.wgsl")
            .unwrap()
            .source;
        let (size, fields) = zoo_host::mirror_fields!(VsmLight {
            first_layer,
            layer_count,
            light,
            perspective,
            texel_scale,
            normal_offset,
            min_variance,
            bleeding_reduction
        });
        check_mirror(&source, "VsmLight", size, &fields, SizeRule::Equal).unwrap();
    }
}
