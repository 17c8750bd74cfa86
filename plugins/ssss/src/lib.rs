//! Layered screen-space soft shadows (seed 001: Tamás and Heisenberger's practical SSSS after
//! Gumbau et al. 2010) for many lights.
//!
//! Every light renders shadow maps from the shadow-map library (a spot cone, six cube faces,
//! a fitted directional box); maps of lights and cube faces the view cannot see are culled.
//! Lights are coloured into screen-space layers so that lights whose influence can meet on
//! screen never share one ([`layers`]); the layers are the host's visibility slots. One
//! compute pass then handles every light at every pixel: a hard shadow test (a bit per layer),
//! a blocker search whose PCSS estimate gives the penumbra width, turned into a Gaussian sigma
//! in screen pixels (a quarter of the width, the standard deviation of a disk light's
//! penumbra across an edge, times sqrt(max(n_view.z, 0.25)) / view depth), and the tint of
//! translucent casters in front. Two separable passes blur all layers at once along rotated
//! screen directions, skipping taps across depth discontinuities, and write each layer's
//! visibility and transmittance colour into the host's slots.

pub mod gpu;
pub mod layers;

use zoo_host::glam::{Mat4, UVec4};
use zoo_host::gpu::layout::ChoiceCodes;
use zoo_host::gpu::{gpu_bytes, gpu_bytes_padded};
use zoo_host::kit::NamedTextures;
use zoo_host::prelude::*;
use zoo_host::render::{SlotAssignment, SlotRequest};
use zoo_host::scene::Scene;
use zoo_host::technique::{DebugImage, ResourceInfo};
use zoo_shadow_maps::culling::frusta_intersect;
use zoo_shadow_maps::{DepthState, ShadowMapSet, TRANSLUCENT_FORMAT, TranslucentPass, light_size};

use gpu::{
    DEBUG_VIEWS, LIGHT_STRIDE, LIGHTS_OFFSET, MinFilter, Passes, Settings, ShaderParams, SsssLight,
    debug_mode_offset, target_specs,
};
use layers::{Layers, assign_layers};

zoo_host::param_choice! {
    /// Taps of each separable blur pass (the seed's 5, 11 and 23); the kernel always spans
    /// +-2.5 sigma, so more taps sample it more finely rather than widen it.
    pub enum Kernel { Taps5, Taps11, Taps23 }
}

zoo_host::param_choice! {
    /// How the penumbra pass finds blockers: a 16-tap search of the shadow map around each
    /// receiver, averaging the blockers' depths (PCSS), or the nearest depth of the
    /// min-filtered maps over the search radius (seed 001 §9: fewer, cheaper fetches; the
    /// nearest blocker rather than the mean, and translucent casters do not count).
    pub enum Estimate { BlockerSearch, MinFilter }
}

zoo_host::technique_params! {
    /// Parameters of layered screen-space soft shadows.
    pub struct SsssParams {
        /// Shadow-map resolution in texels per side (clamped to the device and memory budget).
        map_size: u32 = 1024, range(256, 4096), step(256);
        /// Taps of each blur pass.
        kernel: Kernel = Kernel::Taps11;
        /// How blockers are found for the penumbra estimate.
        estimate: Estimate = Estimate::MinFilter, flags(shader);
        /// Blur on a half-resolution grid (each grid pixel the mean of a 2 x 2 block of the
        /// full-resolution hard shadows), upsampled with depth-aware weights; pixels without
        /// penumbra keep their full-resolution hard result.
        half_resolution: bool = true, flags(shader);
        /// Screen-space layers per batch: lights needing more layers run in several batches of
        /// the penumbra, blur and resolve passes (rounded down to whole groups of four).
        max_layers: u32 = 64, range(4, 64), step(4);
        /// Scales the estimated penumbra (1: the width the light's size gives).
        penumbra_scale: f32 = 1.0, range(0.0, 4.0), step(0.05), flags(shader);
        /// Blur taps whose view depth differs from the centre's by more than this fraction of
        /// it are skipped.
        depth_threshold: f32 = 0.05, range(0.005, 0.5), step(0.005), flags(shader);
        /// Smallest value of the kernel's grazing-angle factor n_view.z.
        grazing_clamp: f32 = 0.25, range(0.01, 1.0), step(0.01), flags(shader);
        /// Largest blur sigma, in pixels.
        max_blur: f32 = 32.0, range(1.0, 128.0), step(1.0), flags(shader);
        /// Largest blocker-search radius, in map texels.
        search_texels: f32 = 24.0, range(2.0, 64.0), step(1.0), flags(shader);
        /// Slope-scaled depth bias of the depth pass.
        slope_bias: f32 = 1.5, range(0.0, 10.0), step(0.1), flags(rebuild);
        /// Lookups move off the surface by this many map texels along the normal.
        normal_offset: f32 = 1.5, range(0.0, 8.0), step(0.1), flags(shader);
        /// Render only the maps of lights and cube faces that can shadow the view.
        cull_maps: bool = true;
        /// Keep directional maps stable as the camera moves.
        stable_fit: bool = true;
        /// Light whose maps the `shadow maps` view shows.
        debug_light: u32 = 0, range(0, 1023), step(1);
    }
}

