//! The buffers of the irregular z-buffer for one frame size, grid resolution and number of
//! lights: the view samples, the grid (list heads, lengths, links and the queue of large
//! triangles), the shadowed flags and the per-light state (counters, the planes' bounds), with
//! each stage's bind group over them.

use zoo_host::glam::UVec2;
use zoo_host::kit::{Stage, StageBindGroup};
use zoo_host::prelude::*;
use zoo_ray_tracing::RayTracing;

/// Bytes of one view sample (`ViewSample` in the shader: two `vec4<f32>`).
const SAMPLE_BYTES: u64 = 32;
/// Counters a light (`COUNTERS` in the shader).
pub(crate) const COUNTERS: u64 = 6;
/// Views a light has at most: a cube's faces (`MAX_VIEWS` in the shader).
pub(crate) const MAX_VIEWS: u64 = 6;
/// Words of a view's bounds (`BOUNDS` in the shader).
pub(crate) const BOUNDS: u64 = 4;
/// Entries of the queue of large triangles (`QUEUE_CAPACITY` in the shader).
pub(crate) const QUEUE_CAPACITY: u64 = 65536;

/// What the buffers were made for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shape {
    pub size: UVec2,
    pub grid: u32,
    pub lights: usize,
}

impl Shape {
    /// Words of the grid buffer's heads and lengths.
    pub fn list_words(self) -> u64 {
        2 * MAX_VIEWS * self.view_words()
    }

    /// Words of one view's heads (or lengths).
    pub fn view_words(self) -> u64 {
        u64::from(self.grid).pow(2)
    }

    /// The byte ranges of the grid buffer that `views` views' heads and lengths take (cleared
    /// for each light: the sun has one view, point and spot lights six).
    pub fn list_ranges(self, views: u64) -> [std::ops::Range<u64>; 2] {
        let view_bytes = 4 * self.view_words();
        let lengths = MAX_VIEWS * view_bytes;
        [0..views * view_bytes, lengths..lengths + views * view_bytes]
    }

    /// Words of the state buffer's counters (cleared each frame).
    pub fn counter_words(self) -> u64 {
        self.lights.max(1) as u64 * COUNTERS
    }

    /// Bytes of every view's bounds in the state buffer (after the counters).
    pub fn bounds_bytes() -> u64 {
        4 * MAX_VIEWS * BOUNDS
    }
}

/// The stages that bind the buffers: samples, insertion, the two triangle passes, and the
/// resolve.
pub struct Stages<'a> {
    pub compute: [&'a Stage; 4],
    pub resolve: &'a Stage,
    /// The raster path's stage, when it is chosen.
    pub raster: Option<&'a Stage>,
}

/// The raster path's own resources: the grid-sized target its casters are drawn into and the
/// views' bounds its vertex stage reads.
pub struct RasterTarget {
    pub view: wgpu::TextureView,
    pub bounds: wgpu::Buffer,
    pub group: StageBindGroup,
}

/// The buffers and each stage's bind group over them.
pub struct IrregularGrid {
    pub shape: Shape,
    /// The grid: heads, lengths, links, queue.
    pub grid: wgpu::Buffer,
    /// Each light's counters, then the current light's bounds and queue length.
    pub state: wgpu::Buffer,
    /// The bind groups of the compute stages, in [`Stages::compute`]' order.
    pub groups: [StageBindGroup; 4],
    /// The resolve stage's bind group (the shadowed flags).
    pub resolve_group: StageBindGroup,
    /// The raster path's target, bounds and bind group, when it is chosen.
    pub raster: Option<RasterTarget>,
    /// The view samples (which the debug stages bind with the grid and the state).
    view_samples: wgpu::Buffer,
}

