//! The page table, the physical pool and the passes that keep them: the GPU side of virtual
//! shadow maps (`shaders/virtual-maps/`). Nothing is read back but the counters, a frame or
//! two late: which pages are needed, allocated, evicted and drawn is decided on the GPU.

use std::sync::Mutex;

use zoo_host::gpu::GpuType;
use zoo_host::gpu::readback::ReadbackRing;
use zoo_host::gpu::{PassRecorder, gpu_bytes};
use zoo_host::kit::{self, Stage, StageBindGroup, UniformSlots};
use zoo_host::render::drawn_runs;
use zoo_host::wgpu::util::DeviceExt;
use zoo_host::{RenderContext, TechniqueResult, wgpu};
use zoo_shadow_maps::MEMORY_BUDGET;

use crate::layers::Layout;
use crate::{CasterBox, CasterRun, VirtualFrame, VirtualLayer, VirtualLight};

/// The bookkeeping and drawing shaders.
pub const BOOKKEEPING: &str = "virtual-maps/bookkeeping.wgsl";
pub const DRAW: &str = "virtual-maps/draw.wgsl";
/// The culling of casters per page.
pub const CULL: &str = "virtual-maps/cull.wgsl";
/// The bookkeeping's debug views.
const DEBUG: &str = "virtual-maps/debug.wgsl";
/// The format of the debug views' images.
const DEBUG_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Texels around each page that filters may read (`gutter` in the shaders' frame).
pub const GUTTER: u32 = 2;
/// Candidate lists of the allocation (`CANDIDATE_LISTS` in the shaders).
pub const CANDIDATE_LISTS: u64 = 5;
/// Counters of the bookkeeping (`COUNTS` and `COUNT_*` in `bookkeeping.wgsl`).
pub const COUNTS: u64 = 16;
pub const COUNT_DRAWN: usize = 6;
pub const COUNT_NEEDED: usize = 7;
pub const COUNT_HITS: usize = 8;
pub const COUNT_EVICTED: usize = 9;
pub const COUNT_NO_ROOM: usize = 10;
pub const COUNT_FALLBACK_PIXELS: usize = 11;
pub const COUNT_RESIDENT_BEFORE: usize = 12;
pub const COUNT_INSTANCES: usize = 13;
/// Invocations a row of a spread dispatch holds: as many 64-wide workgroups as a dispatch
/// takes along one axis (`item` in `bookkeeping.wgsl`).
const ROW: u32 = 65535 * 64;

/// The extent of a dispatch over `items` 64-wide items: one row, or rows of [`ROW`].
fn spread(items: u32) -> [u32; 3] {
    match items <= ROW {
        true => [items, 1, 1],
        false => [ROW, items.div_ceil(ROW), 1],
    }
}

/// Slots a side of a pool of about `pool_pages` slots of `slot` texels a side: a square,
/// within the device's largest texture (`largest` texels a side) and the memory budget the
/// shadow-map atlas keeps to ([`MEMORY_BUDGET`]).
fn pool_side(pool_pages: u32, slot: u32, largest: u32) -> u32 {
    let slot_bytes = u64::from(slot).pow(2) * POOL_FORMAT.block_copy_size(None).unwrap_or(4) as u64;
    let budget = ((MEMORY_BUDGET / slot_bytes) as f64).sqrt() as u32;
    let side = f64::from(pool_pages).sqrt().ceil() as u32;
    side.min(largest / slot).min(budget).max(1)
}

/// The depth format of the pool.
pub const POOL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The bookkeeping's compute entries, in the order they run (`count_fallback` after the
/// draws).
const BOOKKEEPING_ENTRIES: [&str; 8] = [
    "cs_invalidate",
    "cs_mark",
    "cs_age",
    "cs_gather",
    "cs_allocate_fallback",
    "cs_allocate_finer",
    "cs_draw_args",
    "cs_count_fallback",
];

/// The compute and render stages, built once.
pub struct Stages {
    /// One per [`BOOKKEEPING_ENTRIES`].
    bookkeeping: Vec<Stage>,
    cull: Stage,
    /// The page table's debug view, and the pool's.
    debug: [Stage; 2],
    clear: Stage,
    /// Opaque casters, and alpha-tested ones.
    casters: [Stage; 2],
    runs: UniformSlots<CasterRun>,
}

impl Stages {
    pub fn new(ctx: &RenderContext<'_>, slope_bias: f32) -> TechniqueResult<Stages> {
        let compute = |entry| Stage::compute(BOOKKEEPING, entry).build(ctx);
        let runs = UniformSlots::new(
            ctx.gpu,
            "virtual-maps caster runs",
            1,
            wgpu::ShaderStages::VERTEX,
        );
        let depth = |compare, bias: f32| wgpu::DepthStencilState {
            format: POOL_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: wgpu::DepthBiasState {
                constant: 0,
                slope_scale: bias,
                clamp: 0.0,
            },
        };
        Ok(Stages {
            bookkeeping: BOOKKEEPING_ENTRIES
                .map(compute)
                .into_iter()
                .collect::<Result<_, _>>()?,
            cull: Stage::compute(CULL, "cs_cull").build(ctx)?,
            debug: [
                Stage::compute(DEBUG, "cs_page_table").build(ctx)?,
                Stage::compute(DEBUG, "cs_pool").build(ctx)?,
            ],
            clear: Stage::render(DRAW, "vs_clear")
                .depth_stencil(depth(wgpu::CompareFunction::Always, 0.0))
                .build(ctx)?,
            casters: [
                Stage::render(DRAW, "vs_caster")
                    .shared(&[&runs.at(0)])
                    .depth_stencil(depth(wgpu::CompareFunction::LessEqual, slope_bias))
                    .build(ctx)?,
                Stage::render(DRAW, "vs_caster_masked")
                    .fragment("fs_caster_masked")
                    .shared(&[&runs.at(0)])
                    .depth_stencil(depth(wgpu::CompareFunction::LessEqual, slope_bias))
                    .build(ctx)?,
            ],
            runs,
        })
    }
}

/// A debug view of the bookkeeping, drawn when shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DebugView {
    PageTable,
    Cache,
}

