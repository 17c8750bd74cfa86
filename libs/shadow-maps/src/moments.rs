//! Moment shadow maps as one machine: each light's casters store moments of their light depth
//! in a filterable colour map, blurred by a separable Gaussian, and a full-screen lookup per
//! light turns the filtered moments into visibility. A method (VSM, ESM, EVSM, MSM) is one WGSL
//! file with two functions, called by the library's passes:
//!
//! ```text
//! fn moments(z: f32, spread: f32) -> vec4<f32>            // depth pass: what a texel stores
//! fn moment_visibility(m: vec4<f32>, z: f32, bias: f32) -> f32   // lookup: moments, receiver
//! ```
//!
//! `z` is `light_depth` (0 at the light, 1 at the far plane) and `spread` the depth's variance
//! over the texel. A method's moments of the far plane are 1 in every channel, so the maps
//! clear to white. The lookup (`shadow-maps/moments_lookup.wgsl`) reads the method's settings
//! from `MomentLight` and applies the light-bleeding reduction to every method alike.

use zoo_host::kit::{FullscreenLightPass, SharedGroup};
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};

use crate::{ColorOutput, DepthState, LayerBlur, MapHeader, ShadowMapSet};

const STORE_SHADER: &str = "shadow-maps/moments_store.wgsl";
const LOOKUP_SHADER: &str = "shadow-maps/moments_lookup.wgsl";
const STORE_ENTRY: &str = "@fragment fn fs_moments(in: DepthVertex) -> @location(0) vec4<u32> { return bitcast<vec4<u32>>(store_moments(in)); }
@fragment fn fs_moments_masked(in: MaskedVertex) -> @location(0) vec4<u32> { let m = store_moments(to_depth_vertex(in)); if !covered(in.object, in.uv) { discard; } return bitcast<vec4<u32>>(m); }";
const LOOKUP_ENTRY: &str = "@fragment fn fs_moment_lookup(in: FullscreenOut) -> @location(0) vec4<f32> { return moment_lookup(in); }";

/// The maps' clear value: 1.0 in every channel, as the bits the maps store (a clear of an
/// integer format takes the colour's values as integers).
const ONE_BITS: wgpu::Color = {
    let one = 1.0f32.to_bits() as f64;
    wgpu::Color {
        r: one,
        g: one,
        b: one,
        a: one,
    }
};

zoo_host::gpu_struct! {
    "shadow-maps/moment_light.wgsl" =>
    /// One light's lookup (`shadow-maps/moments_lookup.wgsl`).
    #[derive(Debug, Clone, Copy)]
    struct MomentLight {
        map: MapHeader,
        /// The method's bias in its own units (smallest variance, moment bias).
        bias: f32,
        bleeding_reduction: f32,
    }
}

/// A moment method: its WGSL and the map format it stores.
#[derive(Debug, Clone)]
pub struct MomentMethod {
    /// Label of maps, pipelines and passes ("VSM", "EVSM4").
    pub label: &'static str,
    /// The library shader with the method's `moments` and `moment_visibility`.
    pub shader: &'static str,
    /// WGSL composed before the method (constants generated from parameters, for example);
    /// a change needs a new [`MomentMaps`].
    pub prelude: String,
    pub format: wgpu::TextureFormat,
}

/// What a frame's lookups read of the technique's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MomentSettings {
    pub map_size: u32,
    pub stable_fit: bool,
    /// Gaussian taps on each side (0: bilinear filtering only).
    pub blur_radius: u32,
    /// Lookups move off the surface by this many texels.
    pub normal_offset: f32,
    /// The method's bias (smallest variance, moment bias), in its own units.
    pub bias: f32,
    /// Visibility below this becomes 0 and the rest is rescaled (0: off).
    pub bleeding_reduction: f32,
}

/// Maps, blur and lookup of a moment technique.
pub struct MomentMaps {
    label: &'static str,
    maps: ShadowMapSet,
    blur: LayerBlur,
    lookup: FullscreenLightPass<MomentLight>,
}

impl MomentMaps {
    /// Builds the passes of `method`.
    pub fn new(ctx: &RenderContext<'_>, method: &MomentMethod) -> TechniqueResult<MomentMaps> {
        // The library files hold no entry points (they call the method's functions), so each
        // stands as a shared module; the entry points are added here.
        let compose = |pass: &str, entry: &str| {
            format!(
                "{}\n#import \"{}\"\n#import \"{pass}\"\n{entry}\n",
                method.prelude, method.shader
            )
        };
        let store = compose(STORE_SHADER, STORE_ENTRY);
        let store_label = format!("{} depth pass", method.label);
        let output = ColorOutput {
            shader: &store_label,
            source: Some(&store),
            entry: "fs_moments",
            masked_entry: "fs_moments_masked",
            format: method.format,
            clear: ONE_BITS,
        };
        let label = format!("{} moments", method.label);
        let maps = ShadowMapSet::new(ctx, &label, DepthState::default(), Some(output))?;
        let lookup = FullscreenLightPass::from_source(
            ctx,
            &format!("{} lookup", method.label),
            &compose(LOOKUP_SHADER, LOOKUP_ENTRY),
            "fs_moment_lookup",
            &[&maps.lookup()],
        )?;
        Ok(MomentMaps {
            label: method.label,
            blur: LayerBlur::new(ctx, &format!("{} blur", method.label), method.format)?,
            maps,
            lookup,
        })
    }

    /// Fits and allocates the maps for this frame.
    pub fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes, s: &MomentSettings) {
        self.maps.prepare(ctx, changes, s.map_size, s.stable_fit);
    }

    /// Records the depth passes, the blur and the lookups.
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        s: &MomentSettings,
    ) -> TechniqueResult {
        let label = self.label;
        self.maps
            .record(ctx, recorder, &format!("{label} moments"))?;
        let Some(maps) = self.maps.maps() else {
            return Err(TechniqueError::not_prepared());
        };
        let lights = self.maps.lights();
        let blur = format!("{label} blur");
        let passes = self.maps.tile_passes();
        (self.blur).record(ctx, recorder, maps, &passes, s.blur_radius, &blur)?;
        let uniform = |light: usize| MomentLight {
            map: MapHeader::new(&lights[light], s.normal_offset),
            bias: s.bias,
            bleeding_reduction: s.bleeding_reduction,
        };
        let lookup = format!("{label} lookup");
        let shared = [&self.maps.lookup() as &dyn SharedGroup];
        (self.lookup).record_with(ctx, recorder, &lookup, uniform, &[], &shared)
    }

    /// The moment maps and layer cameras.
    pub fn resources(&self) -> Vec<ResourceInfo> {
        let moments =
            (self.maps.maps()).map(|m| ResourceInfo::texture("moments", &m.texture, true));
        let cameras =
            (self.maps.cameras()).map(|c| ResourceInfo::buffer("layer cameras", c, "LayerCamera"));
        moments.into_iter().chain(cameras).collect()
    }

    /// The first channel of the atlas page holding the first light's first layer, for
    /// resource `"moments"`.
    pub fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let page = self.maps.lights().first()?.tiles.first()?.page as usize;
        let view = &self.maps.maps()?.layer_views[page];
        let mapping = ViewMapping::FloatBits {
            channel: 0,
            min: 0.0,
            max: 1.0,
        };
        (resource == "moments").then_some(DebugImage { view, mapping })
    }

    /// The map set's counters.
    pub fn counters(&self) -> Vec<(String, f64)> {
        self.maps.counters()
    }

    /// The format the maps store.
    pub fn format(&self) -> Option<wgpu::TextureFormat> {
        self.maps.maps().map(|m| m.texture.format())
    }
}
