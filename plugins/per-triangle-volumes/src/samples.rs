//! The buffers of the volume passes for one frame size and number of lights: the view samples
//! (each pixel's hard shadow ray), the hierarchy's boxes, the shadowed flags, the casters'
//! batches and the counters, with each stage's bind group over them.

use zoo_host::kit::{Stage, StageBindGroup};
use zoo_host::prelude::*;
use zoo_ray_tracing::RayTracing;

/// Bytes of one view sample (`ViewSample` in the shader: two `vec4<f32>`).
const SAMPLE_BYTES: u64 = 32;
/// Bytes of one node's box (two `vec4<f32>`).
const NODE_BYTES: u64 = 32;
/// Depth clusters a tile holds (`CLUSTERS` in the shader).
pub(crate) const CLUSTERS: u64 = 2;
/// Children per side of a node, and pixels per side of a tile (`BRANCHING` in the shader).
pub(crate) const BRANCHING: u32 = 8;
/// Pixels per side of a node of each level: tiles, then 8x8 tiles twice.
pub(crate) const LEVEL_SPANS: [u32; 3] = [BRANCHING, BRANCHING.pow(2), BRANCHING.pow(3)];

/// Counters a light (`COUNTERS` in the shader): triangles down the hierarchy, nodes
/// classified, samples tested exactly.
pub(crate) const COUNTERS: u64 = 3;

/// The stages that bind the buffers: samples, the two reductions, triangles and resolve.
pub type Stages<'a> = (&'a Stage, &'a [Stage; 2], &'a Stage, &'a Stage);

/// The buffers and each stage's bind group over them.
pub struct ViewSamples {
    size: zoo_host::glam::UVec2,
    lights: usize,
    /// Each light's [`COUNTERS`], written by the volume passes.
    pub counts: wgpu::Buffer,
    /// The bind groups of the samples, the two reductions and the triangle stages.
    pub groups: [StageBindGroup; 4],
    /// The resolve stage's bind group (the shadowed flags).
    pub resolve_group: StageBindGroup,
}

impl ViewSamples {
    /// Buffers for `ctx`'s frame size and `tracing`'s casters, bound for `stages`.
    pub fn new(
        ctx: &RenderContext<'_>,
        (samples, reduce, triangles, resolve): Stages<'_>,
        tracing: &RayTracing,
    ) -> TechniqueResult<ViewSamples> {
        let size = ctx.size;
        let pixels = u64::from(size.x) * u64::from(size.y);
        // Level 0 holds [`CLUSTERS`] nodes a tile.
        let nodes: u64 = (LEVEL_SPANS.iter().zip([CLUSTERS, 1, 1]))
            .map(|(span, count)| {
                count * u64::from(size.x.div_ceil(*span)) * u64::from(size.y.div_ceil(*span))
            })
            .sum();
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
        let view_samples = storage("per-triangle volumes view samples", pixels * SAMPLE_BYTES);
        let node_bounds = storage("per-triangle volumes node boxes", nodes * NODE_BYTES);
        let shadowed = storage("per-triangle volumes shadowed", pixels * 4);
        let batches = tracing.batch_buffer(ctx, "per-triangle volumes caster batches");
        let lights = ctx.lights.len();
        let counts = storage(
            "per-triangle volumes counters",
            lights.max(1) as u64 * COUNTERS * 4,
        );
        let resources = [
            ("counts", counts.as_entire_binding()),
            ("view_samples", view_samples.as_entire_binding()),
            ("node_bounds", node_bounds.as_entire_binding()),
            ("shadowed", shadowed.as_entire_binding()),
            ("caster_batches", batches.as_entire_binding()),
        ];
        let bind = |stage: &Stage| stage.bind(ctx, "per-triangle volumes buffers", &resources);
        Ok(ViewSamples {
            size,
            lights,
            groups: [
                bind(samples)?,
                bind(&reduce[0])?,
                bind(&reduce[1])?,
                bind(triangles)?,
            ],
            resolve_group: resolve.bind(
                ctx,
                "per-triangle volumes resolve",
                &[("shadowed", shadowed.as_entire_binding())],
            )?,
            counts,
        })
    }

    /// Whether they were made for `ctx`'s frame size and number of lights.
    pub fn fits(&self, ctx: &RenderContext<'_>) -> bool {
        self.size == ctx.size && self.lights == ctx.lights.len()
    }
}
