//! A technique's shadow maps for the current lights and camera: the layer plan, the map
//! arrays and the depth pass that fills them, kept up to date from one call per frame. A
//! layer's map is rendered again only when what it holds changes (its light, its fit, its
//! tile, the scene or the technique's parameters) or another tile of its page does.

use zoo_host::gpu::PassRecorder;
use zoo_host::technique::{DebugImage, ViewMapping};
use zoo_host::{Changes, RenderContext, TechniqueResult, wgpu};

use crate::atlas::Allocation;
use crate::atlas_pages::{AtlasLimits, MapTile};
use crate::culling::box_meets_sides;
use crate::depth::{ColorOutput, DepthPass, DepthState};
use crate::light_space::Aabb;
use crate::lookup::LookupGroup;
use crate::maps::{MAP_FORMAT, MapArray};
use crate::planning::{LayerPlan, LightMaps, PlanInputs, StandardLayers, object_bounds, plan_with};
use crate::tile_pass::TilePass;

/// What one layer's map holds: it is rendered again only when this changes. The layer camera
/// follows the light and its fit; casters are static between scene changes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct LayerContent {
    view_proj: zoo_host::glam::Mat4,
    tile: MapTile,
    /// The light's range, which culls casters.
    range: f32,
}

impl LayerContent {
    fn of(maps: &LightMaps, face: usize, light: &zoo_host::Light) -> LayerContent {
        LayerContent {
            view_proj: maps.frustums[face].view_proj,
            tile: maps.tiles[face],
            range: light.range,
        }
    }
}

/// One tile this frame renders: the index of its light's maps, the layer within the light and
/// whether it is the first on its page.
#[derive(Debug, Clone, Copy)]
struct FramePass {
    light: usize,
    face: usize,
    first_on_page: bool,
}

/// Shadow maps of every light in an atlas ([`crate::atlas`]): depth maps, or colour maps
/// (moments, fluxes) with a one-page depth scratch when built with a [`ColorOutput`].
pub struct ShadowMapSet {
    label: String,
    depth_pass: DepthPass,
    color_format: Option<wgpu::TextureFormat>,
    lookup: LookupGroup,
    objects: Vec<Aabb>,
    casters: Vec<Aabb>,
    /// Per scene object: its world bounds (none for an empty object).
    object_boxes: Vec<Option<Aabb>>,
    lights: Vec<LightMaps>,
    depth: Option<MapArray>,
    color: Option<MapArray>,
    limits: Option<AtlasLimits>,
    allocation: Option<Allocation>,
    fitted: bool,
    /// Per layer: whether [`Self::record`] renders it (all, unless [`Self::cull`] says not).
    kept: Vec<bool>,
    /// Per layer: what its map holds now (none where it holds nothing valid).
    rendered: Vec<Option<LayerContent>>,
    /// The tiles this frame renders ([`Self::begin_frame`]).
    frame: Vec<FramePass>,
}

