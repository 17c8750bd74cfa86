//! Virtual shadow maps: each light's map is far larger than any texture, split into pages of
//! which only those that visible pixels need are allocated from one physical pool, drawn,
//! and kept across frames until their layer moves (a light that moves or turns) or scrolls
//! past them (a clipmap level following the camera). Directional lights get a clipmap of
//! levels centred on the camera, each twice the size of the one before; spot lights one
//! frustum and point lights six cube faces, with mip levels each (`layers.rs`).
//!
//! Every step runs on the GPU each frame, nothing read back but counters
//! (`shaders/virtual-maps/bookkeeping.wgsl`, `pages.rs`): pixels mark the pages they need
//! (the level whose texels match their footprint, and the coarsest level's page as a
//! fallback), needed pages take free physical pages, then those no pixel needs, least
//! recently used first (coarsest levels first, so a full pool leaves a coarser page, never
//! none), the pages taken are cleared and every caster drawn into them from indirect
//! arguments, and a full-screen pass per light compares each pixel with its page.

mod layers;
mod pages;

use zoo_host::glam::{IVec2, Mat4, Vec3};
use zoo_host::kit::FullscreenLightPass;
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};

use layers::{LayerView, Layout, Sizes, depth_range, fallback_level, light_layers};
use pages::{GUTTER, Pages, Stages};
use zoo_shadow_maps::light_space::perspective_near;
use zoo_shadow_maps::{FilterParams, MapFilter, MapFilters, light_scissor, light_size};

zoo_host::technique_params! {
    /// Parameters of virtual shadow maps.
    pub struct VirtualParams {
        use filtering: FilterParams;
        /// Texels a page side (rounded down to a power of two).
        page_size: u32 = 128, range(32, 512), step(32), flags(rebuild);
        /// Pages a side of a clipmap level, and of a spot or point light's finest mip level
        /// (rounded down to a power of two).
        pages: u32 = 32, range(2, 128), step(2), flags(rebuild);
        /// Clipmap levels of a directional light, each twice the size of the one before.
        clip_levels: u32 = 14, range(1, 24), step(1), flags(rebuild);
        /// The finest clipmap level's size as a fraction of the scene's diagonal (so a scene
        /// scaled by any factor is shadowed alike; 1/512 of a 1.6 km scene is about 3 m).
        first_level_fraction: f32 = 0.002, range(0.0001, 1.0), step(0.0005);
        /// Physical pages in the pool (rounded up to a square, within the device's texture
        /// size and the 1 GiB that shadow maps keep to).
        pool_pages: u32 = 1024, range(16, 16384), step(16), flags(rebuild);
        /// Multiplies the pixel footprint a level's texels must match (below 1: finer pages,
        /// more of them; 0.5 keeps shadows a pixel wide, of wires, on the right pixels).
        level_bias: f32 = 0.5, range(0.125, 16.0), step(0.125);
        /// Normal offset of the lookup, in texels of the level it reads.
        normal_offset: f32 = 0.5, range(0.0, 8.0), step(0.25);
        /// Slope-scaled depth bias of the page draws.
        slope_bias: f32 = 1.5, range(0.0, 10.0), step(0.25), flags(rebuild);
        /// The light whose page table the "page table" debug view shows.
        debug_light: u32 = 0, range(0, 1023), step(1);
        /// The level (within each face) the "page table" debug view shows.
        debug_level: u32 = 0, range(0, 23), step(1);
    }
}

zoo_host::gpu_struct! {
    "virtual-maps/virtual_frame.wgsl" =>
    /// The frame's settings of every virtual-maps pass (`virtual-maps/tables.wgsl`).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub(crate) struct VirtualFrame {
        /// Frames rendered before this one (pages remember the last frame they were needed).
        pub(crate) frame: u32,
        pub(crate) page_size: u32,
        pub(crate) gutter: u32,
        /// A page and its gutter: texels a side of one slot of the pool.
        pub(crate) slot_size: u32,
        /// Slots a side of the pool, and its texels a side.
        pub(crate) pool_side: u32,
        pub(crate) pool_texels: u32,
        /// World size of a pixel at unit distance from the camera.
        pub(crate) pixel_angle: f32,
        pub(crate) level_bias: f32,
        pub(crate) normal_offset: f32,
        pub(crate) light_count: u32,
        /// How far the filter's taps reach around a receiver, in texels: the pages within it
        /// are marked.
        pub(crate) reach_texels: f32,
        /// The light and level the page-table debug view shows.
        pub(crate) debug_light: u32,
        pub(crate) debug_level: u32,
    }
}

