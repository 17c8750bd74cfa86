//! The GPU side of the layered soft shadows: the declarations of the layered targets and the
//! compute passes (penumbra, two blur passes, debug views) with their bind groups.

use zoo_host::glam::{UVec2, UVec4};
use zoo_host::gpu::gpu_struct::round_up;
use zoo_host::gpu::{GpuStruct, GpuType};
use zoo_host::kit::{NamedTextures, SharedGroup, Stage, StageBindGroup, TextureSize, TextureSpec};
use zoo_host::params::shader::padded_words;
use zoo_host::prelude::*;
use zoo_host::technique::{ResourceInfo, ViewMapping};
use zoo_shadow_maps::{ShadowMapSet, TranslucentPass};

use crate::SsssParams;

/// Words of the parameters the shaders read (`SsssParams` in the generated
/// `ssss/params.wgsl`).
const PARAM_WORDS: usize = padded_words(<SsssParams as TechniqueParams>::SHADER_FIELDS);

/// The `flags(shader)` parameters as the shaders read them: `SsssParams` in the generated
/// `ssss/params.wgsl`, one word each, padded to 16 bytes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ShaderParams(pub [u32; PARAM_WORDS]);

impl GpuType for ShaderParams {
    const ALIGN: usize = 4;
    const SIZE: usize = 4 * PARAM_WORDS;
    fn wgsl_type() -> String {
        "SsssParams".to_string()
    }
    fn imports() -> Vec<&'static str> {
        vec!["ssss/params.wgsl"]
    }
    fn write(&self, out: &mut [u8]) {
        self.0.write(out);
    }
}

zoo_host::gpu_struct! {
    "ssss/settings.wgsl" =>
    /// The settings every pass reads, first in the data buffer (`ssss/data.wgsl`): the
    /// `flags(shader)` parameters, then what each frame derives.
    #[derive(Debug, Clone, Copy, Default)]
    pub struct Settings {
        /// The plugin's parameters the shaders read (generated from their declaration, with
        /// the `ESTIMATE_*` constants of its `estimate` choice).
        pub params: ShaderParams,
        /// Layers in use.
        pub layer_count: u32,
        /// Blur taps on each side of the centre (kernel = 2 * half_taps + 1).
        pub half_taps: u32,
        /// 1 when the scene has translucent casters.
        pub translucent: u32,
        /// Pixels per world unit at unit view depth: proj[1][1] * height / 2.
        pub pixel_scale: f32,
        /// What the debug pass shows (`DEBUG_*` in `ssss/debug.wgsl`).
        pub debug_mode: u32,
        /// The batch's first layer among all (a multiple of four): the passes run once per
        /// batch of at most 64 layers, each over its own layers 0..layer_count.
        pub layer_base: u32,
    }
}

zoo_host::gpu_struct! {
    "ssss/ssss_light.wgsl" =>
    /// One scene light's maps and layer in the batch (`ssss/data.wgsl`; indexed like the
    /// scene's lights).
    #[derive(Debug, Clone, Copy, Default)]
    pub struct SsssLight {
        pub first_layer: u32,
        /// 0 when the light is culled, not shadowed or in another batch; 1 or 6 (cube faces).
        pub layer_count: u32,
        /// Its screen-space layer in the batch (visibility slot layer_base + layer).
        pub layer: u32,
        pub perspective: u32,
        pub near: f32,
        pub far: f32,
        /// World size of a texel: per unit of distance along the face axis (perspective) or
        /// absolute (orthographic).
        pub texel_scale: f32,
        /// Radius (point, spot) or tangent of the angular radius (directional).
        pub size: f32,
        /// Screen rectangle its influence can reach: x, y, width, height in pixels.
        pub scissor: UVec4,
        /// Bit k set when its layer first_layer + k was rendered this frame (culled layers
        /// hold stale depths and are never read).
        pub kept_faces: u32,
    }
}

/// Where the light records start in the data buffer: after the settings, at their alignment.
pub const LIGHTS_OFFSET: usize = round_up(<Settings as GpuType>::SIZE, SsssLight::ALIGN);

/// Bytes of one light record in the data buffer.
pub const LIGHT_STRIDE: usize = round_up(<SsssLight as GpuType>::SIZE, SsssLight::ALIGN);

/// Byte offset of `debug_mode` in the data buffer.
pub fn debug_mode_offset() -> u64 {
    let members = <Settings as GpuStruct>::members();
    let member = members.iter().find(|m| m.name == "debug_mode");
    member.expect("a member of the settings").offset as u64
}

