//! Volumes built on the GPU from the scene's edge adjacency, one light at a time.
//!
//! A compute pass weights every shadow-casting triangle (+1 facing the light, -1 facing away on
//! an open or non-manifold mesh, 0 otherwise) and emits its near cap (and, for point and spot
//! lights, the far cap at infinity); a second pass emits |m| side quads per edge, m being the
//! sum of its faces' weights times their traversal signs, so sides shared by two emitting
//! triangles cancel and boundary or non-manifold edges close the volume. The vertices (w = 0 at
//! infinity) land in one buffer drawn with indirect arguments.
//!
//! Both passes run once per part: the triangles stored in world space, then each shadow-casting
//! instance's shared triangles and edges under its placement, so instances share their
//! geometry here as in every other pass.

use zoo_host::glam::Mat4;
use zoo_host::gpu::gpu_struct::round_up;
use zoo_host::gpu::{GpuType, PassRecorder, gpu_bytes_padded};
use zoo_host::scene::{EdgeKind, Scene};
use zoo_host::technique::ResourceInfo;
use zoo_host::{RenderContext, TechniqueError, wgpu};

zoo_host::param_choice! {
    /// How volumes are built.
    pub enum Volumes { Silhouette, PerTriangle }
}

const FLAG_CASTS: u32 = 1;
const FLAG_CLOSED: u32 = 2;
const FLAG_PLACED: u32 = 4;
/// Invocations per workgroup of both entry points (`@workgroup_size` in the shader).
pub const WORKGROUP_SIZE: u32 = 64;
/// Bytes between the per-light parameter slots and between the per-part slots (uniform
/// dynamic-offset slots).
const SLOT: u64 = 256;
/// Draw arguments followed by the silhouette counter (`DrawArgs` in the shader).
pub const ARGS_BYTES: u64 = 20;

zoo_host::gpu_struct! {
    "shadow-volumes/params.wgsl" =>
    /// The per-light uniform of `shadow-volumes/volumes.wgsl`, in a [`SLOT`]-byte slot.
    #[derive(Debug, Clone, Copy)]
    pub struct Params {
        pub light: u32,
        pub mode: u32,
        pub capacity: u32,
    }
}