impl ShadowMapSet {
    /// Builds the depth pass (`label` names it and the maps).
    pub fn new(
        ctx: &RenderContext<'_>,
        label: &str,
        state: DepthState,
        color: Option<ColorOutput<'_>>,
    ) -> TechniqueResult<ShadowMapSet> {
        // Colour maps are filtered by the lookups themselves (`color_lookup.wgsl`), so the
        // format needs no filtering.
        if let Some(color) = color {
            let features = ctx.gpu.adapter.get_texture_format_features(color.format);
            let usages =
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
            if !features.allowed_usages.contains(usages) {
                return Err(zoo_host::TechniqueError::Other(format!(
                    "{label}: this device cannot render into {:?} maps",
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
            object_boxes: Vec::new(),
            lights: Vec::new(),
            depth: None,
            color: None,
            limits: None,
            allocation: None,
            fitted: false,
            kept: Vec::new(),
            rendered: Vec::new(),
            frame: Vec::new(),
        })
    }

    /// Replans the layers on any change: directional maps follow the camera (with `stable`
    /// they keep a stable fit) and every light's tier follows its span on screen, within an
    /// atlas of pages of `resolution` texels. Returns whether the maps or the camera buffer
    /// were replaced, so bind groups over them must be rebuilt.
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
        if changes.scene || changes.params {
            // New casters, or parameters that may change what the maps hold.
            self.rendered.clear();
        }
        let limits = self.atlas_limits(ctx, resolution);
        if self.fitted && changes == Changes::default() && self.limits == Some(limits) {
            return false;
        }
        self.limits = Some(limits);
        let inputs = PlanInputs {
            lights: ctx.lights,
            camera: ctx.camera,
            view_proj: ctx.frame.matrices.view_proj,
            size: ctx.size,
            objects: &self.objects,
            casters: &self.casters,
            stable,
        };
        // A new scene or new parameters start from a fresh packing.
        let previous = (!(changes.scene || changes.params)).then_some(self.allocation.as_ref());
        let (lights, allocation) = plan_with(&inputs, layout, &limits, previous.flatten());
        if allocation.unfitted > 0 && self.allocation.as_ref().is_none_or(|a| a.unfitted == 0) {
            zoo_host::log::warn!(
                "{}: {} map layers do not fit the atlas even at {}²; their lights are unshadowed there",
                self.label,
                allocation.unfitted,
                limits.tile_size(limits.max_tier())
            );
        }
        self.lights = lights;
        let shrink = changes.scene || changes.lights;
        let new_maps = self.make_pages(ctx, limits.page_size, allocation.pages, shrink);
        if new_maps {
            self.rendered.clear();
        }
        self.allocation = Some(allocation);
        self.fitted = true;
        self.kept.clear();
        let replaced = self.depth_pass.write_cameras(ctx.gpu, &self.lights) || new_maps;
        if replaced {
            // Techniques rebuild what they keep beside the maps (hybrid's triangle ids) when
            // the maps or cameras are replaced: every tile renders again.
            self.rendered.clear();
        }
        let lookup = &mut self.lookup;
        let maps = self.color.as_ref().or(self.depth.as_ref());
        if let (Some(maps), Some(cameras)) = (maps, self.depth_pass.cameras())
            && (replaced || lookup.group.is_none())
        {
            lookup.bind(&ctx.gpu.device, maps, cameras);
        }
        replaced
    }

    /// The atlas's pages for maps of `requested` texels on this device.
    fn atlas_limits(&self, ctx: &RenderContext<'_>, requested: u32) -> AtlasLimits {
        let bytes =
            |format: wgpu::TextureFormat| u64::from(format.block_copy_size(None).unwrap_or(4));
        let (maps, scratch) = match self.color_format {
            Some(color) => (bytes(color), bytes(MAP_FORMAT)),
            None => (bytes(MAP_FORMAT), 0),
        };
        let spare = ctx.gpu.info.backend == wgpu::Backend::Gl;
        let limits = ctx.gpu.device.limits();
        let (limits, note) = AtlasLimits::new(requested, &limits, spare, maps, scratch);
        if let Some(note) = note
            && self.limits != Some(limits)
        {
            zoo_host::log::warn!("{}: {note}", self.label);
        }
        limits
    }

    /// Layer `layer`'s camera, as the group of stages that read one `LayerCamera` (the depth
    /// pass's, and passes of the technique's own that render into the layers).
    pub fn layer_camera(&self, layer: u32) -> zoo_host::kit::UniformSlot<'_, crate::LayerCamera> {
        self.depth_pass.camera(layer)
    }

    /// The lookup group (see [`crate::lookup`]) as stages share it; bound once prepared. A
    /// stage may join its index with variables of its own, binding [`Self::lookup_resources`]
    /// with them.
    pub fn lookup(&self) -> zoo_host::kit::Joinable<zoo_host::kit::NamedGroup<'_>> {
        self.lookup.shared()
    }

    /// The lookup group's resources by variable name (none before the maps are made), for
    /// stages that join its index; their groups must be made again when [`Self::prepare`]
    /// says the maps were replaced.
    pub fn lookup_resources(&self) -> Vec<(&'static str, wgpu::BindingResource<'_>)> {
        let maps = self.color.as_ref().or(self.depth.as_ref());
        match (maps, self.depth_pass.cameras()) {
            (Some(maps), Some(cameras)) => self.lookup.resources(maps, cameras),
            _ => Vec::new(),
        }
    }

    fn update_bounds(&mut self, ctx: &RenderContext<'_>, changes: Changes) {
        if changes.scene || !self.fitted {
            self.objects = object_bounds(ctx.scene, false);
            self.casters = object_bounds(ctx.scene, true);
            self.object_boxes = ctx.scene.each_object_bounds();
        }
    }

    /// World bounds of every object and of each caster (for fitting; current after
    /// [`Self::prepare`]).
    pub fn bounds(&self) -> (&[Aabb], &[Aabb]) {
        (&self.objects, &self.casters)
    }