zoo_host::gpu_struct! {
    "virtual-maps/virtual_layer.wgsl" =>
    /// One virtual layer (a clipmap level, or a face's mip level).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub(crate) struct VirtualLayer {
        pub(crate) view_proj: Mat4,
        /// Its window's first page on its page grid (`LayerView::origin`), and how far the
        /// window scrolled since the last frame.
        pub(crate) origin: IVec2,
        pub(crate) scrolled: IVec2,
        /// Pages a side, and its first page-table entry.
        pub(crate) pages: u32,
        pub(crate) first_entry: u32,
        /// Its level within its face, and its light.
        pub(crate) level: u32,
        pub(crate) light: u32,
        /// Which of its pages are freed ([`Invalidate`]).
        pub(crate) invalidate: u32,
    }
}

/// Which pages of a layer are freed at the start of a frame (`INVALIDATE_*` in
/// `virtual-maps/tables.wgsl`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Invalidate {
    /// None: the layer has not moved.
    None = 0,
    /// Every one: the layer moved (a light that moved or turned) or nothing may be kept.
    All = 1,
    /// Those that left its window: a clipmap level that scrolled.
    Scrolled = 2,
}

zoo_host::gpu_struct! {
    "virtual-maps/virtual_light.wgsl" =>
    /// One light's layers and filter.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub(crate) struct VirtualLight {
        /// How its lookups filter.
        pub(crate) map_filter: MapFilter,
        pub(crate) first_layer: u32,
        pub(crate) faces: u32,
        pub(crate) levels: u32,
        /// 1 for a clipmap (directional).
        pub(crate) clipmap: u32,
        /// World size of a level-0 texel: absolute (clipmap) or at unit distance (mips).
        pub(crate) first_texel: f32,
        /// The level every pixel reads when the pool has no room for its own (a mip chain's
        /// last, the clipmap level whose pages are as wide as the scene): allocated first.
        pub(crate) fallback_level: u32,
        /// The layers' depth range along their axis (for PCSS's blocker distances).
        pub(crate) near: f32,
        pub(crate) far: f32,
    }
}

zoo_host::gpu_struct! {
    "virtual-maps/caster_run.wgsl" =>
    /// One run of caster objects drawn together (instances of a mesh share a run).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub(crate) struct CasterRun {
        pub(crate) first_object: u32,
        pub(crate) objects: u32,
        /// Where its instances start in the instance list (`virtual-maps/cull.wgsl`).
        pub(crate) instances_at: u32,
    }
}

zoo_host::gpu_struct! {
    "virtual-maps/caster_box.wgsl" =>
    /// One caster object's world box, its run and its place among the run's objects, culled
    /// against every page drawn (`virtual-maps/cull.wgsl`).
    #[derive(Debug, Clone, Copy, PartialEq, Default)]
    pub(crate) struct CasterBox {
        pub(crate) lo: Vec3,
        pub(crate) run: u32,
        pub(crate) hi: Vec3,
        pub(crate) local: u32,
    }
}

zoo_host::gpu_struct! {
    "virtual-maps/virtual_lookup.wgsl" =>
    /// One light's lookup: its light. Its filter is read from storage (`VirtualLight`):
    /// lavapipe specialises a shader on the uniforms that steer its control flow and would
    /// compile it again for every light (16 ms a pass against 0.7 on `lights-256`).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub(crate) struct VirtualLookup {
        pub(crate) light: u32,
    }
}