/// Blur sigma in pixels, four layers per texel.
pub const PENUMBRA: &str = "layered penumbra";
/// Occluded then tinted bits, 32 layers per texel.
pub const BITS: &str = "layered bits";
/// Tint colour per layer (translucent scenes; one dummy layer otherwise).
pub const TINTS: &str = "layered tints";
/// Each blur pass's output on the blur grid: occlusion, four layers per texel, and the colour
/// that arrives per layer (translucent scenes).
pub const BLURRED: [[&str; 2]; 2] = [
    ["blurred occlusion 1", "blurred light 1"],
    ["blurred occlusion 2", "blurred light 2"],
];
/// The views the debug pass draws into its one image: each view's name and the name of its
/// `DEBUG_*` constant in `ssss/debug.wgsl`.
pub const DEBUG_VIEWS: [(&str, &str); 5] = [
    ("layer assignment", "Layers"),
    ("penumbra sizes", "Penumbra"),
    ("hard shadows", "Hard"),
    ("blurred shadows", "Blurred"),
    ("translucency", "Translucency"),
];

/// Every screen-size target, for `layer_count` layers, with colour layers when `translucent`
/// and the blur grid at half size when `half_resolution`.
pub fn target_specs(
    layer_count: u32,
    translucent: bool,
    half_resolution: bool,
) -> Vec<TextureSpec> {
    use wgpu::TextureFormat as F;
    let groups = layer_count.div_ceil(4);
    let words = layer_count.div_ceil(32);
    let colored = if translucent { layer_count } else { 1 };
    let grid = TextureSize::Screen {
        divisor: if half_resolution { 2 } else { 1 },
    };
    let layered = |name, size, layers, format| TextureSpec {
        name,
        size,
        layers,
        array: true,
        format,
        usage: wgpu::TextureUsages::STORAGE_BINDING,
        view: None,
        aliases: Vec::new(),
    };
    let screen = TextureSize::SCREEN;
    let mut specs = vec![
        debug_spec(),
        layered(PENUMBRA, screen, groups, F::Rgba16Float),
        layered(BITS, screen, 2 * words, F::R32Uint),
        layered(TINTS, screen, colored, F::Rgba16Float),
    ];
    for [occlusion, light] in BLURRED {
        specs.push(layered(occlusion, grid, groups, F::Rgba16Float));
        specs.push(layered(light, grid, colored, F::Rgba16Float));
    }
    specs
}

/// The debug pass's image, shown under the name of each of [`DEBUG_VIEWS`].
fn debug_spec() -> TextureSpec {
    let shown = ViewMapping::Color { min: 0.0, max: 1.0 };
    let [(first, _), rest @ ..] = DEBUG_VIEWS;
    TextureSpec {
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::STORAGE_BINDING,
        aliases: rest.iter().map(|(name, _)| (*name, shown)).collect(),
        ..TextureSpec::screen_target(first, wgpu::TextureFormat::Rgba8Unorm, Some(shown))
    }
}

/// The compute passes after the maps and their current bind groups.
pub struct Passes {
    penumbra: Stage,
    blur_first: Stage,
    blur_second: Stage,
    resolve: Stage,
    debug: Stage,
    /// Per batch of layers: the groups of the penumbra, blur, resolve and debug passes.
    groups: Vec<[StageBindGroup; 5]>,
}

/// The penumbra pass: hard shadows, penumbra sizes and tints of every light.
pub const PENUMBRA_PASS: &str = "SSSS penumbra";
/// The first separable blur pass.
pub const BLUR_FIRST_PASS: &str = "SSSS blur 1";
/// The second separable blur pass.
pub const BLUR_SECOND_PASS: &str = "SSSS blur 2";
/// The pass that writes the host's visibility and transmittance slots.
pub const RESOLVE_PASS: &str = "SSSS resolve";
/// The debug-view pass, recorded only while one of its views is shown.
pub const DEBUG_PASS: &str = "SSSS debug view";

impl Passes {
    /// Builds every pass's pipeline (their groups as the shaders declare them); the penumbra
    /// pass reads `maps` through their lookup group.
    pub fn new(ctx: &RenderContext<'_>, maps: &ShadowMapSet) -> TechniqueResult<Passes> {
        let stage = |shader, entry| Stage::compute(shader, entry).build(ctx);
        Ok(Passes {
            penumbra: Stage::compute("ssss/penumbra.wgsl", "cs_penumbra")
                .shared(&[&maps.lookup()])
                .build(ctx)?,
            blur_first: stage("ssss/blur_first.wgsl", "cs_blur_first")?,
            blur_second: stage("ssss/blur_second.wgsl", "cs_blur_second")?,
            resolve: stage("ssss/resolve.wgsl", "cs_resolve")?,
            debug: stage("ssss/debug.wgsl", "cs_debug")?,
            groups: Vec::new(),
        })
    }