/// The debug views' images (a texel per page-table entry of one level, and per physical
/// page) and each view's bind group.
pub struct DebugImages {
    pub page_table: wgpu::Texture,
    pub page_table_view: wgpu::TextureView,
    pub pool: wgpu::Texture,
    pub pool_view: wgpu::TextureView,
    groups: [Vec<StageBindGroup>; 2],
}

/// A debug image of `width` x `height` texels that compute stages write.
fn debug_image(
    ctx: &RenderContext<'_>,
    label: &str,
    width: u32,
    height: u32,
) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = ctx.gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: DEBUG_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some(label),
        ..Default::default()
    });
    (texture, view)
}

/// The buffers and pool of one layout, and every stage's bind groups over them.
pub struct Pages {
    pub layout: Layout,
    pub pool_side: u32,
    pub pool: wgpu::Texture,
    pub pool_view: wgpu::TextureView,
    pub page_table: wgpu::Buffer,
    needed: wgpu::Buffer,
    counts: wgpu::Buffer,
    frame: wgpu::Buffer,
    layers: wgpu::Buffer,
    lights: wgpu::Buffer,
    draw_args: wgpu::Buffer,
    /// Caster runs: (index range, object range, alpha-tested) of the scene's casters, and
    /// where each one's instances start.
    runs: Vec<(std::ops::Range<u32>, std::ops::Range<u32>, bool)>,
    instances_at: Vec<u32>,
    /// Caster objects: a dispatch over every (pool page, object) pair culls them.
    casters: u32,
    /// Each bookkeeping stage's groups, the clear's and the casters' draws', and the lookup's
    /// tables.
    bookkeeping: Vec<Vec<StageBindGroup>>,
    cull: Vec<StageBindGroup>,
    pub debug: DebugImages,
    draw: [Vec<StageBindGroup>; 3],
    pub lookup_tables: Vec<StageBindGroup>,
    stats: Mutex<ReadbackRing>,
    /// Where the layers lay in the last frame, to find those that moved.
    pub last_layers: Vec<crate::layers::LayerView>,
}

/// A storage buffer of `bytes` (at least 16, uninitialised).
fn storage(
    ctx: &RenderContext<'_>,
    label: &str,
    bytes: u64,
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
        mapped_at_creation: false,
    })
}

fn init(
    ctx: &RenderContext<'_>,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let mut bytes = contents.to_vec();
    bytes.resize(bytes.len().max(16), 0);
    ctx.gpu
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: &bytes,
            usage,
        })
}

