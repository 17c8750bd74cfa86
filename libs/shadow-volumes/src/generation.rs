//! Volumes built on the GPU from the scene's edge adjacency, one light at a time.
//!
//! A compute pass weights every shadow-casting triangle (+1 facing the light, -1 facing away on
//! an open or non-manifold mesh, 0 otherwise) and emits its near cap (and, for point and spot
//! lights, the far cap at infinity); a second pass emits |m| side quads per edge, m being the
//! sum of its faces' weights times their traversal signs, so sides shared by two emitting
//! triangles cancel and boundary or non-manifold edges close the volume. The vertices (w = 0 at
//! infinity) land in one buffer drawn with indirect arguments.
//!
//! Both passes run once per unit of the work ([`crate::pieces`]): the triangles stored in world
//! space, then each shadow-casting instance's shared triangles and edges under its placement,
//! so instances share their geometry here as in every other pass. Where the volumes may need
//! more vertices than one buffer the device binds (or the budget given) holds, each light's
//! units are generated and drawn in pieces that fit it, one buffer reused by all.

use zoo_host::glam::Mat4;
use zoo_host::gpu::PassRecorder;
use zoo_host::kit::{SharedGroup, Stage, StageBindGroup, UniformSlots};
use zoo_host::scene::{EdgeKind, Scene};
use zoo_host::technique::ResourceInfo;
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};

use crate::culling::reaches_box;
use crate::pieces::{Unit, pack, units};

zoo_host::param_choice! {
    /// How volumes are built.
    pub enum Volumes { Silhouette, PerTriangle }
}

/// The shape of the volumes: how they are built, whether caps close them and how far their
/// sides reach. The default is exact: silhouette volumes, capped, extruded to infinity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeShape {
    /// From silhouette edges or one volume per triangle.
    pub volumes: Volumes,
    /// Near and far caps. Z-fail needs them: without, the counts go wrong where a ray from the
    /// camera leaves the volume through its open ends (cracks).
    pub caps: bool,
    /// How far each vertex is extruded away from the light (0: to infinity). A finite distance
    /// makes volumes too short: shadows end where they do.
    pub extrusion: f32,
}

impl Default for VolumeShape {
    fn default() -> VolumeShape {
        VolumeShape {
            volumes: Volumes::Silhouette,
            caps: true,
            extrusion: 0.0,
        }
    }
}

impl VolumeShape {
    /// Whether a light's volume ends in one point (a directional light extruded to infinity):
    /// its sides are single triangles and it has no far cap.
    pub fn collapses(self, directional: bool) -> bool {
        directional && self.extrusion <= 0.0
    }
}

pub(crate) const FLAG_CASTS: u32 = 1;
const FLAG_CLOSED: u32 = 2;
pub(crate) const FLAG_PLACED: u32 = 4;
/// Invocations per workgroup of both entry points (`@workgroup_size` in the shader).
pub const WORKGROUP_SIZE: u32 = 64;
/// Draw arguments followed by the silhouette counter and the light's vertex total (`DrawArgs`
/// in the shader).
pub const ARGS_BYTES: u64 = 24;
/// Bytes of one volume vertex (`vec4<f32>`).
const VERTEX_BYTES: u64 = 16;
/// Byte offset of the silhouette counter and the vertex total in the arguments.
const COUNTERS_OFFSET: u64 = 16;

zoo_host::gpu_struct! {
    "shadow-volumes/params.wgsl" =>
    /// The per-light uniform of `shadow-volumes/volumes.wgsl`.
    #[derive(Debug, Clone, Copy)]
    pub struct Params {
        pub light: u32,
        pub mode: u32,
        /// Vertices the volume buffer holds.
        pub capacity: u32,
        /// 1: emit near and far caps ([`VolumeShape::caps`]).
        pub caps: u32,
        /// [`VolumeShape::extrusion`] (0: to infinity).
        pub extrusion: f32,
    }
}