const LOOKUP_SHADER: &str = "virtual-maps/lookup.wgsl";
const LOOKUP_PASS: &str = "Virtual map lookup";
/// The debug view of the physical pool: every page's depths in its slot.
const POOL_VIEW: &str = "physical pool";
/// The debug views of the bookkeeping (`virtual-maps/debug.wgsl`): the page table of the
/// light and level the `debug_` parameters choose, and the state of every physical page.
const PAGE_TABLE_VIEW: &str = "page table";
const CACHE_VIEW: &str = "page cache";

impl VirtualParams {
    /// The layers' sizes for a scene of diagonal `diagonal`.
    fn sizes(&self, diagonal: f32) -> Sizes {
        let power = |v: u32| 1 << v.max(1).ilog2();
        Sizes {
            pages: power(self.pages),
            clip_levels: self.clip_levels,
            first_level_size: (self.first_level_fraction * diagonal).max(f32::MIN_POSITIVE),
            page_size: power(self.page_size),
        }
    }
}

/// The diagonal of the scene's box (1 for a scene without geometry).
fn scene_diagonal(scene: &zoo_host::Scene) -> f32 {
    let (lo, hi) = scene.bounds();
    let d = lo.distance(hi);
    if d.is_finite() && d > 0.0 { d } else { 1.0 }
}

/// The stages, and the page table and pool of the current layout.
struct Gpu {
    stages: Stages,
    lookup: FullscreenLightPass<VirtualLookup>,
    filters: MapFilters,
    pages: Option<Pages>,
    /// Frames recorded.
    frame: u32,
    device: wgpu::Device,
}

/// Each light's [`VirtualLight`] in `layout`, seen from `camera` over a scene of `bounds`,
/// its lookups filtered by `filter` (of a light's size).
fn virtual_lights(
    layout: &Layout,
    lights: &[zoo_host::Light],
    (camera, bounds): (Vec3, (Vec3, Vec3)),
    filter: impl Fn(f32) -> MapFilter,
) -> Vec<VirtualLight> {
    let s = &layout.sizes;
    let texels = (s.pages * s.page_size) as f32;
    (layout.lights.iter().zip(lights))
        .map(|(l, light)| {
            let first_texel = match light.kind {
                LightKind::Directional => s.first_level_size / texels,
                LightKind::Spot => {
                    2.0 * (light.spot_angle * 1.05).min(85f32.to_radians()).tan() / texels
                }
                LightKind::Point => 2.0 / texels,
            };
            let fallback_level = match l.clipmap {
                true => fallback_level(light.direction, s, camera, bounds),
                false => l.levels - 1,
            };
            let (near, far) = match l.clipmap {
                true => depth_range(light.direction.normalize(), bounds),
                false => (perspective_near(light.range), light.range),
            };
            VirtualLight {
                map_filter: filter(light_size(light)),
                first_layer: l.first_layer,
                faces: l.faces,
                levels: l.levels,
                clipmap: u32::from(l.clipmap),
                first_texel,
                fallback_level,
                near,
                far,
            }
        })
        .collect()
}

struct VirtualMaps {
    params: VirtualParams,
    gpu: LazyGpu<Gpu>,
}

impl VirtualMaps {
    /// This frame's layers; those that moved since the last frame free their pages (every
    /// one, or for a clipmap level that only scrolled, those that left its window), and every
    /// layer does where unchanged work may not be kept.
    fn frame_layers(&self, ctx: &RenderContext<'_>, pages: &mut Pages) -> Vec<VirtualLayer> {
        let sizes = pages.layout.sizes;
        let bounds = ctx.scene.bounds();
        let views: Vec<LayerView> = (pages.layout.lights.iter().zip(ctx.lights))
            .flat_map(|(layers, light)| light_layers(light, layers, &sizes, ctx.camera, bounds))
            .collect();
        let layers = (views.iter().enumerate())
            .map(|(k, view)| {
                let (count, first_entry) = pages.layout.layers[k];
                let last = pages.last_layers.get(k);
                let invalidate = match last {
                    _ if !ctx.reuse_unchanged => Invalidate::All,
                    Some(last) if last == view => Invalidate::None,
                    Some(last) if last.unscrolled == view.unscrolled => Invalidate::Scrolled,
                    _ => Invalidate::All,
                };
                let (light, level) = light_and_level(&pages.layout, k);
                VirtualLayer {
                    view_proj: view.view_proj,
                    origin: view.origin,
                    scrolled: last.map_or(IVec2::ZERO, |last| view.origin - last.origin),
                    pages: count,
                    first_entry,
                    level,
                    light,
                    invalidate: invalidate as u32,
                }
            })
            .collect();
        pages.last_layers = views;
        layers
    }
}