impl Pages {
    /// Buffers, pool and bind groups for `layout` with a pool of about `pool_pages` pages.
    pub fn new(
        ctx: &RenderContext<'_>,
        stages: &Stages,
        lookup: &Stage,
        layout: Layout,
        pool_pages: u32,
    ) -> TechniqueResult<Pages> {
        let slot = layout.sizes.page_size + 2 * GUTTER;
        let pool_side = pool_side(
            pool_pages,
            slot,
            ctx.gpu.device.limits().max_texture_dimension_2d,
        );
        let texels = pool_side * slot;
        let pool = ctx.gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("virtual-maps physical pool"),
            size: wgpu::Extent3d {
                width: texels,
                height: texels,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: POOL_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let pool_view = pool.create_view(&wgpu::TextureViewDescriptor {
            label: Some("virtual-maps physical pool"),
            ..Default::default()
        });
        let entries = u64::from(layout.entries());
        let pages = u64::from(pool_side * pool_side);
        let limits = ctx.gpu.device.limits();
        let largest = (limits.max_storage_buffer_binding_size).min(limits.max_buffer_size);
        if 4 * entries > largest {
            return Err(zoo_host::TechniqueError::Other(format!(
                "virtual-maps: {} lights need a page table of {entries} entries ({} MiB), more \
                 than the device binds ({} MiB); lower `pages`",
                layout.lights.len(),
                (4 * entries) >> 20,
                largest >> 20
            )));
        }
        let none = wgpu::BufferUsages::empty();
        let storage_init = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let page_table = init(
            ctx,
            "virtual-maps page table",
            &vec![0xff; (4 * entries) as usize],
            storage_init,
        );
        let needed = storage(ctx, "virtual-maps needed pages", 4 * entries, none);
        let pool_pages_buffer = init(
            ctx,
            "virtual-maps physical pages",
            &vec![0xff; (16 * pages) as usize],
            storage_init,
        );
        let lists = storage(
            ctx,
            "virtual-maps page lists",
            4 * pages * (CANDIDATE_LISTS + 1),
            none,
        );
        let counts = storage(
            ctx,
            "virtual-maps counts",
            4 * COUNTS,
            wgpu::BufferUsages::COPY_SRC,
        );
        let entry_layers = init(
            ctx,
            "virtual-maps entry layers",
            zoo_host::bytemuck::cast_slice(&layout.entry_layers),
            storage_init,
        );
        let frame = ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("virtual-maps frame"),
            size: VirtualFrame::SIZE as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layers = storage(
            ctx,
            "virtual-maps layers",
            (VirtualLayer::SIZE * layout.layers.len()) as u64,
            none,
        );
        let virtual_lights = storage(
            ctx,
            "virtual-maps lights",
            (VirtualLight::SIZE * layout.lights.len()) as u64,
            none,
        );
        let runs: Vec<_> = [false, true]
            .into_iter()
            .flat_map(|masked| {
                let kind = |_: usize, o: &zoo_host::scene::SceneObject| {
                    o.casts_shadows && o.alpha_mask.is_some() == masked
                };
                let runs = drawn_runs(ctx.scene, kind).into_iter();
                runs.map(move |(indices, objects)| (indices, objects, masked))
            })
            .collect();
        // Each run's instances: room for every pool page times its objects.
        let instances_at: Vec<u32> = (runs.iter())
            .scan(0u64, |at, (_, objects, _)| {
                let first = *at;
                *at += pages * objects.len() as u64;
                Some(first as u32)
            })
            .collect();
        let casters: u64 = runs
            .iter()
            .map(|(_, objects, _)| objects.len() as u64)
            .sum();
        if 4 * pages * casters > largest {
            return Err(zoo_host::TechniqueError::Other(format!(
                "virtual-maps: {casters} caster objects in each of {pages} pool pages need an \
                 instance list of {} MiB, more than the device binds ({} MiB); lower \
                 `pool_pages`",
                (4 * pages * casters) >> 20,
                largest >> 20
            )));
        }
        let run_words: Vec<u32> = (runs.iter().zip(&instances_at))
            .flat_map(|((indices, objects, _), &at)| {
                [
                    indices.len() as u32,
                    indices.start,
                    objects.len() as u32,
                    at,
                ]
            })
            .collect();
        let boxes: Vec<CasterBox> = (runs.iter().enumerate())
            .flat_map(|(run, (_, objects, _))| {
                objects.clone().enumerate().map(move |(local, object)| {
                    let (lo, hi) = ctx.scene.objects[object as usize]
                        .bounds
                        .unwrap_or_default();
                    CasterBox {
                        lo,
                        run: run as u32,
                        hi,
                        local: local as u32,
                    }
                })
            })
            .collect();
        // One box at least, for the binding's size (with no casters none is read).
        let one = [CasterBox::default()];
        let boxes = if boxes.is_empty() {
            &one[..]
        } else {
            &boxes[..]
        };
        let caster_boxes = init(
            ctx,
            "virtual-maps caster boxes",
            &gpu_bytes(boxes),
            storage_init,
        );
        let instances = storage(
            ctx,
            "virtual-maps caster instances",
            4 * pages * casters,
            none,
        );
        let caster_runs = init(
            ctx,
            "virtual-maps caster runs",
            zoo_host::bytemuck::cast_slice(&run_words),
            storage_init,
        );
        // The clear's arguments and one run's at least (an empty run list is read as one
        // empty run).
        let draw_args = storage(
            ctx,
            "virtual-maps draw arguments",
            16 * (runs.len().max(1) as u64 + 1),
            wgpu::BufferUsages::INDIRECT,
        );
        // Every stage's group 3: the tables (`virtual-maps/tables.wgsl`, bindings 0 to 2),
        // then the stage's own bindings (WebGPU gives a pipeline four groups).
        let table_list = [
            ("virtual_frame", frame.as_entire_binding()),
            ("virtual_layers", layers.as_entire_binding()),
            ("virtual_lights", virtual_lights.as_entire_binding()),
        ];
        let own = [
            ("page_table", page_table.as_entire_binding()),
            ("needed", needed.as_entire_binding()),
            ("pool_pages", pool_pages_buffer.as_entire_binding()),
            ("lists", lists.as_entire_binding()),
            ("counts", counts.as_entire_binding()),
            ("entry_layers", entry_layers.as_entire_binding()),
            ("draw_args", draw_args.as_entire_binding()),
            ("caster_runs", caster_runs.as_entire_binding()),
        ];
        let draw_own = [
            ("page_table", page_table.as_entire_binding()),
            ("entry_layers", entry_layers.as_entire_binding()),
            ("lists", lists.as_entire_binding()),
            (
                "scene_vertices",
                ctx.scene_buffers.vertices.as_entire_binding(),
            ),
            (
                "scene_indices",
                ctx.scene_buffers.indices.as_entire_binding(),
            ),
            ("instances", instances.as_entire_binding()),
        ];
        let cull_own = [
            ("entry_layers", entry_layers.as_entire_binding()),
            ("lists", lists.as_entire_binding()),
            ("draw_args", draw_args.as_entire_binding()),
            ("caster_runs", caster_runs.as_entire_binding()),
            ("caster_boxes", caster_boxes.as_entire_binding()),
            ("instances", instances.as_entire_binding()),
            ("counts", counts.as_entire_binding()),
        ];
        let sampler = |label, filter| {
            ctx.gpu.device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                mag_filter: filter,
                min_filter: filter,
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..Default::default()
            })
        };
        let compare = sampler("virtual-maps pool comparison", wgpu::FilterMode::Nearest);
        let linear = sampler(
            "virtual-maps pool bilinear comparison",
            wgpu::FilterMode::Linear,
        );
        let values_view = pool.create_view(&wgpu::TextureViewDescriptor {
            label: Some("virtual-maps physical pool depths"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        let stats = ReadbackRing::new(&ctx.gpu.device, "virtual-maps counters", 4 * COUNTS, 3);
        let bookkeeping = (stages.bookkeeping.iter())
            .map(|stage| {
                stage.bind_own(
                    ctx,
                    "virtual-maps bookkeeping",
                    &[&with_tables(&table_list, &own)],
                )
            })
            .collect::<Result<_, _>>()?;
        let draw_list = with_tables(&table_list, &draw_own);
        let draw_lists: [&[(&str, wgpu::BindingResource<'_>)]; 1] = [&draw_list];
        let cull = (stages.cull).bind_own(
            ctx,
            "virtual-maps culling",
            &[&with_tables(&table_list, &cull_own)],
        )?;
        // Faces side by side, a texel per page of a face's finest level.
        let side = layout.sizes.pages;
        let (table_image, table_view) =
            debug_image(ctx, "virtual-maps page table view", 6 * side, side);
        let (pool_image, pool_image_view) =
            debug_image(ctx, "virtual-maps page cache view", pool_side, pool_side);
        let debug_own = [
            ("page_table", page_table.as_entire_binding()),
            ("needed", needed.as_entire_binding()),
            ("pool_pages", pool_pages_buffer.as_entire_binding()),
            (
                "page_table_image",
                wgpu::BindingResource::TextureView(&table_view),
            ),
            (
                "pool_image",
                wgpu::BindingResource::TextureView(&pool_image_view),
            ),
        ];
        let debug_group = |stage: &Stage| {
            stage.bind_own(
                ctx,
                "virtual-maps debug view",
                &[&with_tables(&table_list, &debug_own)],
            )
        };
        let debug = DebugImages {
            groups: [
                debug_group(&stages.debug[0])?,
                debug_group(&stages.debug[1])?,
            ],
            page_table: table_image,
            page_table_view: table_view,
            pool: pool_image,
            pool_view: pool_image_view,
        };
        Ok(Pages {
            bookkeeping,
            cull,
            debug,
            draw: [
                stages
                    .clear
                    .bind_own(ctx, "virtual-maps clear", &draw_lists)?,
                stages.casters[0].bind_own(ctx, "virtual-maps draw", &draw_lists)?,
                stages.casters[1].bind_own(ctx, "virtual-maps masked draw", &draw_lists)?,
            ],
            lookup_tables: lookup.bind_own(
                ctx,
                "virtual-maps lookup",
                &[&with_tables(
                    &table_list,
                    &[
                        ("page_table", page_table.as_entire_binding()),
                        ("pool", wgpu::BindingResource::TextureView(&pool_view)),
                        ("pool_linear", wgpu::BindingResource::Sampler(&linear)),
                        (
                            "pool_nearest",
                            wgpu::BindingResource::TextureView(&pool_view),
                        ),
                        ("pool_compare", wgpu::BindingResource::Sampler(&compare)),
                        (
                            "pool_values",
                            wgpu::BindingResource::TextureView(&values_view),
                        ),
                    ],
                )],
            )?,
            layout,
            pool_side,
            pool,
            pool_view,
            page_table,
            needed,
            counts,
            frame,
            layers,
            lights: virtual_lights,
            draw_args,
            runs,
            instances_at,
            casters: casters as u32,
            stats: Mutex::new(stats),
            last_layers: Vec::new(),
        })
    }

    /// Writes this frame's settings, layers and lights.
    pub fn write(
        &self,
        ctx: &RenderContext<'_>,
        frame: &VirtualFrame,
        layers: &[VirtualLayer],
        lights: &[VirtualLight],
    ) {
        let queue = &ctx.gpu.queue;
        queue.write_buffer(&self.frame, 0, &gpu_bytes(std::slice::from_ref(frame)));
        queue.write_buffer(&self.layers, 0, &gpu_bytes(layers));
        queue.write_buffer(&self.lights, 0, &gpu_bytes(lights));
    }

    /// Records the frame's bookkeeping, the page draws and the fallback count.
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        stages: &mut Stages,
        shown: Option<DebugView>,
    ) -> TechniqueResult {
        let runs: Vec<CasterRun> = (self.runs.iter().zip(&self.instances_at))
            .map(|((_, objects, _), &instances_at)| CasterRun {
                first_object: objects.start,
                objects: objects.len() as u32,
                instances_at,
            })
            .collect();
        stages.runs.write(ctx.gpu, &runs);
        let stages = &*stages;
        let encoder = recorder.encoder();
        encoder.clear_buffer(&self.needed, 0, None);
        encoder.clear_buffer(&self.counts, 0, None);
        let entries = spread(self.layout.entries());
        let pool = [self.pool_side * self.pool_side, 1, 1];
        let pixels = [ctx.size.x, ctx.size.y, 1];
        // Each entry's extent, in `BOOKKEEPING_ENTRIES` order.
        let extents = [
            entries,
            pixels,
            entries,
            pool,
            entries,
            entries,
            [1, 1, 1],
            pixels,
        ];
        let dispatch = |pass: &mut wgpu::ComputePass<'_>, k: usize| {
            let own: Vec<&StageBindGroup> = self.bookkeeping[k].iter().collect();
            let groups = (&own[..], &[] as &[&dyn kit::SharedGroup]);
            stages.bookkeeping[k].dispatch_in(ctx, pass, groups, extents[k])
        };
        {
            let mut pass = recorder.compute_pass("Virtual pages: bookkeeping");
            for k in 0..BOOKKEEPING_ENTRIES.len() - 1 {
                dispatch(&mut pass, k)?;
            }
            let own: Vec<&StageBindGroup> = self.cull.iter().collect();
            let groups = (&own[..], &[] as &[&dyn kit::SharedGroup]);
            let pairs = spread(self.pool_side * self.pool_side * self.casters);
            stages.cull.dispatch_in(ctx, &mut pass, groups, pairs)?;
        }
        self.draw(ctx, recorder, stages)?;
        let mut pass = recorder.compute_pass("Virtual pages: fallback count");
        dispatch(&mut pass, BOOKKEEPING_ENTRIES.len() - 1)?;
        drop(pass);
        if let Some(view) = shown {
            let (k, extent) = match view {
                DebugView::PageTable => (0, self.debug.page_table.size()),
                DebugView::Cache => (1, self.debug.pool.size()),
            };
            let own: Vec<&StageBindGroup> = self.debug.groups[k].iter().collect();
            (stages.debug[k]).dispatch(
                ctx,
                recorder,
                "Virtual pages: debug view",
                &own,
                &[],
                [extent.width, extent.height, 1],
            )?;
        }
        let ring = self.stats.lock().ok();
        if let Some(target) = ring.and_then(|mut ring| ring.target().cloned()) {
            recorder
                .encoder()
                .copy_buffer_to_buffer(&self.counts, 0, &target, 0, 4 * COUNTS);
        }
        Ok(())
    }

    /// Clears the pages allocated this frame and draws every caster run into them.
    fn draw(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        stages: &Stages,
    ) -> TechniqueResult {
        let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some("Virtual pages: draw"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.pool_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let clear: Vec<&StageBindGroup> = self.draw[0].iter().collect();
        stages.clear.set_on(ctx, &mut pass, &clear, &[])?;
        pass.draw_indirect(&self.draw_args, 0);
        for (run, (_, _, masked)) in self.runs.iter().enumerate() {
            let kind = usize::from(*masked);
            let own: Vec<&StageBindGroup> = self.draw[1 + kind].iter().collect();
            let slot = stages.runs.at(run);
            stages.casters[kind].set_on(ctx, &mut pass, &own, &[&slot])?;
            pass.draw_indirect(&self.draw_args, 16 * (run as u64 + 1));
        }
        Ok(())
    }

    /// The newest counters that have arrived (none until one has; never waits).
    pub fn counts(&self, device: &wgpu::Device) -> Option<Vec<u32>> {
        let mut ring = self.stats.lock().ok()?;
        let (_, bytes) = ring.latest(device)?;
        Some(
            bytes
                .chunks_exact(4)
                .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
                .collect(),
        )
    }
}

/// A resource named as its WGSL variable.
type Named<'a> = (&'static str, wgpu::BindingResource<'a>);

/// The tables' resources, then a stage's own.
fn with_tables<'a>(tables: &[Named<'a>], own: &[Named<'a>]) -> Vec<Named<'a>> {
    tables.iter().chain(own).cloned().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pool_keeps_to_the_texture_size_and_the_shadow_map_budget() {
        // 1024 slots of 132² texels: 32 a side, 68 MiB.
        assert_eq!(pool_side(1024, 132, 16384), 32);
        assert_eq!(pool_side(1000, 132, 16384), 32);
        // The device's largest texture: 8192 / 132 slots a side.
        assert_eq!(pool_side(16384, 132, 8192), 62);
        // 16384 slots of 516² texels would be 16 GiB: the 1 GiB budget leaves 31 a side.
        let side = pool_side(16384, 516, 1 << 20);
        assert_eq!(side, 31);
        assert!(u64::from(side * 516).pow(2) * 4 <= MEMORY_BUDGET);
    }

    #[test]
    fn dispatches_past_one_axis_spread_over_rows() {
        assert_eq!(spread(100), [100, 1, 1]);
        assert_eq!(spread(ROW), [ROW, 1, 1]);
        assert_eq!(spread(ROW + 1), [ROW, 2, 1]);
        // The shader's rows are 64-wide workgroups, as many as one axis takes.
        let source = zoo_host::ShaderLibrary::embedded()
            .compose(BOOKKEEPING)
            .unwrap()
            .source;
        for entry in [
            "cs_invalidate",
            "cs_age",
            "cs_allocate_fallback",
            "cs_allocate_finer",
        ] {
            let size = zoo_host::gpu::layout::wgsl_workgroup_size(&source, entry);
            assert_eq!(size, Ok([64, 1, 1]), "{entry}");
        }
        let limits = wgpu::Limits::downlevel_defaults();
        assert_eq!(ROW / 64, limits.max_compute_workgroups_per_dimension);
    }
}