const MAP_PASS: &str = "SSSS shadow map";
const TRANSLUCENT_PASS: &str = "SSSS translucency";

/// Maps, passes and targets, built at the first `prepare`.
struct Gpu {
    maps: ShadowMapSet,
    translucent: Option<TranslucentPass>,
    passes: Passes,
    /// The screen-size targets ([`target_specs`]), made at the first prepare.
    targets: NamedTextures,
    /// One data buffer per batch of layers.
    data: Vec<wgpu::Buffer>,
    /// A white translucency map for scenes without translucent casters.
    placeholder: (wgpu::Texture, wgpu::TextureView),
    min_filter: MinFilter,
    debug_codes: ChoiceCodes,
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>, params: &SsssParams) -> TechniqueResult<Gpu> {
        let state = DepthState {
            slope_bias: params.slope_bias,
            opaque_only: true,
            ..DepthState::default()
        };
        let maps = ShadowMapSet::new(ctx, "ssss shadow maps", state, None)?;
        let translucent = ctx
            .scene
            .has_translucent_casters()
            .then(|| TranslucentPass::new(ctx, "ssss translucency", &maps))
            .transpose()?;
        let passes = Passes::new(ctx, &maps)?;
        let source = ctx.shaders.compose("ssss/debug.wgsl")?.source;
        let debug_codes = ChoiceCodes::read(&source, "DEBUG", &DEBUG_VIEWS.map(|v| v.1))
            .map_err(|e| TechniqueError::Other(format!("ssss/debug.wgsl: {e}")))?;
        Ok(Gpu {
            maps,
            translucent,
            passes,
            targets: NamedTextures::new("ssss", target_specs(1, false, params.half_resolution)),
            data: Vec::new(),
            placeholder: placeholder(ctx.gpu),
            min_filter: MinFilter::new(ctx)?,
            debug_codes,
        })
    }
}

/// One white texel in a one-layer array of the translucency format.
fn placeholder(gpu: &GpuContext) -> (wgpu::Texture, wgpu::TextureView) {
    let layers = zoo_host::gpu::array_layers(gpu, 1, 1, 1);
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("ssss no translucency"),
        size: wgpu::Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: TRANSLUCENT_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    // 1.0 as four little-endian halves.
    let one = [0x00, 0x3c].repeat(4);
    for layer in 0..layers {
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer,
                },
                aspect: wgpu::TextureAspect::All,
            },
            &one,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(8),
                rows_per_image: None,
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
    }
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some("ssss no translucency (array)"),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        array_layer_count: Some(1),
        ..Default::default()
    });
    (texture, view)
}

/// Layered screen-space soft shadows.
pub struct Ssss {
    params: SsssParams,
    gpu: LazyGpu<Gpu>,
    /// The layers of the current lights and camera (as assigned to the visibility slots).
    layers: Layers,
}

impl Ssss {
    /// The colouring for the lights and camera of `request`.
    fn layers_for(&self, request: &SlotRequest<'_>) -> TechniqueResult<Layers> {
        Ok(assign_layers(request.lights, request.view_proj()))
    }

    /// Layers per batch: `max_layers` in whole groups of four.
    fn batch_layers(&self) -> u32 {
        (self.params.max_layers / 4 * 4).max(4)
    }
}

/// Batches of at most `per_batch` layers covering `count`: (first layer, layers).
fn batches(count: u32, per_batch: u32) -> Vec<(u32, u32)> {
    (0..count.max(1).div_ceil(per_batch))
        .map(|b| (b * per_batch, per_batch.min(count.max(1) - b * per_batch)))
        .collect()
}