zoo_host::gpu_struct! {
    "shadow-volumes/part.wgsl" =>
    /// The per-part uniform of `shadow-volumes/volumes.wgsl`, in a [`SLOT`]-byte slot: one
    /// dispatch's triangles and edges, and the placement of their stored vertices.
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

// Each value fits its slot.
const _: () = assert!(Params::SIZE <= SLOT as usize);
const _: () = assert!(Part::SIZE <= SLOT as usize);

/// The bytes of `values`, each in a [`SLOT`]-byte slot.
fn in_slots<T: GpuType>(values: &[T]) -> Vec<u8> {
    (values.iter())
        .flat_map(|v| gpu_bytes_padded(v, SLOT as usize))
        .collect()
}

/// The parts volumes are built from: every stored triangle and edge in world space (instances'
/// triangles left out by their flag), then each shadow-casting instance's.
pub fn parts(scene: &Scene) -> Vec<Part> {
    let part = |to_world: Mat4,
                triangles: std::ops::Range<usize>,
                edges: &std::ops::Range<u32>,
                instance| Part {
        to_world,
        first_triangle: triangles.start as u32,
        triangle_count: triangles.len() as u32,
        first_edge: edges.start,
        edge_count: edges.len() as u32,
        instance,
    };
    let everything = 0..scene.adjacency.edges.len() as u32;
    let instances = (scene.objects.iter().enumerate())
        .filter(|(_, o)| o.is_placed() && o.casts_shadows)
        .map(|(i, o)| {
            let triangles = o.indices.start / 3..o.indices.end / 3;
            part(o.placement, triangles, &scene.adjacency.object_edges[i], 1)
        });
    std::iter::once(part(
        zoo_host::glam::Mat4::IDENTITY,
        0..scene.triangle_count(),
        &everything,
        0,
    ))
    .chain(instances)
    .collect()
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

/// Vertex capacity of the volume buffer for `scene` (caps, plus sides for the chosen mode),
/// instances counted.
pub fn volume_capacity(scene: &Scene, volumes: Volumes) -> u64 {
    let adjacency = &scene.adjacency;
    let (mut triangles, mut incidences) = (0u64, 0u64);
    for (i, object) in scene.objects.iter().enumerate() {
        triangles += object.indices.len() as u64 / 3;
        let edges = &adjacency.object_edges[i];
        incidences += (adjacency.edges[edges.start as usize..edges.end as usize].iter())
            .map(|e| u64::from(e.face_count()))
            .sum::<u64>();
    }
    let sides = match volumes {
        Volumes::Silhouette => 6 * incidences,
        Volumes::PerTriangle => 18 * triangles,
    };
    (6 * triangles + sides).max(3)
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
    bind_group: wgpu::BindGroup,
    /// Each part's triangle and edge counts, in slot order.
    parts: Vec<(u32, u32)>,
}

/// The generation pipelines and, once prepared for a scene and its lights, the buffers.
pub struct VolumeGenerator {
    label: String,
    triangles: wgpu::ComputePipeline,
    edges: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    buffers: Option<Buffers>,
}

impl VolumeGenerator {
    /// Builds the compute pipelines (`label` names them and the buffers).
    pub fn new(ctx: &RenderContext<'_>, label: &str) -> Result<VolumeGenerator, TechniqueError> {
        let device = &ctx.gpu.device;
        let module = ctx
            .shaders
            .create_module(device, "shadow-volumes/volumes.wgsl")?;
        let stage = wgpu::ShaderStages::COMPUTE;
        let storage = |binding, read_only| zoo_host::kit::storage(binding, stage, read_only);
        let slot = |binding, size| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: stage,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(size),
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(&format!("{label} generation layout")),
            entries: &[
                storage(0, true),
                storage(1, true),
                storage(2, true),
                storage(3, true),
                storage(4, true),
                storage(5, false),
                storage(6, false),
                storage(7, false),
                slot(8, round_up(Params::SIZE, 16) as u64),
                slot(9, round_up(Part::SIZE, 16) as u64),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label} generation pipeline layout")),
            bind_group_layouts: &[Some(&ctx.frame.layout), Some(&layout)],
            immediate_size: 0,
        });
        let compute = |what: &str, entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(&format!("{label} {what} pipeline")),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Ok(VolumeGenerator {
            label: label.to_string(),
            triangles: compute("caps", "triangles"),
            edges: compute("sides", "edges_main"),
            layout,
            buffers: None,
        })
    }

    /// (Re)creates the buffers for the context's scene and lights, with `volumes` built from
    /// silhouette edges or per triangle.
    pub fn prepare(&mut self, ctx: &RenderContext<'_>, volumes: Volumes) {
        let device = &ctx.gpu.device;
        let label = &self.label;
        let scene = ctx.scene;
        let flags = triangle_flags(scene);
        let needed = volume_capacity(scene, volumes);
        let limit = device.limits().max_storage_buffer_binding_size / 16;
        if needed > limit {
            zoo_host::log::warn!(
                "{label}: volumes may need {needed} vertices, the device binds at most {limit}; \
                 extra volume geometry is dropped"
            );
        }
        let capacity = needed.min(limit) as u32;
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
        let empty = |what: &str, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(&format!("{label} {what}")),
                size: size.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let triangle_flags = init("triangle flags", bytemuck::cast_slice(&flags), storage);
        let weights = empty("triangle weights", 4 * flags.len() as u64, storage);
        let volume = empty(
            "volume vertices",
            16 * capacity as u64,
            storage | wgpu::BufferUsages::VERTEX,
        );
        let args = init(
            "draw arguments",
            bytemuck::cast_slice(&[0u32, 1, 0, 0, 0, 0, 0, 0]),
            storage
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        );
        let params: Vec<Params> = (0..ctx.lights.len().max(1))
            .map(|light| Params {
                light: light as u32,
                mode: u32::from(volumes == Volumes::PerTriangle),
                capacity,
            })
            .collect();
        let params = init(
            "light parameters",
            &in_slots(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        let parts = parts(scene);
        let part_slots = init("parts", &in_slots(&parts), wgpu::BufferUsages::UNIFORM);
        let b = ctx.scene_buffers;
        fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }
        }
        // One whole slot, at dynamic offsets.
        fn slot_entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(SLOT),
                }),
            }
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&format!("{label} generation bind group")),
            layout: &self.layout,
            entries: &[
                entry(0, &b.vertices),
                entry(1, &b.indices),
                entry(2, &b.edges),
                entry(3, &b.edge_faces),
                entry(4, &triangle_flags),
                entry(5, &weights),
                entry(6, &volume),
                entry(7, &args),
                slot_entry(8, &params),
                slot_entry(9, &part_slots),
            ],
        });
        self.buffers = Some(Buffers {
            triangle_flags,
            weights,
            volume,
            args,
            bind_group,
            parts: (parts.iter())
                .map(|p| (p.triangle_count, p.edge_count))
                .collect(),
        });
    }

    /// Records compute pass `name` that builds light `light`'s volume into [`Self::volume`]
    /// and its vertex count (and silhouette-edge counter) into [`Self::args`].
    pub fn record(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        light: usize,
        name: &str,
    ) -> Result<(), TechniqueError> {
        let b = self
            .buffers
            .as_ref()
            .ok_or_else(TechniqueError::not_prepared)?;
        // Reset the vertex count (keeping instance_count = 1) and the silhouette counter.
        let encoder = recorder.encoder();
        encoder.clear_buffer(&b.args, 0, Some(4));
        encoder.clear_buffer(&b.args, 16, Some(4));
        let mut pass = recorder.compute_pass(name);
        pass.set_bind_group(0, &ctx.frame.bind_group, &[]);
        // Each part's triangles weigh in before its edges read the weights (wgpu orders the
        // dispatches' storage accesses).
        for (k, &(triangles, edges)) in b.parts.iter().enumerate() {
            let offsets = [light as u64 * SLOT, k as u64 * SLOT].map(|o| o as u32);
            pass.set_bind_group(1, &b.bind_group, &offsets);
            let (x, y) = dispatch_size(triangles);
            pass.set_pipeline(&self.triangles);
            pass.dispatch_workgroups(x, y, 1);
            let (x, y) = dispatch_size(edges);
            pass.set_pipeline(&self.edges);
            pass.dispatch_workgroups(x, y, 1);
        }
        Ok(())
    }

    /// The volume vertices (`vec4<f32>`, [`super::VOLUME_VERTEX_LAYOUT`]), once prepared.
    pub fn volume(&self) -> Option<&wgpu::Buffer> {
        self.buffers.as_ref().map(|b| &b.volume)
    }

    /// Indirect draw arguments (offset 0) and the silhouette-edge counter (offset 16), once
    /// prepared: [`ARGS_BYTES`] bytes.
    pub fn args(&self) -> Option<&wgpu::Buffer> {
        self.buffers.as_ref().map(|b| &b.args)
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
            ResourceInfo::buffer("draw arguments", &b.args, "DrawIndirectArgs + counter"),
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
