//! A technique's shadow maps for the current lights and camera: the layer plan, the map
//! arrays and the depth pass that fills them, kept up to date from one call per frame.

use zoo_host::gpu::PassRecorder;
use zoo_host::technique::{DebugImage, ViewMapping};
use zoo_host::{Changes, RenderContext, TechniqueResult, wgpu};

use crate::depth::{ColorOutput, DepthPass, DepthState};
use crate::light_space::Aabb;
use crate::lookup::LookupGroup;
use crate::maps::{MAP_FORMAT, MapArray, effective_resolution};
use crate::planning::{
    LayerPlan, LightMaps, PlanInputs, StandardLayers, layers_needed_with, object_bounds, plan_with,
};

/// The name of the pass that renders `layer` of a light's layers: `"{base}: light {l}"` for
/// a light with one layer, else `"{base}: light {l} {word} {layer}"` with the plan's word for
/// its layers ("face" for cube faces, "split" for cascades).
pub fn layer_pass_name(base: &str, maps: &LightMaps, layer: usize) -> String {
    let light = maps.light;
    match maps.frustums.len() {
        1 => format!("{base}: light {light}"),
        _ => format!("{base}: light {light} {} {layer}", maps.layer_word),
    }
}

/// Shadow maps of every light: depth maps, or colour maps (moments, fluxes) with a one-layer
/// depth scratch when built with a [`ColorOutput`].
pub struct ShadowMapSet {
    label: String,
    depth_pass: DepthPass,
    color_format: Option<wgpu::TextureFormat>,
    lookup: LookupGroup,
    objects: Vec<Aabb>,
    casters: Vec<Aabb>,
    lights: Vec<LightMaps>,
    depth: Option<MapArray>,
    color: Option<MapArray>,
    fitted: bool,
    /// Per layer: whether [`Self::record`] renders it (all, unless [`Self::cull`] says not).
    kept: Vec<bool>,
}

impl ShadowMapSet {
    /// Builds the depth pass (`label` names it and the maps).
    pub fn new(
        ctx: &RenderContext<'_>,
        label: &str,
        state: DepthState,
        color: Option<ColorOutput<'_>>,
    ) -> TechniqueResult<ShadowMapSet> {
        if let Some(color) = color {
            let features = ctx.gpu.adapter.get_texture_format_features(color.format);
            let needed = wgpu::TextureFormatFeatureFlags::FILTERABLE;
            let usages =
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
            if !features.flags.contains(needed) || !features.allowed_usages.contains(usages) {
                return Err(zoo_host::TechniqueError::Other(format!(
                    "{label}: this device cannot render into and filter {:?} maps",
                    color.format
                )));
            }
        }
        let lookup = LookupGroup::new(&ctx.gpu.device, label, color.is_none());
        Ok(ShadowMapSet {
            label: label.to_string(),
            depth_pass: DepthPass::new(ctx, label, state, color)?,
            color_format: color.map(|c| c.format),
            lookup,
            objects: Vec::new(),
            casters: Vec::new(),
            lights: Vec::new(),
            depth: None,
            color: None,
            fitted: false,
            kept: Vec::new(),
        })
    }

    /// Replans the layers when the scene or the lights change (new maps when their number or
    /// `resolution` changes) and refits the frusta on any change (directional maps follow the
    /// camera; with `stable` they keep a stable fit). Returns whether the maps or the camera
    /// buffer were replaced, so bind groups over them must be rebuilt.
    pub fn prepare(
        &mut self,
        ctx: &RenderContext<'_>,
        changes: Changes,
        resolution: u32,
        stable: bool,
    ) -> bool {
        self.prepare_with(ctx, changes, resolution, stable, &StandardLayers)
    }

    /// As [`Self::prepare`] with the technique's own layer plan.
    pub fn prepare_with(
        &mut self,
        ctx: &RenderContext<'_>,
        changes: Changes,
        resolution: u32,
        stable: bool,
        layout: &dyn LayerPlan,
    ) -> bool {
        self.update_bounds(ctx, changes);
        let replanned = self.plan_maps(ctx, resolution, layout);
        if !replanned && self.fitted && changes == Changes::default() {
            return false;
        }
        let resolution = self.resolution();
        self.lights = plan_with(
            &PlanInputs {
                lights: ctx.lights,
                camera: ctx.camera,
                view_proj: ctx.frame.matrices.view_proj,
                size: ctx.size,
                objects: &self.objects,
                casters: &self.casters,
                resolution,
                stable,
            },
            layout,
        );
        self.fitted = true;
        self.kept.clear();
        let replaced = self.depth_pass.write_cameras(ctx.gpu, &self.lights) || replanned;
        let lookup = &mut self.lookup;
        let maps = self.color.as_ref().or(self.depth.as_ref());
        if let (Some(maps), Some(cameras)) = (maps, self.depth_pass.cameras())
            && (replaced || lookup.group.is_none())
        {
            lookup.bind(&ctx.gpu.device, maps, cameras);
        }
        replaced
    }

    /// The layout of [`Self::lookup_group`] (see [`crate::lookup`]), for the lookup's
    /// pipeline layout.
    pub fn lookup_layout(&self) -> &wgpu::BindGroupLayout {
        &self.lookup.layout
    }