/// The light of layer `layer` and its level within its face.
fn light_and_level(layout: &Layout, layer: usize) -> (u32, u32) {
    let layer = layer as u32;
    (layout.lights.iter().enumerate())
        .rev()
        .find(|(_, l)| l.first_layer <= layer)
        .map_or((0, 0), |(light, l)| {
            (light as u32, (layer - l.first_layer) % l.levels)
        })
}

impl ShadowTechnique for VirtualMaps {
    fn resources(&self) -> Vec<ResourceInfo> {
        let pages = self.gpu.built().and_then(|g| g.pages.as_ref());
        let Some(pages) = pages else {
            return Vec::new();
        };
        vec![
            ResourceInfo::texture(POOL_VIEW, &pages.pool, true),
            ResourceInfo::texture(PAGE_TABLE_VIEW, &pages.debug.page_table, true),
            ResourceInfo::texture(CACHE_VIEW, &pages.debug.pool, true),
            ResourceInfo::buffer("page table", &pages.page_table, "u32"),
        ]
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let p = &self.params;
        let gpu = self.gpu.prepare(false, || {
            Ok(Gpu {
                stages: Stages::new(ctx, p.slope_bias)?,
                lookup: FullscreenLightPass::new(ctx, LOOKUP_SHADER, "fs_lookup", &[])?,
                filters: MapFilters::read(ctx.shaders)?,
                pages: None,
                frame: 0,
                device: ctx.gpu.device.clone(),
            })
        })?;
        let kinds: Vec<LightKind> = ctx.lights.iter().map(|l| l.kind).collect();
        let sizes = p.sizes(scene_diagonal(ctx.scene));
        let current = (gpu.pages.as_ref())
            .is_some_and(|pages| pages.layout.sizes == sizes && pages.layout.kinds() == kinds);
        if changes.scene || !current {
            let layout = Layout::new(ctx.lights, sizes);
            let pages = Pages::new(ctx, &gpu.stages, gpu.lookup.stage(), layout, p.pool_pages)?;
            gpu.pages = Some(pages);
        }
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let mut pages =
            (self.gpu.get_mut()?.pages.take()).ok_or_else(TechniqueError::not_prepared)?;
        let layers = self.frame_layers(ctx, &mut pages);
        let p = &self.params;
        let gpu = self.gpu.get_mut()?;
        gpu.frame = gpu.frame.wrapping_add(1);
        let sizes = pages.layout.sizes;
        let slot_size = sizes.page_size + 2 * GUTTER;
        let frame = VirtualFrame {
            frame: gpu.frame,
            page_size: sizes.page_size,
            gutter: GUTTER,
            slot_size,
            pool_side: pages.pool_side,
            pool_texels: pages.pool_side * slot_size,
            pixel_angle: 2.0 * (ctx.camera.fov_y * 0.5).tan() / ctx.size.y.max(1) as f32,
            level_bias: p.level_bias,
            normal_offset: p.normal_offset,
            light_count: ctx.lights.len() as u32,
            // Marking assumes a reach under a page (corners then span at most 2x2 pages).
            reach_texels: p.filtering.reach_texels().min(sizes.page_size as f32),
            debug_light: p.debug_light,
            debug_level: p.debug_level,
        };
        let filters = &gpu.filters;
        let lights = virtual_lights(
            &pages.layout,
            ctx.lights,
            (ctx.camera.position, ctx.scene.bounds()),
            |size| filters.filter(&p.filtering, size),
        );
        pages.write(ctx, &frame, &layers, &lights);
        let shown = match ctx.debug_view {
            Some(PAGE_TABLE_VIEW) => Some(pages::DebugView::PageTable),
            Some(CACHE_VIEW) => Some(pages::DebugView::Cache),
            _ => None,
        };
        let result = pages
            .record(ctx, recorder, &mut gpu.stages, shown)
            .and_then(|()| {
                let own: Vec<&zoo_host::kit::StageBindGroup> = pages.lookup_tables.iter().collect();
                let per_light = |light: usize| VirtualLookup {
                    light: light as u32,
                };
                // Each light's pass covers the pixels its range can reach.
                let view_proj = ctx
                    .camera
                    .projection(ctx.size.x as f32 / ctx.size.y.max(1) as f32)
                    * ctx.camera.view();
                let scissor =
                    |light: usize| Some(light_scissor(&ctx.lights[light], view_proj, ctx.size));
                let passes = (
                    LOOKUP_PASS,
                    per_light,
                    &scissor as &dyn Fn(usize) -> Option<[u32; 4]>,
                );
                gpu.lookup
                    .record_scissored(ctx, recorder, passes, &own, &[])
            });
        gpu.pages = Some(pages);
        result
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        Ok(self.params.update(values)?)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let pages = self.gpu.built()?.pages.as_ref()?;
        let colors = ViewMapping::Color { min: 0.0, max: 1.0 };
        match resource {
            POOL_VIEW => Some(DebugImage {
                view: &pages.pool_view,
                mapping: ViewMapping::Depth { min: 0.0, max: 1.0 },
            }),
            PAGE_TABLE_VIEW => Some(DebugImage {
                view: &pages.debug.page_table_view,
                mapping: colors,
            }),
            CACHE_VIEW => Some(DebugImage {
                view: &pages.debug.pool_view,
                mapping: colors,
            }),
            _ => None,
        }
    }