    /// (Re)creates the pages when their size changes or more are needed (and, with
    /// `shrink`, when fewer are); returns whether it did.
    fn make_pages(&mut self, ctx: &RenderContext<'_>, size: u32, pages: u32, shrink: bool) -> bool {
        let pages = pages.max(1);
        let fits = self.maps().is_some_and(|m| {
            m.resolution == size && m.layers >= pages && (!shrink || m.layers == pages)
        });
        if fits {
            return false;
        }
        let (gpu, label) = (ctx.gpu, &self.label);
        self.color = self
            .color_format
            .map(|format| MapArray::with_format(gpu, label, size, pages, format));
        let depth_pages = if self.color.is_some() { 1 } else { pages };
        let depth_label = format!("{label} depth");
        self.depth = Some(MapArray::new(gpu, &depth_label, size, depth_pages));
        true
    }

    /// Decides which tiles this frame renders: every kept tile of each page on which a kept
    /// tile's content changed (a page is cleared as a whole, so its other kept tiles render
    /// again; tiles of pages left alone keep their maps), or every kept tile when the frame
    /// may not reuse work ([`RenderContext::reuse_unchanged`]). Once a frame: [`Self::record`]
    /// calls it; a technique that renders the tiles with its own pass instead calls it before
    /// [`Self::tile_passes`] (and not `record`).
    pub fn begin_frame(&mut self, ctx: &RenderContext<'_>) {
        if !ctx.reuse_unchanged {
            self.rendered.clear();
        }
        let lights = ctx.lights;
        let layers: usize = self.lights.iter().map(|l| l.frustums.len()).sum();
        self.rendered.resize(layers, None);
        let mut dirty_pages = std::collections::BTreeSet::new();
        for maps in &self.lights {
            for (face, tile) in maps.tiles.iter().enumerate() {
                let layer = maps.first_layer as usize + face;
                let content = Some(LayerContent::of(maps, face, &lights[maps.light]));
                if tile.size > 0 && self.is_kept(layer as u32) && self.rendered[layer] != content {
                    dirty_pages.insert(tile.page);
                }
            }
        }
        let mut frame = Vec::new();
        for (index, maps) in self.lights.iter().enumerate() {
            for (face, tile) in maps.tiles.iter().enumerate() {
                if !dirty_pages.contains(&tile.page) {
                    continue;
                }
                let layer = maps.first_layer as usize + face;
                let drawn = tile.size > 0 && self.is_kept(layer as u32);
                self.rendered[layer] =
                    drawn.then(|| LayerContent::of(maps, face, &lights[maps.light]));
                if drawn {
                    frame.push((tile.page, layer, index, face));
                }
            }
        }
        frame.sort_unstable();
        let mut page = None;
        self.frame = (frame.into_iter())
            .map(|(tile_page, _, light, face)| {
                let first_on_page = page != Some(tile_page);
                page = Some(tile_page);
                FramePass {
                    light,
                    face,
                    first_on_page,
                }
            })
            .collect();
    }