zoo_host::gpu_struct! {
    "shadow-volumes/part.wgsl" =>
    /// The per-part uniform of `shadow-volumes/volumes.wgsl`: one dispatch's triangles and
    /// edges, and the placement of their stored vertices.
    #[derive(Debug, Clone, Copy)]
    pub struct Part {
        pub to_world: Mat4,
        pub first_triangle: u32,
        pub triangle_count: u32,
        pub first_edge: u32,
        pub edge_count: u32,
        /// 1 for an instance, 0 for the world-space part.
        pub instance: u32,
    }
}

/// Per-triangle flags: casts shadows, belongs to a closed (all edges manifold) object, and is
/// shared by instances.
pub fn triangle_flags(scene: &Scene) -> Vec<u32> {
    let mut flags = vec![0; scene.triangle_count()];
    for (i, object) in scene.objects.iter().enumerate() {
        let edges = &scene.adjacency.edges[scene.adjacency.object_edges[i].start as usize
            ..scene.adjacency.object_edges[i].end as usize];
        let closed = edges.iter().all(|e| e.kind() == EdgeKind::Manifold);
        let value = u32::from(object.casts_shadows) * FLAG_CASTS
            + u32::from(closed) * FLAG_CLOSED
            + u32::from(object.is_placed()) * FLAG_PLACED;
        flags[object.indices.start / 3..object.indices.end / 3].fill(value);
    }
    flags
}

/// Volume vertices one piece may hold: as many as one storage binding and one buffer of the
/// device take (`limits`), or as `budget` bytes take where given and smaller; at least a
/// triangle's, and few enough for the shader's 32-bit counts.
pub fn piece_vertices(limits: &wgpu::Limits, budget: Option<u64>) -> u64 {
    let bytes = (limits.max_storage_buffer_binding_size)
        .min(limits.max_buffer_size)
        .min(budget.unwrap_or(u64::MAX));
    (bytes / VERTEX_BYTES).clamp(24, u64::from(u32::MAX / 2))
}

/// The name of a pass of piece `piece` of light `light`'s volumes: `"{base}: light {light}"`,
/// then `" piece {piece}"` after the first.
pub fn piece_pass_name(base: &str, light: usize, piece: usize) -> String {
    let name = zoo_host::kit::light_pass_name(base, light);
    match piece {
        0 => name,
        _ => format!("{name} piece {piece}"),
    }
}

/// Workgroups (x, y) of [`WORKGROUP_SIZE`] invocations covering `items` (more than 65535
/// groups go 2D).
pub fn dispatch_size(items: u32) -> (u32, u32) {
    let groups = items.div_ceil(WORKGROUP_SIZE).max(1);
    let x = groups.min(65535);
    (x, groups.div_ceil(x))
}

struct Buffers {
    triangle_flags: wgpu::Buffer,
    weights: wgpu::Buffer,
    volume: wgpu::Buffer,
    args: wgpu::Buffer,
    /// The generation group of each stage: caps, sides, tally.
    groups: [StageBindGroup; 3],
    shape: VolumeShape,
    /// Vertices the volume buffer holds.
    capacity: u64,
    /// The work, one uniform slot each.
    units: Vec<Unit>,
    /// Per light, its pieces: indices into `units`.
    pieces: Vec<Vec<Vec<u32>>>,
    /// What the pieces cannot hold.
    unmet: Vec<String>,
}

/// The generation stages and, once prepared for a scene and its lights, the buffers.
pub struct VolumeGenerator {
    label: String,
    /// Caps (`triangles`), sides (`edges_main`) and the vertex tally (`tally`).
    stages: [Stage; 3],
    /// Per light, its parameters.
    params: UniformSlots<Params>,
    /// Per unit of work, its part.
    parts: UniformSlots<Part>,
    buffers: Option<Buffers>,
}

impl VolumeGenerator {
    /// Builds the compute stages (`label` names them and the buffers).
    pub fn new(ctx: &RenderContext<'_>, label: &str) -> Result<VolumeGenerator, TechniqueError> {
        let compute = wgpu::ShaderStages::COMPUTE;
        let params = UniformSlots::new(ctx.gpu, &format!("{label} light parameters"), 1, compute);
        let parts = UniformSlots::new(ctx.gpu, &format!("{label} parts"), 1, compute);
        let shared: [&dyn SharedGroup; 2] = [&params.at(0), &parts.at(0)];
        let stage = |entry| {
            Stage::compute("shadow-volumes/volumes.wgsl", entry)
                .shared(&shared)
                .build(ctx)
        };
        let stages = [stage("triangles")?, stage("edges_main")?, stage("tally")?];
        Ok(VolumeGenerator {
            label: label.to_string(),
            stages,
            params,
            parts,
            buffers: None,
        })
    }

