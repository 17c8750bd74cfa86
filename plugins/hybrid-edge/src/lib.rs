//! Hybrid shadows (seed 003): shadow maps decide every pixel they can, shadow volumes resolve
//! only the band along shadow edges where the map cannot.
//!
//! Per light: (1) a shadow map from the shadow-map library; (2) a full-screen pass classifies
//! each pixel from its (2r + 1)² shadow-map neighbourhood (nearest comparisons one texel apart)
//! into lit, shadowed or edge (a pixel the samples call lit joins the edge band when a caster
//! thinner than a texel may cross its light ray: conservatively rasterised coverage maps hold
//! the nearest depth of any caster touching each texel), writes the visibility of lit and
//! shadowed pixels, and writes the
//! edge pixels' depth into a depth image whose other pixels hold 1; (3) the light's shadow
//! volumes (from the shadow-volume library) are counted like z-fail against that image with a
//! `Greater` depth test, so outside the band every volume fragment fails the early depth test
//! instead of being counted; (4) edge pixels with a non-zero count are shadowed.
//!
//! Restriction methods, a parameter:
//! - `DepthBand` (default): the volumes above, rejected outside the band by the depth test;
//! - `TriangleIds`: the map pass also stores the id of the front-most triangle in each texel,
//!   and edge pixels test their light ray exactly against the triangles of their
//!   neighbourhood (seed 003's future-work idea), so no volume is rasterised at all (exact
//!   unless an occluder is thinner than a texel or hidden behind another in the map);
//! - `Tiles`: the depth band, with the volumes drawn only into the screen tiles that hold edge
//!   pixels (a compute pass lists them; each tile is an instance clipped by clip distances),
//!   so nothing is rasterised outside those tiles even where early depth tests are not;
//! - `Stencil`: seed 003's own restriction: a full-screen pass marks the band's pixels (those
//!   the band's depth image holds a depth at) in the top bit of the G-buffer's stencil, and the
//!   volumes are counted against the G-buffer's depth, which holds every pixel's surface, in
//!   the bits below it wherever the stencil test finds the mark: they are rejected outside the
//!   band by the stencil test alone (the seed found this "not very suitable": the rejected
//!   fragments are still rasterised);
//! - `Everywhere`: every pixel in the band (plain shadow volumes through the same passes), to
//!   measure what the restriction saves.

mod casters;
mod closed;
mod tiles;

use zoo_host::gpu::PassRecorder;
use zoo_host::gpu::layout::ChoiceCodes;
use zoo_host::kit::{NamedTextures, Stage, StageBindGroup, TextureSpec, light_pass_name};
use zoo_host::prelude::*;
use zoo_host::render::gbuffer::DEPTH_FORMAT;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};
use zoo_shadow_maps::{DepthState, LightMaps, LookupPass, LookupShader, MapHeader, ShadowMapSet};

use casters::{CasterIdMaps, CasterIds};
use tiles::Tiles;
use zoo_shadow_volumes::{
    COUNTS_FORMAT, MARK_BIT, StencilCounts, VolumeGenerator, VolumeShape,
    band_volume_depth_stencil, mark_depth_stencil, marked_resolve_stage,
    marked_volume_depth_stencil, piece_pass_name, resolve_stage, volume_stage,
};

zoo_host::param_choice! {
    /// Where shadow volumes are counted.
    pub enum Restriction { DepthBand, Everywhere, TriangleIds, Tiles, Stencil }
}