    /// The tiles this frame renders ([`Self::begin_frame`]), page by page: tiles of one page
    /// are disjoint, so a depth scratch cleared at each page's first tile serves them all.
    pub fn tile_passes(&self) -> Vec<TilePass<'_>> {
        (self.frame.iter())
            .map(|pass| {
                let maps = &self.lights[pass.light];
                TilePass {
                    maps,
                    face: pass.face,
                    layer: maps.first_layer + pass.face as u32,
                    tile: maps.tiles[pass.face],
                    first_on_page: pass.first_on_page,
                }
            })
            .collect()
    }

    /// The atlas pages that hold a kept tile, in order.
    pub fn kept_pages(&self) -> Vec<u32> {
        let pages: std::collections::BTreeSet<u32> = (self.lights.iter())
            .flat_map(|maps| {
                (maps.tiles.iter().enumerate())
                    .filter(|(face, tile)| {
                        tile.size > 0 && self.is_kept(maps.first_layer + *face as u32)
                    })
                    .map(|(_, tile)| tile.page)
            })
            .collect();
        pages.into_iter().collect()
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

    /// The `shadow maps` debug image: the atlas page that holds the first layer of
    /// [`Self::debug_light`]`(wanted)` (depth maps shown as depth, colour maps as colour).
    pub fn debug_image(&self, wanted: u32) -> Option<DebugImage<'_>> {
        let light = self.debug_light(wanted)?;
        let mapping = match self.color {
            Some(_) => ViewMapping::Color { min: 0.0, max: 1.0 },
            None => ViewMapping::Depth { min: 0.0, max: 1.0 },
        };
        Some(DebugImage {
            view: &self.maps()?.layer_views[light.tiles[0].page as usize],
            mapping,
        })
    }

    /// Workload counters: map layers in use, maps and pages rendered in the last frame, the
    /// atlas (pages, page size, texels used and the budget) and how many lights have maps of
    /// each size.
    pub fn counters(&self) -> Vec<(String, f64)> {
        let layers: usize = self.lights.iter().map(|l| l.frustums.len()).sum();
        let pages_rendered = (self.frame.iter()).filter(|p| p.first_on_page).count();
        let mut counters = vec![
            ("map layers".into(), layers as f64),
            ("maps rendered".into(), self.frame.len() as f64),
            ("atlas pages rendered".into(), pages_rendered as f64),
        ];
        if let (Some(limits), Some(allocation)) = (self.limits, &self.allocation) {
            let budget = u64::from(limits.max_pages) * u64::from(limits.page_size).pow(2);
            counters.extend([
                ("atlas pages".into(), f64::from(allocation.pages)),
                ("atlas page size".into(), f64::from(limits.page_size)),
                ("atlas texels used".into(), allocation.texels as f64),
                ("atlas texel budget".into(), budget as f64),
                (
                    "map layers without a tile".into(),
                    f64::from(allocation.unfitted),
                ),
            ]);
            for tier in 0..=limits.max_tier() {
                let size = limits.tile_size(tier);
                let lights = (self.lights.iter())
                    .filter(|l| !l.tiles.is_empty() && l.resolution == size)
                    .count();
                if lights > 0 {
                    counters.push((format!("lights with {size}² maps"), lights as f64));
                }
            }
        }
        counters
    }

    /// The maps lookups read (the colour maps when there are any, else the depth maps).
    pub fn maps(&self) -> Option<&MapArray> {
        self.color.as_ref().or(self.depth.as_ref())
    }

    /// Texels per side of the atlas pages (0 before the first [`Self::prepare`]); each
    /// light's maps are [`LightMaps::resolution`].
    pub fn page_size(&self) -> u32 {
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

    /// Renders this frame's tiles ([`Self::begin_frame`]), one pass each named by
    /// [`layer_pass_name`](crate::layer_pass_name) with `base`.
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        base: &str,
    ) -> TechniqueResult {
        self.begin_frame(ctx);
        let depth = self
            .depth
            .as_ref()
            .ok_or_else(zoo_host::TechniqueError::not_prepared)?;
        let color = self.color.as_ref();
        let passes = self.tile_passes();
        let casts = |pass: &TilePass<'_>, object| {
            self.casts_into(&ctx.lights[pass.maps.light], pass, object)
        };
        (self.depth_pass).record(ctx, recorder, color, depth, &passes, base, &casts)
    }

    /// Whether scene object `object` can cast into the tile of `pass`: it reaches the pass's
    /// light ([`Self::reaches`]) and its box meets the sides of the layer's frustum, widened by
    /// two texels (for rasterisation grown by up to that much). Warped layers (their clip
    /// space is not the light's) test the light only.
    pub fn casts_into(&self, light: &zoo_host::Light, pass: &TilePass<'_>, object: usize) -> bool {
        if !self.reaches(light, object) {
            return false;
        }
        let frustum = &pass.maps.frustums[pass.face];
        let margin = 4.0 / pass.tile.size.max(1) as f32;
        let warped = matches!(frustum.projection, crate::light_space::Projection::Warped);
        let bounds = self.object_boxes.get(object).copied().flatten();
        warped || bounds.is_none_or(|b| box_meets_sides(frustum.view_proj, margin, b))
    }

    /// Whether scene object `object` can cast into `light`'s maps: it meets the light's range
    /// (directional lights reach everything).
    pub fn reaches(&self, light: &zoo_host::Light, object: usize) -> bool {
        if light.kind == zoo_host::scene::LightKind::Directional {
            return true;
        }
        self.object_boxes.get(object).is_none_or(|bounds| {
            bounds.is_some_and(|(lo, hi)| {
                let nearest = light.position.clamp(lo, hi);
                nearest.distance_squared(light.position) <= light.range * light.range
            })
        })
    }
}