    fn counters(&self) -> Vec<(String, f64)> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let Some(pages) = &gpu.pages else {
            return Vec::new();
        };
        // Nothing until a frame's counts have arrived (callers that wait retry on empty).
        let Some(c) = pages.counts(&gpu.device) else {
            return Vec::new();
        };
        let slot = f64::from(pages.layout.sizes.page_size + 2 * GUTTER);
        let pool_pages = f64::from(pages.pool_side * pages.pool_side);
        let mut counters = vec![
            ("pool pages".to_string(), pool_pages),
            (
                "pool MiB".to_string(),
                pool_pages * slot * slot * 4.0 / f64::from(1 << 20),
            ),
            (
                "page-table entries".to_string(),
                f64::from(pages.layout.entries()),
            ),
        ];
        {
            let value = |k: usize| f64::from(c[k]);
            let needed = value(pages::COUNT_NEEDED);
            counters.extend([
                ("pages needed".to_string(), needed),
                ("pages drawn".to_string(), value(pages::COUNT_DRAWN)),
                (
                    "caster instances".to_string(),
                    value(pages::COUNT_INSTANCES),
                ),
                ("pages evicted".to_string(), value(pages::COUNT_EVICTED)),
                (
                    "pages without room".to_string(),
                    value(pages::COUNT_NO_ROOM),
                ),
                (
                    "pages resident".to_string(),
                    value(pages::COUNT_RESIDENT_BEFORE) + value(pages::COUNT_DRAWN)
                        - value(pages::COUNT_EVICTED),
                ),
                (
                    "cache hit rate".to_string(),
                    if needed > 0.0 {
                        value(pages::COUNT_HITS) / needed
                    } else {
                        1.0
                    },
                ),
                (
                    "fallback pixels".to_string(),
                    value(pages::COUNT_FALLBACK_PIXELS),
                ),
            ]);
        }
        counters
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    Ok(Box::new(VirtualMaps {
        params: VirtualParams::from_values(values)?,
        gpu: LazyGpu::default(),
    }))
}

