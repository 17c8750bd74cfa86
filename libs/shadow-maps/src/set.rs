//! A technique's shadow maps for the current lights and camera: the layer plan, the map
//! arrays and the depth pass that fills them, kept up to date from one call per frame.

use zoo_host::gpu::PassRecorder;
use zoo_host::kit::{bind_group, bind_group_layout, sampler, storage, texture};
use zoo_host::{Changes, RenderContext, TechniqueResult, wgpu};

use crate::depth::{ColorOutput, DepthPass, DepthState};
use crate::light_space::Aabb;
use crate::maps::{MAP_FORMAT, MapArray, effective_resolution};
use crate::planning::{LightMaps, PlanInputs, layers_needed, object_bounds, plan};

/// The name of the pass that renders light `light`'s layer (`face` of a cube):
/// `"{base}: light {light}"` or `"{base}: light {light} face {face}"`.
pub fn layer_pass_name(base: &str, light: usize, face: Option<usize>) -> String {
    match face {
        Some(face) => format!("{base}: light {light} face {face}"),
        None => format!("{base}: light {light}"),
    }
}

/// The bind group colour-map lookups read: the maps (`texture_2d_array<f32>`, filterable) at
/// binding 0, a linear clamping sampler at 1 and the layer cameras (`array` of 256-byte slots
/// holding a `LayerCamera`, storage) at 2.
struct LookupGroup {
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    group: Option<wgpu::BindGroup>,
}

/// Shadow maps of every light: depth maps, or colour maps (moments, fluxes) with a one-layer
/// depth scratch when built with a [`ColorOutput`].
pub struct ShadowMapSet {
    label: String,
    depth_pass: DepthPass,
    color_format: Option<wgpu::TextureFormat>,
    lookup: Option<LookupGroup>,
    objects: Vec<Aabb>,
    casters: Vec<Aabb>,
    lights: Vec<LightMaps>,
    depth: Option<MapArray>,
    color: Option<MapArray>,
    fitted: bool,
}

impl ShadowMapSet {
    /// Builds the depth pass (`label` names it and the maps).
    pub fn new(
        ctx: &RenderContext<'_>,
        label: &str,
        state: DepthState,
        color: Option<ColorOutput<'_>>,
    ) -> TechniqueResult<ShadowMapSet> {
        let stage = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let filterable = wgpu::TextureSampleType::Float { filterable: true };
        let device = &ctx.gpu.device;
        let lookup = color.map(|_| LookupGroup {
            layout: bind_group_layout(
                device,
                &format!("{label} lookup layout"),
                &[
                    texture(0, stage, filterable, wgpu::TextureViewDimension::D2Array),
                    sampler(1, stage, wgpu::SamplerBindingType::Filtering),
                    storage(2, stage, true),
                ],
            ),
            sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(&format!("{label} sampler")),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            }),
            group: None,
        });
        Ok(ShadowMapSet {
            label: label.to_string(),
            depth_pass: DepthPass::with_color(ctx, label, state, color)?,
            color_format: color.map(|c| c.format),
            lookup,
            objects: Vec::new(),
            casters: Vec::new(),
            lights: Vec::new(),
            depth: None,
            color: None,
            fitted: false,
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
        if changes.scene || !self.fitted {
            self.objects = object_bounds(ctx.scene, false);
            self.casters = object_bounds(ctx.scene, true);
        }
        let replanned = self.plan_maps(ctx, resolution);
        if !replanned && self.fitted && changes == Changes::default() {
            return false;
        }
        let resolution = self.resolution();
        self.lights = plan(&PlanInputs {
            lights: ctx.lights,
            camera: ctx.camera,
            view_proj: ctx.frame.matrices.view_proj,
            size: ctx.size,
            objects: &self.objects,
            casters: &self.casters,
            resolution,
            stable,
        });
        self.fitted = true;
        let replaced = self.depth_pass.write_cameras(ctx.gpu, &self.lights) || replanned;
        if let (Some(lookup), Some(color), Some(cameras)) =
            (&mut self.lookup, &self.color, self.depth_pass.cameras())
            && (replaced || lookup.group.is_none())
        {
            lookup.group = Some(bind_group(
                &ctx.gpu.device,
                &format!("{} lookup", self.label),
                &lookup.layout,
                &[
                    wgpu::BindingResource::TextureView(&color.array_view),
                    wgpu::BindingResource::Sampler(&lookup.sampler),
                    cameras.as_entire_binding(),
                ],
            ));
        }
        replaced
    }

    /// For sets with colour maps: the layout of [`Self::lookup_group`] (maps at binding 0,
    /// linear sampler at 1, layer cameras at 2), for the lookup's pipeline layout.
    pub fn lookup_layout(&self) -> Option<&wgpu::BindGroupLayout> {
        self.lookup.as_ref().map(|l| &l.layout)
    }

    /// For sets with colour maps, once prepared: the lookup's bind group over the current
    /// maps and cameras.
    pub fn lookup_group(&self) -> Option<&wgpu::BindGroup> {
        self.lookup.as_ref().and_then(|l| l.group.as_ref())
    }

    /// (Re)creates the maps when the layer count or the resolution changes.
    fn plan_maps(&mut self, ctx: &RenderContext<'_>, requested: u32) -> bool {
        let layers = layers_needed(ctx.lights);
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

    /// The passes [`Self::record`] records, named by [`layer_pass_name`] with `base`.
    pub fn pass_names(&self, base: &str) -> Vec<String> {
        DepthPass::pass_names(&self.lights, |l, f| layer_pass_name(base, l, f))
    }

    /// Renders every layer, one pass each named by [`layer_pass_name`] with `base`.
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
        let name = |l, f| layer_pass_name(base, l, f);
        match &self.color {
            Some(color) => {
                (self.depth_pass).record_color(ctx, recorder, color, depth, &self.lights, name)
            }
            None => self
                .depth_pass
                .record(ctx, recorder, depth, &self.lights, name),
        }
    }
}