    /// (Re)creates the buffers and the units of work for the context's scene and number of
    /// lights, with volumes of `shape`, in pieces of at most
    /// `budget` bytes where given (and never more than the device binds), and plans each
    /// light's pieces. Fails, saying why, where the scene's per-triangle data exceeds what the
    /// device binds.
    pub fn prepare(
        &mut self,
        ctx: &RenderContext<'_>,
        shape: VolumeShape,
        budget: Option<u64>,
    ) -> TechniqueResult {
        let volumes = shape.volumes;
        let device = &ctx.gpu.device;
        let label = &self.label;
        let scene = ctx.scene;
        let limits = device.limits();
        let per_triangle = 4 * scene.triangle_count() as u64;
        let binds = limits.max_storage_buffer_binding_size;
        if per_triangle > binds.min(limits.max_buffer_size) {
            return Err(TechniqueError::Unavailable {
                id: label.clone(),
                reason: format!(
                    "the scene stores {} triangles, whose weights ({per_triangle} bytes) exceed \
                     the {binds} bytes the device binds",
                    scene.triangle_count()
                ),
            });
        }
        let flags = triangle_flags(scene);
        let limit = piece_vertices(&limits, budget);
        let work = units(scene, &flags, volumes, limit);
        let needed: u64 = (work.units.iter())
            .map(|u| u.emitters.most_vertices(volumes))
            .sum();
        let capacity = needed.clamp(24, limit);
        if needed > limit {
            zoo_host::log::info!(
                "{label}: volumes may need {needed} vertices, a piece holds {capacity}: \
                 each light's are generated and drawn in pieces"
            );
        }
        let params: Vec<Params> = (0..ctx.lights.len().max(1))
            .map(|light| Params {
                light: light as u32,
                mode: u32::from(volumes == Volumes::PerTriangle),
                capacity: capacity as u32,
                caps: u32::from(shape.caps),
                extrusion: shape.extrusion.max(0.0),
            })
            .collect();
        let parts: Vec<Part> = work.units.iter().map(|u| u.part).collect();
        self.params.write(ctx.gpu, &params);
        self.parts.write(ctx.gpu, &parts);
        self.buffers = Some(self.buffers(ctx, &flags, (shape, capacity), work)?);
        self.plan(ctx);
        Ok(())
    }