    /// Once prepared: the lookup's bind group over the current maps and layer cameras.
    pub fn lookup_group(&self) -> Option<&wgpu::BindGroup> {
        self.lookup.group.as_ref()
    }

    fn update_bounds(&mut self, ctx: &RenderContext<'_>, changes: Changes) {
        if changes.scene || !self.fitted {
            self.objects = object_bounds(ctx.scene, false);
            self.casters = object_bounds(ctx.scene, true);
        }
    }

    /// World bounds of every object and of each caster (for fitting; current after
    /// [`Self::prepare`]).
    pub fn bounds(&self) -> (&[Aabb], &[Aabb]) {
        (&self.objects, &self.casters)
    }

    /// (Re)creates the maps when the layer count or the resolution changes.
    fn plan_maps(
        &mut self,
        ctx: &RenderContext<'_>,
        requested: u32,
        layout: &dyn LayerPlan,
    ) -> bool {
        let layers = layers_needed_with(ctx.lights, layout);
        let device_max = ctx.gpu.device.limits().max_texture_dimension_2d;
        let format = self.color_format.unwrap_or(MAP_FORMAT);
        let bytes = u64::from(format.block_copy_size(None).unwrap_or(4));
        let (resolution, note) = effective_resolution(requested, device_max, layers, bytes);
        let current = self.maps().map(|m| (m.resolution, m.layers));
        if current == Some((resolution, layers)) {
            return false;
        }
        if let Some(note) = note {
            zoo_host::log::warn!("{}: {note}", self.label);
        }
        let (gpu, label) = (ctx.gpu, &self.label);
        self.color = self
            .color_format
            .map(|format| MapArray::with_format(gpu, label, resolution, layers, format));
        let depth_layers = if self.color.is_some() { 1 } else { layers };
        let depth_label = format!("{label} depth");
        self.depth = Some(MapArray::new(gpu, &depth_label, resolution, depth_layers));
        true
    }

    /// Every light's layers, in light order.
    pub fn lights(&self) -> &[LightMaps] {
        &self.lights
    }

    /// The light debug views show: light `wanted` when it has layers, else the first light
    /// that has.
    pub fn debug_light(&self, wanted: u32) -> Option<&LightMaps> {
        let shadowed = || self.lights.iter().filter(|l| !l.frustums.is_empty());
        shadowed()
            .find(|l| l.light as u32 == wanted)
            .or_else(|| shadowed().next())
    }

    /// The `shadow maps` debug image: the first layer of [`Self::debug_light`]`(wanted)`
    /// (depth maps shown as depth, colour maps as colour).
    pub fn debug_image(&self, wanted: u32) -> Option<DebugImage<'_>> {
        let light = self.debug_light(wanted)?;
        let mapping = match self.color {
            Some(_) => ViewMapping::Color { min: 0.0, max: 1.0 },
            None => ViewMapping::Depth { min: 0.0, max: 1.0 },
        };
        Some(DebugImage {
            view: &self.maps()?.layer_views[light.first_layer as usize],
            mapping,
        })
    }

    /// Workload counters: map layers in use and their resolution.
    pub fn counters(&self) -> Vec<(String, f64)> {
        let layers: usize = self.lights.iter().map(|l| l.frustums.len()).sum();
        vec![
            ("map layers".into(), layers as f64),
            ("map resolution".into(), self.resolution() as f64),
        ]
    }

    /// The maps lookups read (the colour maps when there are any, else the depth maps).
    pub fn maps(&self) -> Option<&MapArray> {
        self.color.as_ref().or(self.depth.as_ref())
    }

    /// Texels per side of the maps (0 before the first [`Self::prepare`]).
    pub fn resolution(&self) -> u32 {
        self.maps().map_or(0, |m| m.resolution)
    }

    /// Every layer's `LayerCamera` in 256-byte slots (`shadow-maps/layers.wgsl`).
    pub fn cameras(&self) -> Option<&wgpu::Buffer> {
        self.depth_pass.cameras()
    }

    /// Renders only the layers `keep(light_maps, layer within the light)` accepts, until the
    /// next [`Self::prepare`] (which keeps every layer again): for techniques that cull the
    /// maps of lights and cube faces the view cannot see.
    pub fn cull(&mut self, keep: impl Fn(&LightMaps, usize) -> bool) {
        self.kept = self
            .lights
            .iter()
            .flat_map(|l| (0..l.frustums.len()).map(move |k| (l, k)))
            .map(|(l, k)| keep(l, k))
            .collect();
    }

    /// Whether [`Self::record`] renders `layer`.
    pub fn is_kept(&self, layer: u32) -> bool {
        self.kept.get(layer as usize).copied().unwrap_or(true)
    }

    /// The depth maps (the depth-test scratch layer when the set has colour maps).
    pub fn depth_maps(&self) -> Option<&MapArray> {
        self.depth.as_ref()
    }

    /// Renders every kept layer, one pass each named by [`layer_pass_name`] with `base`.
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        base: &str,
    ) -> TechniqueResult {
        let depth = self
            .depth
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        let name = |l: &LightMaps, k| layer_pass_name(base, l, k);
        let keep = |layer| self.is_kept(layer);
        let color = self.color.as_ref();
        (self.depth_pass).record(ctx, recorder, color, depth, &self.lights, name, &keep)
    }
}
