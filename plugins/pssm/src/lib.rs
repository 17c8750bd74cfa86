//! Parallel-split shadow maps (Zhang et al. 2006; seed 000 sections 7.6 and 13.1) against
//! perspective aliasing in large views. The visible depth range [n, f] of each frame is split
//! at C_i = λ·n·(f/n)^(i/m) + (1 - λ)·(n + (f - n)·i/m); every split of a directional light gets
//! its own orthographic crop (the split's slice of the view frustum, reaching back to the
//! casters) in one depth array, optionally stabilised (bounding sphere, whole-texel snapping).
//! Lookups pick the split by view depth and blend across split borders; filters are the
//! shadow-map library's (PCF, Poisson, PCSS). Spot and point lights are not shadowed (they
//! are declared unsupported).

mod sdsm;
mod top_view;
mod warped;

pub use warped::{LispsmParams, PsmParams};

use zoo_host::glam::Vec4;
use zoo_host::kit::{NamedTextures, TextureSize, TextureSpec};
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_shadow_maps::light_space::Projection;
use zoo_shadow_maps::{
    Cascades, DepthState, FilterParams, LightMaps, LookupPass, LookupShader, MapFilter, MapFilters,
    MapParams, ShadowMapSet, light_size,
};

zoo_host::technique_params! {
    /// Parameters of parallel-split shadow maps.
    pub struct PssmParams {
        use map: MapParams;
        use filtering: FilterParams;
        /// Number of splits of the view's depth range.
        splits: u32 = 4, range(1, 8), step(1);
        /// Split scheme: 0 uniform, 1 logarithmic, between them a blend.
        lambda: f32 = 0.5, range(0.0, 1.0), step(0.05);
        /// Fraction of each split, at its far end, blended into the next split.
        blend: f32 = 0.1, range(0.0, 0.5), step(0.01);
        /// Stable crops (bounding sphere, centre snapped to whole texels): no shimmering edges.
        stabilise: bool = true;
        /// Constant depth bias of the depth pass, in units of the depth format's resolution.
        constant_bias: u32 = 0, range(0, 100000), step(100), flags(rebuild);
        /// Light whose splits the debug views show (the first shadowed light if it has none).
        debug_light: u32 = 0, range(0, 1023), step(1);
    }
}

zoo_host::gpu_struct! {
    "pssm/pssm_light.wgsl" =>
    /// One light's lookup (`pssm/lookup.wgsl`).
    #[derive(Debug, Clone, Copy)]
    struct PssmLight {
        /// Index of the scene light (directional).
        light: u32,
        first_layer: u32,
        splits: u32,
        /// 1 when this light's diagnostics are written.
        diagnostics: u32,
        map_filter: MapFilter,
        /// Fraction of each split blended into the next.
        blend: f32,
        /// Normal offset in texels of the split's map.
        normal_offset: f32,
        /// Split distances C_0..C_8 (view depths), four per vector.
        distances: [Vec4; 3],
        /// Per split: world size of one texel, and the map's depth range.
        texel: [Vec4; 2],
        depth_near: [Vec4; 2],
        depth_far: [Vec4; 2],
    }
}

/// `values` four to a vector, zero past their end.
fn vec4s<const N: usize>(values: &[f32]) -> [Vec4; N] {
    let mut padded = vec![0.0; 4 * N];
    padded[..values.len()].copy_from_slice(values);
    std::array::from_fn(|k| Vec4::from_slice(&padded[4 * k..]))
}

const SHADER: &str = "pssm/lookup.wgsl";
const MAP_PASS: &str = "PSSM map";
const LOOKUP_PASS: &str = "PSSM lookup";
const DIAGNOSTICS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const SPLITS_VIEW: &str = "splits";
const DENSITY_VIEW: &str = "texel density";
const TOP_VIEW: &str = "split frusta (top view)";