/// The data buffer's settings for the batch of `layer_count` layers from `layer_base`.
fn settings(
    p: &SsssParams,
    (layer_base, layer_count): (u32, u32),
    ctx: &RenderContext<'_>,
) -> Settings {
    let proj = ctx.frame.matrices.proj;
    Settings {
        params: ShaderParams(p.shader_block()),
        layer_base,
        layer_count: layer_count.max(1),
        half_taps: match p.kernel {
            Kernel::Taps5 => 2,
            Kernel::Taps11 => 5,
            Kernel::Taps23 => 11,
        },
        translucent: u32::from(ctx.scene.has_translucent_casters()),
        pixel_scale: proj.y_axis.y * ctx.size.y as f32 * 0.5,
        debug_mode: 0,
    }
}

/// The light records of a batch: layers counted from the batch's first (lights of other
/// batches have none).
fn batch_records(records: &[SsssLight], (base, count): (u32, u32)) -> Vec<SsssLight> {
    (records.iter())
        .map(|record| {
            let mut record = *record;
            if (base..base + count).contains(&record.layer) {
                record.layer -= base;
            } else {
                record.layer_count = 0;
            }
            record
        })
        .collect()
}

/// A batch's data: its settings, then its light records (see [`batch_records`]).
fn batch_data(settings: Settings, records: &[SsssLight], batch: (u32, u32)) -> Vec<u8> {
    let mut bytes = gpu_bytes_padded(&settings, LIGHTS_OFFSET);
    bytes.extend(gpu_bytes(&batch_records(records, batch)));
    bytes
}

/// One record per scene light: its maps and layer (none for lights without either).
fn light_records(ctx: &RenderContext<'_>, set: &ShadowMapSet, layers: &Layers) -> Vec<SsssLight> {
    let mut records = vec![SsssLight::default(); ctx.lights.len().max(1)];
    for maps in set.lights() {
        let (Some(layer), false) = (layers.of_light[maps.light], maps.frustums.is_empty()) else {
            continue;
        };
        let scale = maps.scale();
        records[maps.light] = SsssLight {
            first_layer: maps.first_layer,
            layer_count: maps.frustums.len() as u32,
            layer,
            perspective: u32::from(scale.perspective),
            near: scale.near,
            far: scale.far,
            texel_scale: scale.texel_scale,
            size: light_size(&ctx.lights[maps.light]),
            scissor: UVec4::from_array(maps.scissor),
            kept_faces: (0..maps.frustums.len() as u32)
                .filter(|&k| set.is_kept(maps.first_layer + k))
                .fold(0, |bits, k| bits | 1 << k),
        };
    }
    records
}

/// Which of a light's map layers can shadow what the camera sees.
fn layer_visible(layers: &Layers, view_proj: Mat4, light: usize, frustum: Mat4) -> bool {
    layers.of_light[light].is_some() && frusta_intersect(frustum, view_proj)
}