zoo_host::technique_params! {
    /// Parameters of the hybrid shadow-map / shadow-volume technique.
    pub struct HybridParams {
        /// Side of the screen tiles of the `Tiles` restriction, in pixels (rounded up to a
        /// multiple of 8).
        tile_size: u32 = 16, range(8, 64), step(8);
        /// Shadow-map resolution in texels per side.
        map_size: u32 = 2048, range(256, 8192), step(256);
        /// Neighbourhood radius r in texels: (2r + 1)² taps decide lit, shadowed or edge.
        radius: u32 = 1, range(1, 4), step(1);
        /// Send pixels whose light ray may cross a caster thinner than a map texel (which the
        /// map's samples miss) to the exact pass, from conservatively rasterised coverage maps.
        coverage: bool = true;
        /// How edge pixels are resolved: volumes restricted to the band by a depth image (and
        /// optionally to its screen tiles) or by a stencil mark, exact tests against the map's
        /// triangle ids, or volumes everywhere.
        restriction: Restriction = Restriction::DepthBand;
        /// Slope-scaled depth bias of the shadow map.
        slope_bias: f32 = 1.5, range(0.0, 10.0), step(0.1), flags(rebuild);
        /// Normal offset of the classification taps, in texels.
        normal_offset: f32 = 1.0, range(0.0, 8.0), step(0.1);
        /// Constant depth bias pushing volume faces back (depth-buffer units).
        volume_bias: u32 = 16, range(0, 65536), step(1), flags(rebuild);
        /// Light whose classification the debug view shows.
        debug_light: u32 = 0, range(0, 1023), step(1);
        /// Largest volume vertex buffer in MiB (0: as large as the device binds). Volumes that
        /// may need more are generated and drawn in pieces that fit it, their stencil counts
        /// adding up, so the band stays exact; smaller pieces take less memory and more passes.
        volume_buffer_mib: u32 = 0, range(0, 4096), step(1), flags(rebuild);
    }
}

impl HybridParams {
    /// The volume buffer's budget in bytes, if one is set.
    fn volume_budget(&self) -> Option<u64> {
        (self.volume_buffer_mib > 0).then(|| u64::from(self.volume_buffer_mib) << 20)
    }
}

zoo_host::gpu_struct! {
    "hybrid-edge/edge_light.wgsl" =>
    /// One light's band pass uniform (`hybrid-edge/band.wgsl`).
    #[derive(Debug, Clone, Copy)]
    struct EdgeLight {
        map: MapHeader,
        /// Neighbourhood radius r in texels.
        radius: u32,
        /// Restriction (`RESTRICTION_*` in the shader).
        restriction: u32,
        /// 1: pixels the coverage maps cannot clear join the band.
        coverage: u32,
    }
}

const SHADER: &str = "hybrid-edge/band.wgsl";
const IDS_PASS: &str = "Hybrid id map";
const COVERAGE_PASS: &str = "Hybrid coverage map";
const TILES_PASS: &str = "Hybrid tiles";
/// Passes that only feed debug views.
const DEBUG_PASS: &str = "Hybrid debug view";
/// The id of texels no triangle covers.
const NO_TRIANGLE: u32 = u32::MAX;
const MAP_PASS: &str = "Hybrid map";
const BAND_PASS: &str = "Hybrid band";
const GENERATION_PASS: &str = "Hybrid volume generation";
const VOLUME_PASS: &str = "Hybrid volumes";
const CLASS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const CLASS_VIEW: &str = "classification";
const COUNTS_VIEW: &str = "stencil counts";
const TILES_VIEW: &str = "active tiles";
const COVERAGE_VIEW: &str = "coverage maps";
/// The band's depth-stencil: the edge pixels' depth, 1 elsewhere, and the volumes' counts.
const BAND_TARGET: &str = "band depth-stencil";

/// Screen-sized targets: the band's depth-stencil and the debug views.
fn targets() -> NamedTextures {
    let color = Some(ViewMapping::Color { min: 0.0, max: 1.0 });
    let mut band = TextureSpec::screen_target(BAND_TARGET, DEPTH_FORMAT, None);
    // The tile restriction reads the band's depth.
    band.usage |= wgpu::TextureUsages::TEXTURE_BINDING;
    NamedTextures::new(
        "hybrid",
        [
            TextureSpec::screen_target(CLASS_VIEW, CLASS_FORMAT, color),
            band,
            TextureSpec::screen_target(COUNTS_VIEW, COUNTS_FORMAT, Some(ViewMapping::Integer)),
            TextureSpec::screen_target(TILES_VIEW, tiles::OVERLAY_FORMAT, color),
        ],
    )
}