/// Screen-sized diagnostics (split colours, texel density) and the top view, drawn on the CPU.
fn diagnostics() -> NamedTextures {
    let colour = Some(ViewMapping::Color { min: 0.0, max: 1.0 });
    let top_view = TextureSpec {
        size: TextureSize::Fixed(zoo_host::glam::UVec2::splat(top_view::SIZE)),
        usage: wgpu::TextureUsages::COPY_DST,
        ..TextureSpec::screen_target(TOP_VIEW, DIAGNOSTICS_FORMAT, colour)
    };
    NamedTextures::new(
        "pssm",
        [
            TextureSpec::screen_target(SPLITS_VIEW, DIAGNOSTICS_FORMAT, colour),
            TextureSpec::screen_target(DENSITY_VIEW, DIAGNOSTICS_FORMAT, colour),
            top_view,
        ],
    )
}

/// Maps and the lookup, built at the first `prepare`.
struct Gpu {
    maps: ShadowMapSet,
    lookup: LookupPass<PssmLight>,
    filters: MapFilters,
    diagnostics: NamedTextures,
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>, params: &PssmParams) -> TechniqueResult<Gpu> {
        let state = DepthState {
            constant_bias: params.constant_bias as i32,
            slope_bias: params.map.slope_bias,
            ..DepthState::default()
        };
        let maps = ShadowMapSet::new(ctx, "pssm maps", state, None)?;
        let shader = LookupShader {
            shader: SHADER,
            entry: "fs_pssm",
            // Split colours and texel density.
            diagnostics: &[DIAGNOSTICS_FORMAT, DIAGNOSTICS_FORMAT],
            depth_stencil: None,
            shared: &[],
        };
        Ok(Gpu {
            lookup: LookupPass::new(ctx, &maps, LOOKUP_PASS, shader)?,
            maps,
            filters: MapFilters::read(ctx.shaders)?,
            diagnostics: diagnostics(),
        })
    }
}

/// Parallel-split shadow maps.
pub struct Pssm {
    params: PssmParams,
    gpu: LazyGpu<Gpu>,
    /// Where the view's samples are (sdsm's, from the depth buffer); `None` fits the splits
    /// to the objects' boxes.
    samples: Option<std::sync::Arc<zoo_shadow_maps::SampleFit>>,
}

impl Pssm {
    fn new(values: &ParamValues) -> TechniqueResult<Pssm> {
        Ok(Pssm {
            params: PssmParams::from_values(values)?,
            gpu: LazyGpu::default(),
            samples: None,
        })
    }

    fn cascades(&self) -> Cascades {
        Cascades {
            splits: self.params.splits,
            lambda: self.params.lambda,
            blend: self.params.blend,
            samples: self.samples.clone(),
        }
    }
}

/// The lookup's uniform for one light's splits at `distances`.
fn light_uniform(
    p: &PssmParams,
    map_filter: MapFilter,
    maps: &LightMaps,
    distances: &[f32],
    debug: bool,
) -> PssmLight {
    let mut texel = [0.0; 8];
    let mut depth_near = [0.0; 8];
    let mut depth_far = [0.0; 8];
    for (i, frustum) in maps.frustums.iter().enumerate() {
        if let Projection::Orthographic { extent, near, far } = frustum.projection {
            texel[i] = extent / maps.resolution as f32;
            depth_near[i] = near;
            depth_far[i] = far;
        }
    }
    PssmLight {
        light: maps.light as u32,
        first_layer: maps.first_layer,
        splits: maps.frustums.len() as u32,
        diagnostics: u32::from(debug),
        map_filter,
        blend: p.blend,
        normal_offset: p.map.normal_offset,
        distances: vec4s(distances),
        texel: vec4s(&texel),
        depth_near: vec4s(&depth_near),
        depth_far: vec4s(&depth_far),
    }
}