    /// The buffers for `work` on the context's scene and lights, with volumes of `shape` built
    /// into a buffer of `capacity` vertices.
    fn buffers(
        &self,
        ctx: &RenderContext<'_>,
        flags: &[u32],
        (shape, capacity): (VolumeShape, u64),
        work: crate::pieces::Units,
    ) -> TechniqueResult<Buffers> {
        let device = &ctx.gpu.device;
        let label = &self.label;
        let init = |what: &str, contents: &[u8], usage| {
            wgpu::util::DeviceExt::create_buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("{label} {what}")),
                    contents,
                    usage,
                },
            )
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let triangle_flags = init("triangle flags", bytemuck::cast_slice(flags), storage);
        let weights = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{label} triangle weights")),
            size: (4 * flags.len() as u64).max(16),
            usage: storage,
            mapped_at_creation: false,
        });
        let volume = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{label} volume vertices")),
            size: VERTEX_BYTES * capacity,
            usage: storage | wgpu::BufferUsages::VERTEX,
            mapped_at_creation: false,
        });
        let args = init(
            "draw arguments",
            bytemuck::cast_slice(&[0u32, 1, 0, 0, 0, 0, 0, 0]),
            storage
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        );
        let b = ctx.scene_buffers;
        let resources = [
            ("vertices", b.vertices.as_entire_binding()),
            ("indices", b.indices.as_entire_binding()),
            ("edges", b.edges.as_entire_binding()),
            ("edge_faces", b.edge_faces.as_entire_binding()),
            ("triangle_flags", triangle_flags.as_entire_binding()),
            ("weights", weights.as_entire_binding()),
            ("volume", volume.as_entire_binding()),
            ("draw", args.as_entire_binding()),
        ];
        let [caps, sides, tally] = &self.stages;
        let group =
            |stage: &Stage, what| stage.bind(ctx, &format!("{label} {what} group"), &resources);
        let groups = [
            group(caps, "caps")?,
            group(sides, "sides")?,
            group(tally, "vertex tally")?,
        ];
        Ok(Buffers {
            triangle_flags,
            weights,
            volume,
            args,
            groups,
            shape,
            capacity,
            units: work.units,
            pieces: Vec::new(),
            unmet: work.unmet,
        })
    }

    /// Packs each of the context's lights' units into pieces: those of the instances the
    /// light reaches (all for a directional light), each piece at most the buffer's capacity
    /// for the light's kind. Called by [`Self::prepare`]; call it again after lights move.
    pub fn plan(&mut self, ctx: &RenderContext<'_>) {
        let Some(b) = &mut self.buffers else { return };
        let scene = ctx.scene;
        b.pieces = (ctx.lights.iter())
            .map(|light| {
                let directional = light.kind == zoo_host::LightKind::Directional;
                let collapses = b.shape.collapses(directional);
                let needed = |unit: &Unit| {
                    let reached = unit.object.is_none_or(|i| {
                        (scene.objects[i].bounds).is_none_or(|bounds| reaches_box(light, bounds))
                    });
                    reached.then(|| unit.emitters.vertices(b.shape.volumes, collapses))
                };
                pack(&b.units, b.capacity, needed)
            })
            .collect();
    }

    /// The number of pieces light `light`'s volumes are generated and drawn in (0 before
    /// [`Self::prepare`]).
    pub fn pieces(&self, light: usize) -> usize {
        (self.buffers.as_ref())
            .and_then(|b| b.pieces.get(light))
            .map_or(0, Vec::len)
    }

    /// Records compute pass `name` that builds piece `piece` of light `light`'s volume into
    /// [`Self::volume`] and its vertex count into [`Self::args`], adding its silhouette edges
    /// and vertices to the light's counters there (reset by piece 0). Draw each piece before
    /// recording the next.
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        (light, piece): (usize, usize),
        name: &str,
    ) -> TechniqueResult {
        let b = self
            .buffers
            .as_ref()
            .ok_or_else(TechniqueError::not_prepared)?;
        let units = (b.pieces.get(light))
            .and_then(|pieces| pieces.get(piece))
            .ok_or_else(TechniqueError::not_prepared)?;
        // Reset the vertex count (keeping instance_count = 1), and the light's counters first.
        let encoder = recorder.encoder();
        encoder.clear_buffer(&b.args, 0, Some(4));
        if piece == 0 {
            encoder.clear_buffer(&b.args, COUNTERS_OFFSET, Some(ARGS_BYTES - COUNTERS_OFFSET));
        }
        let mut pass = recorder.compute_pass(name);
        let light_params = self.params.at(light);
        // Each unit's triangles weigh in before its edges read the weights (wgpu orders the
        // dispatches' storage accesses).
        let [caps, sides, tally] = &self.stages;
        for &k in units {
            let part = &b.units[k as usize].part;
            let shared: [&dyn SharedGroup; 2] = [&light_params, &self.parts.at(k as usize)];
            for (items, stage, group) in [
                (part.triangle_count, caps, &b.groups[0]),
                (part.edge_count, sides, &b.groups[1]),
            ] {
                if items > 0 {
                    let (x, y) = dispatch_size(items);
                    let extent = [x * WORKGROUP_SIZE, y, 1];
                    stage.dispatch_in(ctx, &mut pass, (&[group], &shared), extent)?;
                }
            }
        }
        let shared: [&dyn SharedGroup; 2] = [&light_params, &self.parts.at(0)];
        tally.dispatch_in(ctx, &mut pass, (&[&b.groups[2]], &shared), [1, 1, 1])?;
        Ok(())
    }

    /// Counters: `light N volume pieces` for each light, once prepared.
    pub fn counters(&self) -> Vec<(String, f64)> {
        (self.buffers.iter())
            .flat_map(|b| b.pieces.iter().enumerate())
            .map(|(light, pieces)| (format!("light {light} volume pieces"), pieces.len() as f64))
            .collect()
    }

    /// The volume vertices (`vec4<f32>`, [`super::VOLUME_VERTEX_LAYOUT`]), once prepared.
    pub fn volume(&self) -> Option<&wgpu::Buffer> {
        self.buffers.as_ref().map(|b| &b.volume)
    }

    /// Indirect draw arguments of the last piece (offset 0), then the light's silhouette-edge
    /// count (offset 16) and volume vertex total (offset 20) so far, once prepared:
    /// [`ARGS_BYTES`] bytes.
    pub fn args(&self) -> Option<&wgpu::Buffer> {
        self.buffers.as_ref().map(|b| &b.args)
    }

    /// What the volumes cannot meet for the prepared scene, each a sentence naming the
    /// generator: geometry that no piece can hold and is dropped. Empty where every volume is
    /// exact.
    pub fn warnings(&self) -> Vec<String> {
        (self.buffers.iter())
            .flat_map(|b| &b.unmet)
            .map(|line| format!("{}: {line}", self.label))
            .collect()
    }

    /// The buffers, for the memory table.
    pub fn resources(&self) -> Vec<ResourceInfo> {
        let Some(b) = &self.buffers else {
            return Vec::new();
        };
        vec![
            ResourceInfo::buffer("volume vertices", &b.volume, "vec4<f32>"),
            ResourceInfo::buffer("triangle flags", &b.triangle_flags, "u32"),
            ResourceInfo::buffer("triangle weights", &b.weights, "i32"),
            ResourceInfo::buffer("draw arguments", &b.args, "DrawIndirectArgs + counters"),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::layout::wgsl_struct;
    use zoo_host::scene::EdgeRecord;

    #[test]
    fn draw_arguments_match_the_shader() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose("shadow-volumes/volumes.wgsl")
            .unwrap()
            .source;
        assert_eq!(
            wgsl_struct(&source, "DrawArgs").unwrap().size as u64,
            ARGS_BYTES
        );
    }

    #[test]
    fn shared_numbers_match_the_shader() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose("shadow-volumes/volumes.wgsl")
            .unwrap()
            .source;
        let constant = |name| zoo_host::gpu::layout::wgsl_integer_constant(&source, name);
        assert_eq!(constant("FLAG_CASTS"), Ok(i64::from(FLAG_CASTS)));
        assert_eq!(constant("FLAG_CLOSED"), Ok(i64::from(FLAG_CLOSED)));
        assert_eq!(constant("FLAG_PLACED"), Ok(i64::from(FLAG_PLACED)));
        assert_eq!(
            constant("EDGE_FACE_COUNT_MASK"),
            Ok(i64::from(EdgeRecord::FACE_COUNT_MASK))
        );
        assert_eq!(constant("WORKGROUP_SIZE"), Ok(i64::from(WORKGROUP_SIZE)));
        for entry in ["triangles", "edges_main"] {
            let size = zoo_host::gpu::layout::wgsl_workgroup_size(&source, entry);
            assert_eq!(size, Ok([WORKGROUP_SIZE, 1, 1]), "{entry}");
        }
        let info = EdgeRecord::pack_info(3, EdgeKind::NonManifold);
        let record = EdgeRecord {
            v0: 0,
            v1: 1,
            first_face: 0,
            info,
        };
        assert_eq!(
            (record.face_count(), record.kind()),
            (3, EdgeKind::NonManifold)
        );
    }

    #[test]
    fn dispatches_cover_every_item() {
        assert_eq!(dispatch_size(0), (1, 1));
        assert_eq!(dispatch_size(64), (1, 1));
        assert_eq!(dispatch_size(65), (2, 1));
        let (x, y) = dispatch_size(64 * 70_000);
        assert!(x <= 65535 && x as u64 * y as u64 * 64 >= 64 * 70_000);
    }
}