zoo_host::register_technique! {
    id: "virtual-maps",
    name: "Virtual shadow maps",
    description: "Per-light virtual maps (directional clipmaps, spot and point mip chains) whose pages are allocated from the G-buffer's needs, drawn and cached on the GPU",
    source: "Unreal Engine 5 virtual shadow maps; GPU Zen 3, \"Virtual Shadow Maps\"",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    required_features: || wgpu::Features::CLIP_DISTANCES,
    required_limits: || wgpu::Limits {
        // The page draws read the page table, the drawn list, the layers, the lights and the
        // scene's vertices, indices and objects in the vertex stage; stages bind the frame,
        // the G-buffer or materials, a per-light or per-run slot, and the tables with their own.
        max_storage_buffers_per_shader_stage: 10,
        ..wgpu::Limits::downlevel_defaults()
    },
    // Bookkeeping in compute, page draws from indirect arguments, vertices pulled from storage.
    required_downlevel: || {
        wgpu::DownlevelFlags::COMPUTE_SHADERS
            | wgpu::DownlevelFlags::INDIRECT_EXECUTION
            | wgpu::DownlevelFlags::VERTEX_STORAGE
    },
    params: VirtualParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_match_the_shaders() {
        use zoo_host::gpu::layout::wgsl_integer_constant;
        let library = zoo_host::ShaderLibrary::embedded();
        let source = library.compose(pages::BOOKKEEPING).unwrap().source;
        let constant = |name| wgsl_integer_constant(&source, name);
        assert_eq!(constant("COUNTS"), Ok(pages::COUNTS as i64));
        assert_eq!(
            constant("CANDIDATE_LISTS"),
            Ok(pages::CANDIDATE_LISTS as i64)
        );
        for invalidate in [Invalidate::None, Invalidate::All, Invalidate::Scrolled] {
            let name = format!("INVALIDATE_{}", format!("{invalidate:?}").to_uppercase());
            let code = wgsl_integer_constant(&source, &name);
            assert_eq!(code, Ok(invalidate as i64), "{name}");
        }
        for (name, index) in [
            ("COUNT_DRAWN", pages::COUNT_DRAWN),
            ("COUNT_NEEDED", pages::COUNT_NEEDED),
            ("COUNT_HITS", pages::COUNT_HITS),
            ("COUNT_EVICTED", pages::COUNT_EVICTED),
            ("COUNT_NO_ROOM", pages::COUNT_NO_ROOM),
            ("COUNT_FALLBACK_PIXELS", pages::COUNT_FALLBACK_PIXELS),
            ("COUNT_RESIDENT_BEFORE", pages::COUNT_RESIDENT_BEFORE),
        ] {
            assert_eq!(constant(name), Ok(index as i64), "{name}");
        }
        let cull = library.compose(pages::CULL).unwrap().source;
        assert_eq!(
            wgsl_integer_constant(&cull, "COUNT_INSTANCES"),
            Ok(pages::COUNT_INSTANCES as i64)
        );
        let draw = library.compose(pages::DRAW).unwrap().source;
        assert_eq!(
            wgsl_integer_constant(&draw, "CANDIDATE_LISTS"),
            Ok(pages::CANDIDATE_LISTS as i64)
        );
    }

    #[test]
    fn levels_within_a_face_count_from_each_face_s_finest() {
        let sizes = Sizes {
            pages: 8,
            clip_levels: 3,
            first_level_size: 1.0,
            page_size: 64,
        };
        let light = |kind| zoo_host::Light {
            kind,
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            radiance: Vec3::ONE,
            range: 10.0,
            spot_angle: 0.5,
            spot_softness: 0.1,
            radius: 0.0,
        };
        let layout = Layout::new(
            &[light(LightKind::Directional), light(LightKind::Point)],
            sizes,
        );
        let levels: Vec<(u32, u32)> = (0..layout.layers.len())
            .map(|k| light_and_level(&layout, k))
            .collect();
        // Three clip levels, then six faces of four mips (8, 4, 2, 1 pages).
        let mut expected = vec![(0, 0), (0, 1), (0, 2)];
        for _ in 0..6 {
            expected.extend([(1, 0), (1, 1), (1, 2), (1, 3)]);
        }
        assert_eq!(levels, expected);
    }
}