impl ShadowTechnique for Pssm {
    fn resources(&self) -> Vec<ResourceInfo> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let mut out = Vec::new();
        if let Some(maps) = gpu.maps.maps() {
            out.push(ResourceInfo::texture("shadow maps", &maps.texture, true));
        }
        out.extend(gpu.diagnostics.resources());
        if let Some(cameras) = gpu.maps.cameras() {
            out.push(ResourceInfo::buffer(
                "layer cameras",
                cameras,
                "LayerCamera",
            ));
        }
        out
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        self.gpu.prepare(false, || Gpu::new(ctx, &self.params))?;
        let cascades = self.cascades();
        let gpu = self.gpu.get_mut()?;
        gpu.diagnostics.prepare(ctx);
        let p = &self.params;
        (gpu.maps).prepare_with(ctx, changes, p.map.map_size, p.stabilise, &cascades);
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let cascades = self.cascades();
        let p = &self.params;
        let Gpu {
            maps,
            lookup,
            filters,
            diagnostics: d,
        } = self.gpu.get_mut()?;
        maps.record(ctx, recorder, MAP_PASS)?;
        let aspect = ctx.size.x as f32 / ctx.size.y.max(1) as f32;
        let distances = cascades.distances(ctx.camera, aspect, maps.bounds().0, p.stabilise);
        // Lights without splits (spot, point) are not shadowed.
        let uniform = |l: &LightMaps, debug| {
            let size = light_size(&ctx.lights[l.light]);
            let map_filter = filters.filter(&p.filtering, size);
            let shadowed = !l.frustums.is_empty();
            shadowed.then(|| light_uniform(p, map_filter, l, &distances, debug))
        };
        let (Some(splits), Some(density), Some(top)) = (
            d.view(SPLITS_VIEW),
            d.view(DENSITY_VIEW),
            d.texture(TOP_VIEW),
        ) else {
            return Err(TechniqueError::not_prepared());
        };
        let targets = [splits, density];
        lookup.record(ctx, recorder, maps, p.debug_light, &targets, uniform)?;
        if ctx.debug_view == Some(TOP_VIEW) {
            let aspect = ctx.size.x as f32 / ctx.size.y.max(1) as f32;
            let debug: Vec<LightMaps> = maps
                .debug_light(p.debug_light)
                .cloned()
                .into_iter()
                .collect();
            let pixels = top_view::draw(ctx.camera, aspect, &debug, &distances);
            write_top_view(ctx.gpu, top, &pixels);
        }
        Ok(())
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        // The depth biases live in the depth pipeline (`flags(rebuild)`); everything else
        // applies at `prepare`.
        Ok(self.params.update(values)?)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let gpu = self.gpu.built()?;
        match resource {
            "shadow maps" => gpu.maps.debug_image(self.params.debug_light),
            _ => gpu.diagnostics.debug_view(resource),
        }
    }

    fn counters(&self) -> Vec<(String, f64)> {
        self.gpu
            .built()
            .map_or(Vec::new(), |gpu| gpu.maps.counters())
    }
}

fn write_top_view(gpu: &GpuContext, texture: &wgpu::Texture, pixels: &[u8]) {
    let size = top_view::SIZE;
    gpu.queue.write_texture(
        texture.as_image_copy(),
        pixels,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size * 4),
            rows_per_image: Some(size),
        },
        wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
    );
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    Ok(Box::new(Pssm::new(values)?))
}

zoo_host::register_technique! {
    id: "pssm",
    name: "Parallel-split shadow maps",
    description: "Directional lights: the view's depth range split by the practical scheme, one stable orthographic crop per split, blended split borders",
    source: "seed 000 sections 7.6 and 13.1 (Zhang et al. 2006); seed 004",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional],
    params: PssmParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_uniform_holds_every_split() {
        // Eight splits and their nine distances fit.
        let p = PssmParams::from_values(&ParamValues::new()).unwrap();
        assert!(PssmParams::schema().iter().any(|s| s.key == "splits"));
        let distances: Vec<f32> = (0..9).map(|i| i as f32).collect();
        let maps = LightMaps {
            light: 0,
            first_layer: 3,
            resolution: 1024,
            tiles: Vec::new(),
            frustums: Vec::new(),
            layer_word: "split",
            scissor: [0; 4],
        };
        let light = light_uniform(&p, MapFilter::default(), &maps, &distances, true);
        assert_eq!(light.distances[2].x, 8.0);
        assert_eq!(light.first_layer, 3);
    }
}