/// Maps, volumes, pipelines and targets, built at the first `prepare`.
struct Gpu {
    maps: ShadowMapSet,
    generator: VolumeGenerator,
    /// The band's classification: volumes next, or exact id tests.
    band: LookupPass<EdgeLight>,
    band_ids: LookupPass<EdgeLight>,
    coverage: CasterIdMaps,
    ids: CasterIdMaps,
    /// The tile restriction, built when first chosen.
    tiles: Option<Tiles>,
    volume_bias: wgpu::DepthBiasState,
    /// The band shader's value of each `Restriction`.
    restriction_codes: ChoiceCodes,
    volume: Stage,
    resolve: Stage,
    /// The stencil restriction's passes.
    marked: Marked,
    counts: StencilCounts,
    targets: NamedTextures,
    /// The band passes' groups over the coverage maps (and the id maps), once made.
    band_groups: [Option<StageBindGroup>; 2],
    /// Lights the volume buffers were made for.
    lights: usize,
}

/// The `Stencil` restriction's passes: the mark, the volumes counted where it is, the resolve
/// and the count view of the bits below the mark.
struct Marked {
    mark: Stage,
    volume: Stage,
    resolve: Stage,
    counts: StencilCounts,
}

/// Writes the band's depth (compare always), leaves the stencil for the volumes.
fn band_depth_state() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Always),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

impl Gpu {
    fn new(ctx: &RenderContext<'_>, p: &HybridParams) -> TechniqueResult<Gpu> {
        let state = DepthState {
            constant_bias: 0,
            slope_bias: p.slope_bias,
            ..DepthState::default()
        };
        let maps = ShadowMapSet::new(ctx, "hybrid shadow maps", state, None)?;
        let coverage = CasterIds {
            label: "hybrid coverage",
            shader: "hybrid-edge/coverage.wgsl",
            entries: ("vs_coverage", "fs_coverage"),
            // Both faces, no bias: an open caster's every triangle counts, whichever way it
            // faces; closed casters need only the faces turned to the light.
            state: DepthState::default(),
            own_depth: true,
            closed_casters: true,
        };
        let ids = CasterIds {
            label: "hybrid triangle ids",
            shader: "hybrid-edge/ids.wgsl",
            entries: ("vs_ids", "fs_ids"),
            state,
            own_depth: false,
            closed_casters: false,
        };
        let source = ctx.shaders.compose(SHADER)?.source;
        let restriction_codes = ChoiceCodes::read(&source, "RESTRICTION", Restriction::NAMES)
            .map_err(|e| TechniqueError::Other(format!("{SHADER}: {e}")))?;
        let band_pass = |entry| {
            let shader = LookupShader {
                shader: SHADER,
                entry,
                diagnostics: &[CLASS_FORMAT],
                depth_stencil: Some(band_depth_state()),
                shared: &[],
            };
            LookupPass::new(ctx, &maps, BAND_PASS, shader)
        };
        let bias = wgpu::DepthBiasState {
            constant: p.volume_bias as i32,
            slope_scale: 0.0,
            clamp: 0.0,
        };
        let draw = "shadow-volumes/draw.wgsl";
        let volume = volume_stage(draw, "vs_volume", band_volume_depth_stencil(bias));
        let marked_volume = volume_stage(draw, "vs_volume", marked_volume_depth_stencil(bias));
        Ok(Gpu {
            band: band_pass("fs_band")?,
            band_ids: band_pass("fs_band_ids")?,
            coverage: CasterIdMaps::new(ctx, &maps, coverage)?,
            ids: CasterIdMaps::new(ctx, &maps, ids)?,
            maps,
            generator: VolumeGenerator::new(ctx, "hybrid")?,
            tiles: None,
            volume_bias: bias,
            restriction_codes,
            volume: volume.build(ctx)?,
            resolve: resolve_stage(ctx)?,
            marked: Marked {
                mark: mark_stage(ctx)?,
                volume: marked_volume.build(ctx)?,
                resolve: marked_resolve_stage(ctx)?,
                counts: StencilCounts::reading(ctx, MARK_BIT - 1)?,
            },
            counts: StencilCounts::new(ctx)?,
            targets: targets(),
            band_groups: [None, None],
            lights: 0,
        })
    }