impl ShadowTechnique for Ssss {
    fn resources(&self) -> Vec<ResourceInfo> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let mut out = Vec::new();
        if let Some(maps) = gpu.maps.maps() {
            out.push(ResourceInfo::texture("shadow maps", &maps.texture, true));
        }
        if let Some(maps) = gpu.translucent.as_ref().and_then(|t| t.maps()) {
            out.push(ResourceInfo::texture(
                "translucency maps",
                &maps.texture,
                false,
            ));
        }
        out.extend(gpu.targets.resources());
        out.extend(gpu.min_filter.resources());
        out
    }

    fn assign_slots(&self, request: &SlotRequest<'_>) -> TechniqueResult<SlotAssignment> {
        let layers = self.layers_for(request)?;
        // Culled lights light no visible pixel: any slot will do.
        let slots = layers.of_light.iter().map(|l| l.unwrap_or(0)).collect();
        Ok(SlotAssignment::from_slots(slots))
    }

    fn slots_follow_camera(&self) -> bool {
        true
    }

    fn writes_transmittance(&self, scene: &Scene) -> bool {
        scene.has_translucent_casters()
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        self.gpu
            .prepare(changes.scene, || Gpu::new(ctx, &self.params))?;
        let aspect = ctx.size.x as f32 / ctx.size.y as f32;
        let request = SlotRequest {
            lights: ctx.lights,
            camera: ctx.camera,
            aspect,
        };
        self.layers = self.layers_for(&request)?;
        // The host colours with the same function: its slots must be these layers.
        for (light, layer) in self.layers.of_light.iter().enumerate() {
            if let Some(layer) = layer
                && ctx.visibility.slots.slot(light) != (layer / 4, layer % 4)
            {
                return Err(TechniqueError::Other(format!(
                    "ssss: light {light} is in layer {layer} but writes visibility slot {:?}",
                    ctx.visibility.slots.slot(light)
                )));
            }
        }
        let batches = batches(self.layers.count, self.batch_layers());
        let gpu = self.gpu.get_mut()?;
        let min_filter = self.params.estimate == Estimate::MinFilter;
        let p = &self.params;
        gpu.maps.prepare(ctx, changes, p.map_size, p.stable_fit);
        let view_proj = ctx.frame.matrices.view_proj;
        if p.cull_maps {
            let layers = &self.layers;
            gpu.maps
                .cull(|l, k| layer_visible(layers, view_proj, l.light, l.frustums[k].view_proj));
        } else {
            let layers = &self.layers;
            gpu.maps.cull(|l, _| layers.of_light[l.light].is_some());
        }
        if let Some(translucent) = &mut gpu.translucent {
            translucent.prepare(ctx, &gpu.maps);
        }
        if min_filter {
            gpu.min_filter.prepare(ctx, &gpu.maps)?;
        }
        // Batches run one after another through the same targets.
        let specs = target_specs(batches[0].1, gpu.translucent.is_some(), p.half_resolution);
        gpu.targets.respec_all(specs);
        gpu.targets.prepare(ctx);
        // The data buffers: a batch's settings, then one record per scene light (lights of
        // other batches have no layers there).
        let records = light_records(ctx, &gpu.maps, &self.layers);
        // Exactly the size of the data: the shaders take the light count from it.
        let size = (LIGHTS_OFFSET + LIGHT_STRIDE * records.len()) as u64;
        if gpu.data.len() != batches.len() || gpu.data[0].size() != size {
            gpu.data = (0..batches.len())
                .map(|b| {
                    ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(&format!("ssss data (batch {b})")),
                        size,
                        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    })
                })
                .collect();
        }
        for (&batch, data) in batches.iter().zip(&gpu.data) {
            let bytes = batch_data(settings(p, batch, ctx), &records, batch);
            ctx.gpu.queue.write_buffer(data, 0, &bytes);
        }
        let translucency = gpu::translucency_view(gpu.translucent.as_ref(), &gpu.placeholder.1);
        let min_maps = match gpu.min_filter.view() {
            Some(view) if min_filter => view,
            _ => &gpu.placeholder.1,
        };
        gpu.passes
            .bind(ctx, &gpu.data, &gpu.targets, translucency, min_maps)?;
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let gpu = self.gpu.get_mut()?;
        gpu.maps.record(ctx, recorder, MAP_PASS)?;
        if let Some(translucent) = &gpu.translucent {
            translucent.record(ctx, recorder, &gpu.maps, TRANSLUCENT_PASS)?;
        }
        if self.params.estimate == Estimate::MinFilter {
            gpu.min_filter.record(ctx, recorder)?;
        }
        let debug = ctx
            .debug_view
            .and_then(|name| DEBUG_VIEWS.iter().position(|v| v.0 == name));
        if let (Some(view), Some(data)) = (debug, gpu.data.last()) {
            let code = gpu.debug_codes.code(view);
            ctx.gpu
                .queue
                .write_buffer(data, debug_mode_offset(), &code.to_ne_bytes());
        }
        let half = self.params.half_resolution;
        gpu.passes
            .record(ctx, recorder, &gpu.maps, half, debug.is_some())
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let gpu = self.gpu.built()?;
        if resource == "shadow maps" {
            return gpu.maps.debug_image(self.params.debug_light);
        }
        gpu.targets.debug_view(resource)
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        // The depth bias lives in the depth pipeline (`flags(rebuild)`); everything else
        // reaches the shaders through the data buffer at the next `prepare`.
        Ok(self.params.update(values)?)
    }

    fn counters(&self) -> Vec<(String, f64)> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let mut counters = gpu.maps.counters();
        let kept = gpu
            .maps
            .lights()
            .iter()
            .flat_map(|l| (0..l.frustums.len() as u32).map(move |k| l.first_layer + k))
            .filter(|&layer| gpu.maps.is_kept(layer))
            .count();
        let shadowed = self.layers.of_light.iter().filter(|l| l.is_some()).count();
        counters.push(("map layers kept".into(), kept as f64));
        counters.push(("screen-space layers".into(), f64::from(self.layers.count)));
        counters.push(("lights on screen".into(), shadowed as f64));
        counters
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = SsssParams::from_values(values)?;
    Ok(Box::new(Ssss {
        params,
        gpu: LazyGpu::default(),
        layers: Layers::default(),
    }))
}

zoo_host::shader_params_module!("ssss/params.wgsl", SsssParams);