    /// Rebuilds the bind groups over each batch's data, the targets, maps and host slots.
    pub fn bind(
        &mut self,
        ctx: &RenderContext<'_>,
        data: &[wgpu::Buffer],
        targets: &NamedTextures,
        translucency: &wgpu::TextureView,
        min_maps: &wgpu::TextureView,
    ) -> TechniqueResult {
        self.groups = (data.iter())
            .map(|data| self.batch_groups(ctx, data, targets, translucency, min_maps))
            .collect::<TechniqueResult<_>>()?;
        Ok(())
    }

    fn batch_groups(
        &self,
        ctx: &RenderContext<'_>,
        data: &wgpu::Buffer,
        targets: &NamedTextures,
        translucency: &wgpu::TextureView,
        min_maps: &wgpu::TextureView,
    ) -> TechniqueResult<[StageBindGroup; 5]> {
        let view = wgpu::BindingResource::TextureView;
        let data = || ("data", data.as_entire_binding());
        let target = |name| targets.view(name).expect("made in prepare");
        let t = |name| view(target(name));
        let [[occlusion_1, light_1], [occlusion_2, light_2]] = BLURRED.map(|pass| pass.map(target));
        let penumbra = self.penumbra.bind(
            ctx,
            "ssss penumbra group",
            &[
                data(),
                ("penumbra_out", t(PENUMBRA)),
                ("bits_out", t(BITS)),
                ("tint_out", t(TINTS)),
                ("translucency", view(translucency)),
                ("min_maps", view(min_maps)),
            ],
        )?;
        let blur_first = self.blur_first.bind(
            ctx,
            "ssss blur 1 group",
            &[
                data(),
                ("penumbra", t(PENUMBRA)),
                ("bits", t(BITS)),
                ("tints", t(TINTS)),
                ("occlusion_out", view(occlusion_1)),
                ("light_out", view(light_1)),
            ],
        )?;
        let blur_second = self.blur_second.bind(
            ctx,
            "ssss blur 2 group",
            &[
                data(),
                ("penumbra", t(PENUMBRA)),
                ("occlusion_in", view(occlusion_1)),
                ("light_in", view(light_1)),
                ("occlusion_out", view(occlusion_2)),
                ("light_out", view(light_2)),
            ],
        )?;
        let resolve = self.resolve.bind(
            ctx,
            "ssss resolve group",
            &[
                data(),
                ("penumbra", t(PENUMBRA)),
                ("bits", t(BITS)),
                ("tints", t(TINTS)),
                ("occlusion_in", view(occlusion_2)),
                ("light_in", view(light_2)),
                ("visibility_out", view(&ctx.visibility.array_view)),
                ("transmittance_out", view(&ctx.transmittance.array_view)),
            ],
        )?;
        let debug = self.debug.bind(
            ctx,
            "ssss debug group",
            &[
                data(),
                ("penumbra", t(PENUMBRA)),
                ("bits", t(BITS)),
                ("visibility", view(&ctx.visibility.array_view)),
                ("transmittance", view(&ctx.transmittance.array_view)),
                ("image", t(DEBUG_VIEWS[0].0)),
            ],
        )?;
        Ok([penumbra, blur_first, blur_second, resolve, debug])
    }

    /// Records, for each batch of layers, the penumbra pass, both blur passes (on the
    /// half-resolution grid when `half_resolution`) and the resolve pass; then the debug pass
    /// when `debug` (over the last batch's layers).
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        maps: &ShadowMapSet,
        half_resolution: bool,
        debug: bool,
    ) -> TechniqueResult {
        if self.groups.is_empty() {
            return Err(TechniqueError::not_prepared());
        }
        let lookup = maps.lookup();
        let full = ctx.size;
        let grid = if half_resolution {
            ctx.size.map(|side| side.div_ceil(2))
        } else {
            full
        };
        let stages = [
            (
                PENUMBRA_PASS,
                &self.penumbra,
                Some(&lookup as &dyn SharedGroup),
                full,
            ),
            (BLUR_FIRST_PASS, &self.blur_first, None, grid),
            (BLUR_SECOND_PASS, &self.blur_second, None, grid),
            (RESOLVE_PASS, &self.resolve, None, full),
            (DEBUG_PASS, &self.debug, None, full),
        ];
        let batches = self.groups.len();
        for (b, groups) in self.groups.iter().enumerate() {
            for (k, (name, stage, lookup, extent)) in stages.iter().enumerate() {
                if *name == DEBUG_PASS && !(debug && b + 1 == batches) {
                    continue;
                }
                let name = match (batches, *name) {
                    (1, _) | (_, DEBUG_PASS) => name.to_string(),
                    _ => format!("{name} (batch {b})"),
                };
                let shared: Vec<&dyn SharedGroup> = lookup.iter().copied().collect();
                let extent = [extent.x, extent.y, 1];
                stage.dispatch(ctx, recorder, &name, &[&groups[k]], &shared, extent)?;
            }
        }
        Ok(())
    }
}