    /// Makes the band passes' groups again over the current maps, coverage and id maps: the
    /// maps' lookup group with the band's own variables in its index.
    fn bind_band_groups(&mut self, ctx: &RenderContext<'_>) -> TechniqueResult {
        let Some(coverage) = self.coverage.maps() else {
            return Ok(());
        };
        let scene = ctx.scene_buffers;
        let mut resources = self.maps.lookup_resources();
        resources.extend([
            (
                "coverage_ids",
                wgpu::BindingResource::TextureView(&coverage.array_view),
            ),
            ("scene_vertices", scene.vertices.as_entire_binding()),
            ("scene_indices", scene.indices.as_entire_binding()),
        ]);
        let label = "hybrid band lookups (coverage)";
        self.band_groups[0] = Some(self.band.stage().bind(ctx, label, &resources)?);
        if let Some(ids) = self.ids.maps() {
            let view = wgpu::BindingResource::TextureView(&ids.array_view);
            resources.push(("triangle_ids", view));
            let label = "hybrid band lookups (triangle ids)";
            self.band_groups[1] = Some(self.band_ids.stage().bind(ctx, label, &resources)?);
        }
        Ok(())
    }
}

/// The `Stencil` restriction's mark (`hybrid-edge/mark.wgsl`): in a light pass on the G-buffer's
/// depth-stencil whose colour attachment is the light's slot (left untouched).
fn mark_stage(ctx: &RenderContext<'_>) -> TechniqueResult<Stage> {
    let untouched = Some(wgpu::ColorTargetState {
        write_mask: wgpu::ColorWrites::empty(),
        ..zoo_host::kit::slot_target()
    });
    Stage::render("hybrid-edge/mark.wgsl", "fullscreen_vs")
        .fragment("fs_mark")
        .targets(&[untouched])
        .depth_stencil(mark_depth_stencil())
        .build(ctx)
}

/// The tile restriction, where the device can run it: it clips by clip distances and reads the
/// band's depth in a compute shader (which GLSL cannot).
fn tiles_for(ctx: &RenderContext<'_>, bias: wgpu::DepthBiasState) -> TechniqueResult<Tiles> {
    if !ctx
        .gpu
        .device
        .features()
        .contains(wgpu::Features::CLIP_DISTANCES)
    {
        return Err(TechniqueError::Other(
            "hybrid-edge: the Tiles restriction needs the CLIP_DISTANCES feature".into(),
        ));
    }
    if ctx.gpu.info.backend == wgpu::Backend::Gl {
        return Err(TechniqueError::Other(
            "hybrid-edge: the Tiles restriction reads depth in a compute shader, which GL cannot"
                .into(),
        ));
    }
    Tiles::new(ctx, bias)
}