zoo_host::register_technique! {
    id: "ssss",
    name: "Layered screen-space soft shadows",
    description: "Shadow maps for many lights, penumbrae estimated per light and blurred in screen space, one layer per group of lights that never overlap on screen; coloured translucent shadows",
    source: "seed 001 (Tamás and Heisenberger, practical SSSS; Gumbau et al. 2010)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    required_downlevel: || wgpu::DownlevelFlags::COMPUTE_SHADERS,
    params: SsssParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::layout::wgsl_struct;

    fn shader(name: &str) -> String {
        zoo_host::ShaderLibrary::embedded()
            .compose(name)
            .unwrap()
            .source
    }

    #[test]
    fn the_light_records_start_where_the_shaders_read_them() {
        let data = wgsl_struct(&shader("ssss/penumbra.wgsl"), "SsssData").unwrap();
        let lights = data.members.iter().find(|(name, _)| name == "lights");
        assert_eq!(lights.map(|m| m.1 as usize), Some(LIGHTS_OFFSET));
    }

    #[test]
    fn the_min_block_matches_the_shader() {
        let source = shader("ssss/min_depth.wgsl");
        let block = zoo_host::gpu::layout::wgsl_integer_constant(&source, "MIN_BLOCK");
        assert_eq!(block, Ok(i64::from(gpu::MIN_BLOCK)));
        // Min texels never straddle two atlas tiles.
        assert!(zoo_shadow_maps::atlas_pages::TILE_ALIGN.is_multiple_of(gpu::MIN_BLOCK));
    }

    #[test]
    fn every_debug_view_has_a_shader_constant() {
        let names = DEBUG_VIEWS.map(|v| v.1);
        let codes = ChoiceCodes::read(&shader("ssss/debug.wgsl"), "DEBUG", &names).unwrap();
        let mut values: Vec<u32> = (0..names.len()).map(|i| codes.code(i)).collect();
        values.sort();
        values.dedup();
        assert_eq!(values.len(), DEBUG_VIEWS.len());
    }

    #[test]
    fn layers_past_the_cap_run_in_batches() {
        let light = |x: f32| zoo_host::Light {
            kind: LightKind::Point,
            position: zoo_host::glam::Vec3::new(x, 1.0, 0.0),
            direction: zoo_host::glam::Vec3::NEG_Y,
            radiance: zoo_host::glam::Vec3::ONE,
            range: 5.0,
            spot_angle: 0.5,
            spot_softness: 0.1,
            radius: 0.1,
        };
        // Ten lights that all overlap on screen: ten layers, more than a batch of four.
        let lights: Vec<_> = (0..10).map(|i| light(i as f32 * 0.2)).collect();
        let camera = zoo_host::Camera {
            position: zoo_host::glam::Vec3::new(0.0, 5.0, 10.0),
            target: zoo_host::glam::Vec3::ZERO,
            fov_y: 1.0,
            near: 0.1,
            far: 100.0,
        };
        let request = SlotRequest {
            lights: &lights,
            camera: &camera,
            aspect: 1.0,
        };
        let mut values = zoo_host::params::defaults(&SsssParams::schema());
        values.insert("max_layers".into(), zoo_host::ParamValue::Int(4));
        let technique = create_for_test(&values);
        let slots = technique.assign_slots(&request).unwrap();
        assert_eq!(slots.slot_count(), 10, "every light keeps its own slot");
        assert_eq!(
            batches(10, technique.batch_layers()),
            [(0, 4), (4, 4), (8, 2)]
        );
        assert_eq!(batches(64, 64), [(0, 64)]);
        assert_eq!(batches(0, 64), [(0, 1)], "one batch even without lights");
        // A batch's records count layers from its first; other batches' lights have none.
        let record = |layer| SsssLight {
            layer,
            layer_count: 6,
            ..SsssLight::default()
        };
        let records: Vec<SsssLight> = (0..10).map(record).collect();
        let bytes = batch_data(Settings::default(), &records, (4, 4));
        assert_eq!(bytes.len(), LIGHTS_OFFSET + LIGHT_STRIDE * records.len());
        let batch = batch_records(&records, (4, 4));
        let layers: Vec<(u32, u32)> = batch.iter().map(|r| (r.layer, r.layer_count)).collect();
        let expected: Vec<(u32, u32)> = (0..10)
            .map(|l| match l {
                4..8 => (l - 4, 6),
                _ => (l, 0),
            })
            .collect();
        assert_eq!(layers, expected);
    }

    fn create_for_test(values: &ParamValues) -> Ssss {
        Ssss {
            params: SsssParams::from_values(values).unwrap(),
            gpu: LazyGpu::default(),
            layers: Layers::default(),
        }
    }
}