/// Min-filtered depth maps: each texel the nearest depth of an 8 x 8 block of its map layer
/// (`ssss/min_depth.wgsl`), for the min-filter penumbra estimate.
pub struct MinFilter {
    stage: Stage,
    /// The min maps ([`MIN_MAPS`]), made at the first prepare.
    maps: NamedTextures,
    kept: Option<wgpu::Buffer>,
    kept_count: u32,
    group: Option<StageBindGroup>,
}

/// Full-resolution texels per min-map texel along each side (`MIN_BLOCK` in the shader).
pub const MIN_BLOCK: u32 = 8;
/// The pass that fills the min-filtered maps.
pub const MIN_FILTER_PASS: &str = "SSSS min filter";
/// The min-filtered maps: a layer per depth map layer.
pub const MIN_MAPS: &str = "min-filtered depth";

/// The min maps of `layers` layers of `resolution` texels a side.
fn min_maps_spec(resolution: u32, layers: u32) -> TextureSpec {
    TextureSpec {
        size: TextureSize::Fixed(UVec2::splat(resolution)),
        layers,
        array: true,
        usage: wgpu::TextureUsages::STORAGE_BINDING,
        ..TextureSpec::screen_target(MIN_MAPS, wgpu::TextureFormat::R32Float, None)
    }
}

impl MinFilter {
    /// Builds the reduction pipeline.
    pub fn new(ctx: &RenderContext<'_>) -> TechniqueResult<MinFilter> {
        let stage = Stage::compute("ssss/min_depth.wgsl", "cs_min_depth").build(ctx)?;
        Ok(MinFilter {
            stage,
            maps: NamedTextures::new("ssss", [min_maps_spec(1, 1)]),
            kept: None,
            kept_count: 0,
            group: None,
        })
    }

    /// Sizes the min maps to `set`'s depth pages and lists the pages it renders into.
    pub fn prepare(&mut self, ctx: &RenderContext<'_>, set: &ShadowMapSet) -> TechniqueResult {
        let Some(depth) = set.depth_maps() else {
            return Ok(());
        };
        let gpu = ctx.gpu;
        let resolution = depth.resolution.div_ceil(MIN_BLOCK).max(1);
        (self.maps).respec_all([min_maps_spec(resolution, depth.layers)]);
        self.maps.prepare(ctx);
        // The atlas pages that hold a rendered tile.
        let kept = set.kept_pages();
        let bytes: &[u8] = bytemuck::cast_slice(&kept);
        let size = (bytes.len() as u64).max(4);
        if self.kept.as_ref().is_none_or(|b| b.size() < size) {
            self.kept = Some(gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("ssss kept map layers"),
                size: size.next_power_of_two(),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let buffer = self.kept.as_ref().expect("created above");
        gpu.queue.write_buffer(buffer, 0, bytes);
        self.kept_count = kept.len() as u32;
        let maps = self.maps.view(MIN_MAPS).expect("made above");
        let kept = wgpu::BufferBinding {
            buffer,
            offset: 0,
            size: wgpu::BufferSize::new(u64::from(self.kept_count.max(1)) * 4),
        };
        let group = self.stage.bind(
            ctx,
            "ssss min filter group",
            &[
                (
                    "depth_maps",
                    wgpu::BindingResource::TextureView(&depth.array_view),
                ),
                ("min_maps", wgpu::BindingResource::TextureView(maps)),
                ("kept_layers", wgpu::BindingResource::Buffer(kept)),
            ],
        )?;
        self.group = Some(group);
        Ok(())
    }

    /// Whether [`Self::record`] records its pass (some layer is rendered).
    pub fn has_work(&self) -> bool {
        self.group.is_some() && self.kept_count > 0
    }

    /// The min maps' array view, once prepared.
    pub fn view(&self) -> Option<&wgpu::TextureView> {
        self.maps.view(MIN_MAPS)
    }

    /// The min maps, once prepared, for `resources()`.
    pub fn resources(&self) -> Vec<ResourceInfo> {
        self.maps.resources()
    }

    /// Fills the min maps of the rendered layers.
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let (Some(group), Some(maps)) = (&self.group, self.maps.texture(MIN_MAPS)) else {
            return Err(TechniqueError::not_prepared());
        };
        if self.kept_count == 0 {
            return Ok(());
        }
        let extent = [maps.width(), maps.height(), self.kept_count];
        (self.stage).dispatch(ctx, recorder, MIN_FILTER_PASS, &[group], &[], extent)
    }
}

/// The translucency maps' array view, or a white placeholder when the scene has none.
pub fn translucency_view<'a>(
    translucent: Option<&'a TranslucentPass>,
    placeholder: &'a wgpu::TextureView,
) -> &'a wgpu::TextureView {
    translucent
        .and_then(|t| t.maps())
        .map_or(placeholder, |m| &m.array_view)
}