/// Counts light `light`'s volumes in its band, piece by piece into the band's stencil (only
/// into the listed edge tiles with `Tiles`; with `Stencil`, into the G-buffer's stencil where
/// the mark is), and shadows the band pixels with a non-zero count; `debug`: the light the
/// debug views show.
fn record_volumes(
    ctx: &RenderContext<'_>,
    recorder: &mut PassRecorder<'_>,
    gpu: &Gpu,
    (light, debug): (usize, bool),
    restriction: Restriction,
) -> TechniqueResult {
    let tiled = restriction == Restriction::Tiles;
    let marked = restriction == Restriction::Stencil;
    let (volume_stage, resolve) = match marked {
        true => (&gpu.marked.volume, &gpu.marked.resolve),
        false => (&gpu.volume, &gpu.resolve),
    };
    let (Some(volume), Some(args)) = (gpu.generator.volume(), gpu.generator.args()) else {
        return Err(TechniqueError::not_prepared());
    };
    let showing = |view| debug && ctx.debug_view == Some(view);
    let tiles = gpu.tiles.as_ref().filter(|_| tiled);
    if let Some(tiles) = tiles {
        tiles.record_list(ctx, recorder, &light_pass_name(TILES_PASS, light))?;
        if showing(TILES_VIEW) {
            let name = light_pass_name(DEBUG_PASS, light);
            let view = (gpu.targets.view(TILES_VIEW)).ok_or_else(TechniqueError::not_prepared)?;
            tiles.record_overlay(ctx, recorder, view, &name)?;
        }
    }
    let band = (gpu.targets.view(BAND_TARGET)).ok_or_else(TechniqueError::not_prepared)?;
    let mark_group = match marked {
        true => Some(bind_mark(ctx, gpu)?),
        false => None,
    };
    let pieces = gpu.generator.pieces(light);
    for piece in 0..pieces {
        let generation = piece_pass_name(GENERATION_PASS, light, piece);
        gpu.generator
            .record(ctx, recorder, (light, piece), &generation)?;
        let last = piece + 1 == pieces;
        // The next piece counts on; the count view reads the stencil after the last.
        let keep = match !last || showing(COUNTS_VIEW) {
            true => wgpu::StoreOp::Store,
            false => wgpu::StoreOp::Discard,
        };
        // The stencil restriction counts against the G-buffer's depth (read only), in a
        // stencil it clears for each light.
        let (view, depth_ops, stencil_load) = match marked {
            true => (
                &ctx.gbuffer.depth_view,
                None,
                match piece {
                    0 => wgpu::LoadOp::Clear(0),
                    _ => wgpu::LoadOp::Load,
                },
            ),
            false => (
                band,
                Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: keep,
                }),
                wgpu::LoadOp::Load,
            ),
        };
        let depth = wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops,
            stencil_ops: Some(wgpu::Operations {
                load: stencil_load,
                store: keep,
            }),
        };
        if let Some(tiles) = tiles {
            tiles.take_vertex_count(recorder, args)?;
        }
        let name = piece_pass_name(VOLUME_PASS, light, piece);
        let mut pass = ctx.light_pass(recorder, &name, light, Some(depth));
        if let Some(group) = &mark_group {
            pass.set_stencil_reference(MARK_BIT);
            if piece == 0 {
                gpu.marked.mark.set_on(ctx, &mut pass, &[group], &[])?;
                pass.draw(0..3, 0..1);
            }
        }
        if let Some(tiles) = tiles {
            tiles.draw(ctx, &mut pass, volume)?;
        } else {
            volume_stage.set_on(ctx, &mut pass, &[], &[])?;
            pass.set_vertex_buffer(0, volume.slice(..));
            pass.draw_indirect(args, 0);
        }
        if last {
            resolve.set_on(ctx, &mut pass, &[], &[])?;
            pass.set_stencil_reference(0);
            pass.draw(0..3, 0..1);
        }
    }
    if showing(COUNTS_VIEW) {
        let name = light_pass_name(DEBUG_PASS, light);
        let view = (gpu.targets.view(COUNTS_VIEW)).ok_or_else(TechniqueError::not_prepared)?;
        let (counts, stencil) = match marked {
            true => (&gpu.marked.counts, &ctx.gbuffer.depth_view),
            false => (&gpu.counts, band),
        };
        counts.record(ctx, recorder, (stencil, view), &name)?;
    }
    Ok(())
}

/// The mark's group over the band's depth (made each frame: the band follows the screen).
fn bind_mark(ctx: &RenderContext<'_>, gpu: &Gpu) -> TechniqueResult<StageBindGroup> {
    let band = (gpu.targets.texture(BAND_TARGET)).ok_or_else(TechniqueError::not_prepared)?;
    let depth = band.create_view(&wgpu::TextureViewDescriptor {
        label: Some("hybrid band depth (mark)"),
        aspect: wgpu::TextureAspect::DepthOnly,
        ..Default::default()
    });
    let view = wgpu::BindingResource::TextureView(&depth);
    (gpu.marked.mark).bind(ctx, "hybrid mark", &[("band_depth", view)])
}