impl IrregularGrid {
    /// Buffers of `shape` for `tracing`'s casters, bound for `stages`; an error naming the
    /// grid when the device cannot bind it.
    pub fn new(
        ctx: &RenderContext<'_>,
        stages: Stages<'_>,
        tracing: &RayTracing,
        shape: Shape,
    ) -> TechniqueResult<IrregularGrid> {
        let pixels = u64::from(shape.size.x) * u64::from(shape.size.y);
        let grid_bytes = 4 * (shape.list_words() + pixels + QUEUE_CAPACITY);
        let sample_bytes = pixels * SAMPLE_BYTES;
        let limit = ctx.gpu.device.limits().max_storage_buffer_binding_size;
        let (size, grid) = (shape.size, shape.grid);
        let too_large = [
            (
                grid_bytes,
                format!("the grid of {grid}x{grid} texels a face and its lists"),
            ),
            (
                sample_bytes,
                format!("the view samples of {}x{} pixels", size.x, size.y),
            ),
        ];
        if let Some((bytes, what)) = too_large.into_iter().find(|(bytes, _)| *bytes > limit) {
            return Err(TechniqueError::Unavailable {
                id: "frustum-traced".into(),
                reason: format!(
                    "{what} take {bytes} bytes, the device binds at most {limit}; lower `grid` \
                     or the resolution"
                ),
            });
        }
        let device = &ctx.gpu.device;
        let storage = |label: &str, bytes: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let view_samples = storage("frustum-traced view samples", sample_bytes);
        let grid = storage("frustum-traced grid", grid_bytes);
        let shadowed = storage("frustum-traced shadowed", pixels * 4);
        let state_words = shape.counter_words() + MAX_VIEWS * BOUNDS + 1;
        let state = storage("frustum-traced state", state_words * 4);
        let batches = tracing.batch_buffer(ctx, "frustum-traced caster batches");
        let resources = [
            ("caster_batches", batches.as_entire_binding()),
            ("view_samples", view_samples.as_entire_binding()),
            ("grid", grid.as_entire_binding()),
            ("shadowed", shadowed.as_entire_binding()),
            ("state", state.as_entire_binding()),
        ];
        let bind = |stage: &Stage| stage.bind(ctx, "frustum-traced buffers", &resources);
        let [samples, insert, triangles, big] = stages.compute;
        let raster = match stages.raster {
            Some(stage) => Some(RasterTarget::new(ctx, stage, shape, &resources)?),
            None => None,
        };
        Ok(IrregularGrid {
            shape,
            groups: [bind(samples)?, bind(insert)?, bind(triangles)?, bind(big)?],
            raster,
            resolve_group: stages.resolve.bind(
                ctx,
                "frustum-traced resolve",
                &[("shadowed", shadowed.as_entire_binding())],
            )?,
            grid,
            state,
            view_samples,
        })
    }

    /// The bind group of debug stage `stage`, writing into `texture` (bound as `name`).
    pub fn debug_group(
        &self,
        ctx: &RenderContext<'_>,
        stage: &Stage,
        (name, texture): (&str, &wgpu::TextureView),
    ) -> TechniqueResult<StageBindGroup> {
        let resources = [
            ("view_samples", self.view_samples.as_entire_binding()),
            ("grid", self.grid.as_entire_binding()),
            ("state", self.state.as_entire_binding()),
            (name, wgpu::BindingResource::TextureView(texture)),
        ];
        stage.bind(ctx, "frustum-traced debug view", &resources)
    }
}

impl RasterTarget {
    fn new(
        ctx: &RenderContext<'_>,
        stage: &Stage,
        shape: Shape,
        resources: &[(&str, wgpu::BindingResource<'_>)],
    ) -> TechniqueResult<RasterTarget> {
        let device = &ctx.gpu.device;
        let (_, view) = zoo_host::gpu::render_target(
            device,
            "frustum-traced raster target",
            UVec2::splat(shape.grid),
            RASTER_FORMAT,
            wgpu::TextureUsages::empty(),
        );
        let bounds = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frustum-traced raster bounds"),
            size: Shape::bounds_bytes(),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut all: Vec<(&str, wgpu::BindingResource<'_>)> = resources.to_vec();
        all.push(("raster_bounds", bounds.as_entire_binding()));
        let group = stage.bind(ctx, "frustum-traced raster", &all)?;
        Ok(RasterTarget {
            view,
            bounds,
            group,
        })
    }
}

/// The raster path's target format (its colour is never written).
pub const RASTER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;