/// The band pass's uniform for one light's maps.
fn edge_light(p: &HybridParams, maps: &LightMaps, restriction: u32) -> EdgeLight {
    EdgeLight {
        map: MapHeader::new(maps, p.normal_offset),
        radius: p.radius,
        restriction,
        coverage: u32::from(p.coverage),
    }
}

/// Hybrid shadow maps and shadow volumes.
pub struct Hybrid {
    params: HybridParams,
    gpu: LazyGpu<Gpu>,
}

impl ShadowTechnique for Hybrid {
    fn resources(&self) -> Vec<ResourceInfo> {
        let Some(gpu) = self.gpu.built() else {
            return Vec::new();
        };
        let mut out = gpu.generator.resources();
        if let Some(maps) = gpu.maps.maps() {
            out.push(ResourceInfo::texture("shadow maps", &maps.texture, true));
        }
        out.extend(gpu.targets.resources());
        if let Some(coverage) = gpu.coverage.maps() {
            out.push(ResourceInfo::texture(
                COVERAGE_VIEW,
                &coverage.texture,
                true,
            ));
        }
        if let Some(ids) = gpu.ids.maps() {
            out.push(ResourceInfo::texture("triangle ids", &ids.texture, false));
        }
        out
    }

    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        let gpu = self.gpu.prepare(false, || Gpu::new(ctx, &self.params))?;
        gpu.targets.prepare(ctx);
        if changes.scene || ctx.lights.len() != gpu.lights || gpu.generator.volume().is_none() {
            let budget = self.params.volume_budget();
            gpu.generator.prepare(ctx, VolumeShape::default(), budget)?;
            gpu.lights = ctx.lights.len();
        } else if changes.lights {
            // The casters each light reaches, and so its pieces, follow the lights.
            gpu.generator.plan(ctx);
        }
        let replaced = gpu.maps.prepare(ctx, changes, self.params.map_size, true);
        if let Some(depth) = gpu.maps.maps() {
            let mut remade = replaced || gpu.band_groups[0].is_none();
            remade |= gpu.coverage.prepare(ctx, depth)?;
            if self.params.restriction == Restriction::TriangleIds {
                remade |= gpu.ids.prepare(ctx, depth)?;
                remade |= gpu.band_groups[1].is_none();
            }
            if remade {
                gpu.bind_band_groups(ctx)?;
            }
        }
        if self.params.restriction == Restriction::Tiles {
            if gpu.tiles.is_none() {
                gpu.tiles = Some(tiles_for(ctx, gpu.volume_bias)?);
            }
            let tiles = gpu.tiles.as_mut().expect("built above");
            let band = (gpu.targets.texture(BAND_TARGET)).expect("prepared above");
            tiles.prepare(ctx, band, ctx.size, self.params.tile_size)?;
        }
        Ok(())
    }

    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> TechniqueResult {
        let p = &self.params;
        let gpu = self.gpu.get_mut()?;
        let exact = p.restriction == Restriction::TriangleIds;
        if exact {
            gpu.maps.begin_frame(ctx);
        } else {
            gpu.maps.record(ctx, recorder, MAP_PASS)?;
        }
        let maps = &gpu.maps;
        let passes = maps.tile_passes();
        if exact {
            (gpu.ids).record(ctx, recorder, maps, (&passes, IDS_PASS))?;
        }
        if p.coverage {
            (gpu.coverage).record(ctx, recorder, maps, (&passes, COVERAGE_PASS))?;
        }
        let restriction = gpu.restriction_codes.code(p.restriction.index());
        let uniform = |l: &LightMaps, _| Some(edge_light(p, l, restriction));
        let lookups = match exact {
            true => gpu.band_ids.write(ctx, &gpu.maps, p.debug_light, uniform),
            false => gpu.band.write(ctx, &gpu.maps, p.debug_light, uniform),
        };
        let band_pass = if exact { &gpu.band_ids } else { &gpu.band };
        let group = gpu.band_groups[usize::from(exact)]
            .as_ref()
            .ok_or_else(TechniqueError::not_prepared)?;
        let (Some(band), Some(class)) =
            (gpu.targets.view(BAND_TARGET), gpu.targets.view(CLASS_VIEW))
        else {
            return Err(TechniqueError::not_prepared());
        };
        for (k, lookup) in lookups.iter().enumerate() {
            let light = lookup.maps.light;
            {
                let clear = zoo_host::gpu::clear_first(k == 0, wgpu::Color::TRANSPARENT);
                let class = [zoo_host::gpu::color_attachment(class, clear)];
                let depth = wgpu::RenderPassDepthStencilAttachment {
                    view: band,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0),
                        store: wgpu::StoreOp::Store,
                    }),
                };
                let groups = (&[group] as &[_], &[] as &[_]);
                band_pass.record_one(
                    ctx,
                    recorder,
                    &gpu.maps,
                    lookup,
                    &class,
                    Some(depth),
                    groups,
                )?;
            }
            if exact {
                continue;
            }
            record_volumes(ctx, recorder, gpu, (light, lookup.debug), p.restriction)?;
        }
        Ok(())
    }

    fn warnings(&self) -> Vec<String> {
        (self.gpu.built()).map_or(Vec::new(), |gpu| gpu.generator.warnings())
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        // Biases live in the map and volume pipelines (`flags(rebuild)`); the rest applies at
        // the next frame.
        Ok(self.params.update(values)?)
    }

    fn counters(&self) -> Vec<(String, f64)> {
        self.gpu.built().map_or(Vec::new(), |gpu| {
            let mut out = gpu.maps.counters();
            out.extend(gpu.generator.counters());
            out
        })
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        let gpu = self.gpu.built()?;
        match resource {
            "shadow maps" => gpu.maps.debug_image(self.params.debug_light),
            COVERAGE_VIEW => {
                let light = gpu.maps.debug_light(self.params.debug_light)?;
                Some(DebugImage {
                    view: &gpu.coverage.maps()?.layer_views[light.tiles[0].page as usize],
                    mapping: ViewMapping::Integer,
                })
            }
            _ => gpu.targets.debug_view(resource),
        }
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = HybridParams::from_values(values)?;
    Ok(Box::new(Hybrid {
        params,
        gpu: LazyGpu::default(),
    }))
}

zoo_host::register_technique! {
    id: "hybrid-edge",
    name: "Hybrid shadow maps and volumes",
    description: "Shadow maps classify lit, shadowed and edge pixels; shadow volumes (or exact tests against the map's triangle ids) resolve only the edge band",
    source: "seed 003 (hybrid SM/SV at shadow edges)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
    // Its edge band is resolved by volumes or by exact tests against triangle ids, and neither
    // follows a mask (nor do its coverage and id maps).
    masked_casters: zoo_host::MaskedCasters::Opaque,
    required_features: || wgpu::Features::DEPTH_CLIP_CONTROL,
    required_limits: || wgpu::Limits {
        // Volume generation: the frame group's lights and objects and the generation group's
        // eight buffers in one compute stage.
        max_storage_buffers_per_shader_stage: 10,
        ..wgpu::Limits::downlevel_defaults()
    },
    optional_features: || wgpu::Features::CLIP_DISTANCES,
    // Volumes are generated by compute shaders into storage buffers and drawn indirectly.
    required_downlevel: || {
        wgpu::DownlevelFlags::COMPUTE_SHADERS | wgpu::DownlevelFlags::INDIRECT_EXECUTION
    },
    params: HybridParams::schema,
    create: create,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_empty_id_matches_the_shader() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose(SHADER)
            .unwrap()
            .source;
        let value = zoo_host::gpu::layout::wgsl_integer_constant(&source, "NO_TRIANGLE");
        assert_eq!(value, Ok(i64::from(NO_TRIANGLE)));
    }

    #[test]
    fn every_restriction_has_a_shader_constant() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose(SHADER)
            .unwrap()
            .source;
        ChoiceCodes::read(&source, "RESTRICTION", Restriction::NAMES).unwrap();
    }
}
