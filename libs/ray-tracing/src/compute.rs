//! The portable traversal: the casters in the judge's own hierarchy
//! ([`zoo_host::judge::FlatBvh`]), uploaded as storage buffers and walked in WGSL
//! (`ray-tracing/trace.wgsl`), so it runs on every adapter with storage buffers.

use zoo_host::glam::{Vec2, Vec3, Vec4};
use zoo_host::gpu::{gpu_bytes, gpu_bytes_padded};
use zoo_host::judge::FlatBvh;
use zoo_host::kit::{bind_group, bind_group_layout, sampler, storage, texture, uniform};
use zoo_host::scene::Scene;
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};

use crate::{
    BuildStats, CasterInstance, CasterTriangle, Casters, GpuTranslucent, Hierarchy, NO_HIERARCHY,
    Tracer, storage_buffer,
};

/// Nodes a traversal can hold pending (`RT_STACK_SIZE` in `ray-tracing/trace.wgsl`): a
/// hierarchy at most this deep is traversed exactly.
pub const STACK_SIZE: u32 = 64;

zoo_host::gpu_struct! {
    "ray-tracing/node.wgsl" =>
    /// A node of `ray-tracing/trace.wgsl`'s hierarchies: a box, and its children (`first`,
    /// `first + 1`) or, for a leaf (`count` > 0), its triangles `first..first + count`.
    #[derive(Debug, Clone, Copy, PartialEq, Default)]
    pub struct GpuNode {
        pub min: Vec3,
        pub first: u32,
        pub max: Vec3,
        pub count: u32,
    }
}

zoo_host::gpu_struct! {
    "ray-tracing/triangle.wgsl" =>
    /// A triangle of `ray-tracing/trace.wgsl`: a corner and the two edges from it, its
    /// translucent object (for translucent casters drawn once; an instance names its own) and
    /// its alpha test (mask layer, -1 for none, and cutoff).
    #[derive(Debug, Clone, Copy, PartialEq, Default)]
    pub struct GpuTriangle {
        pub v0: Vec3,
        pub translucent: u32,
        pub e1: Vec3,
        pub mask_layer: i32,
        pub e2: Vec3,
        pub alpha_cutoff: f32,
    }
}

zoo_host::gpu_struct! {
    "ray-tracing/texcoords.wgsl" =>
    /// A triangle's corners' texture coordinates in `ray-tracing/trace.wgsl`.
    #[derive(Debug, Clone, Copy, PartialEq, Default)]
    pub struct GpuTexcoords {
        pub uv: [Vec2; 3],
    }
}

zoo_host::gpu_struct! {
    "ray-tracing/instance.wgsl" =>
    /// An instance in `ray-tracing/trace.wgsl`: its inverse placement (the rows of a 3x4
    /// matrix), the root node of its mesh's hierarchy and its translucent object
    /// ([`NO_OBJECT`] for a blocking caster).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct GpuInstance {
        pub to_local: [Vec4; 3],
        pub root: u32,
        pub translucent: u32,
    }
}

zoo_host::gpu_struct! {
    "ray-tracing/batch.wgsl" =>
    /// A run of caster triangles that a per-triangle pass visits
    /// ([`CasterGeometry::caster_batches`]): triangles `first..first + count` of
    /// `ray-tracing/trace.wgsl`'s triangles, in world space or placed by instance `instance`
    /// ([`NO_INSTANCE`] for none), numbered from `start` in the pass's flat numbering.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct GpuBatch {
        pub first: u32,
        pub count: u32,
        pub start: u32,
        pub instance: u32,
    }
}

/// [`GpuBatch::instance`] of triangles stored in world space.
pub const NO_INSTANCE: u32 = u32::MAX;

/// [`GpuInstance::translucent`] of a blocking caster (`RT_NO_OBJECT` in
/// `ray-tracing/trace.wgsl`).
pub const NO_OBJECT: u32 = u32::MAX;

zoo_host::gpu_struct! {
    "ray-tracing/roots.wgsl" =>
    /// The roots of `ray-tracing/trace.wgsl`: the first nodes of the hierarchies of
    /// translucent casters drawn once, of blocking instances and of translucent instances
    /// ([`crate::NO_HIERARCHY`] where there are none). Blocking casters drawn once start at
    /// node 0.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct GpuRoots {
        pub translucent: u32,
        pub blocking_instances: u32,
        pub translucent_instances: u32,
    }
}

/// The scene object of every stored triangle and every instance, for rays that need the
/// surface they hit (`rt_closest_surface`): a triangle of a shared mesh is its instance's
/// (its own entry names the mesh's first instance).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SurfaceObjects {
    /// Per triangle of [`CasterGeometry::triangles`] ([`NO_OBJECT`] for the placeholder of a
    /// scene without blocking casters).
    pub triangles: Vec<u32>,
    /// Per instance of [`CasterGeometry::instances`].
    pub instances: Vec<u32>,
}

/// The shadow casters as the GPU traces them, triangles in their hierarchies' leaf order.
/// Casters drawn once are in world space; each mesh instances share has a hierarchy of its
/// own in its stored space, and the instances (in leaf order) are under hierarchies over their
/// world boxes, one of blocking and one of translucent instances.
#[derive(Debug, Clone, PartialEq)]
pub struct CasterGeometry {
    /// The hierarchy of opaque and masked casters drawn once from node 0, then the others.
    pub nodes: Vec<GpuNode>,
    pub triangles: Vec<GpuTriangle>,
    pub texcoords: Vec<GpuTexcoords>,
    pub instances: Vec<GpuInstance>,
    pub roots: GpuRoots,
    /// The translucent objects' records ([`crate::translucent_records`]).
    pub translucent: Vec<GpuTranslucent>,
    /// Which scene object each triangle and each instance belong to
    /// ([`SurfaceObjects`]).
    pub objects: SurfaceObjects,
    /// The first node of every hierarchy.
    hierarchies: Vec<u32>,
    /// The triangles of every hierarchy over triangles: its first node, first triangle and
    /// triangle count.
    triangle_runs: Vec<(u32, u32, u32)>,
    /// Triangles traced, an instance's each time.
    traced: usize,
}

impl CasterGeometry {
    /// Every shadow caster of `scene` (degenerate triangles left out): opaque and masked ones
    /// drawn once in one hierarchy, translucent ones in a second, one per mesh instances
    /// share, and one over each kind of instance.
    pub fn of(scene: &Scene) -> CasterGeometry {
        let casters = Casters::of(scene);
        let (translucent, blocking): (Vec<&CasterTriangle>, Vec<&CasterTriangle>) =
            (casters.triangles.iter()).partition(|c| c.translucent.is_some());
        let mut geometry = CasterGeometry {
            nodes: Vec::new(),
            triangles: Vec::new(),
            texcoords: Vec::new(),
            instances: Vec::new(),
            roots: GpuRoots {
                translucent: NO_HIERARCHY,
                blocking_instances: NO_HIERARCHY,
                translucent_instances: NO_HIERARCHY,
            },
            translucent: Vec::new(),
            objects: SurfaceObjects::default(),
            hierarchies: Vec::new(),
            triangle_runs: Vec::new(),
            traced: casters.traced_count(),
        };
        geometry.append_hierarchy(&blocking);
        if geometry.nodes.is_empty() {
            // Node 0 is where `rt_occluded` starts: without blocking casters, a leaf over a
            // triangle without area, which no ray hits.
            geometry.nodes.push(GpuNode {
                count: 1,
                ..GpuNode::default()
            });
            geometry.triangles.push(GpuTriangle::default());
            geometry.texcoords.push(GpuTexcoords::default());
            geometry.objects.triangles.push(NO_OBJECT);
            geometry.hierarchies.push(0);
        }
        // (None where every translucent triangle is degenerate and left out.)
        if let Some(root) = geometry.append_hierarchy(&translucent) {
            geometry.roots.translucent = root;
        }
        let meshes: Vec<Option<u32>> = (casters.meshes.iter())
            .map(|mesh| geometry.append_hierarchy(&mesh.triangles.iter().collect::<Vec<_>>()))
            .collect();
        for translucent in [false, true] {
            let members: Vec<(&CasterInstance, u32)> = (casters.instances.iter())
                .filter(|i| casters.meshes[i.mesh].translucent == translucent)
                .filter_map(|i| Some((i, meshes[i.mesh]?)))
                .collect();
            if let Some(root) = geometry.append_instances(&members) {
                match translucent {
                    false => geometry.roots.blocking_instances = root,
                    true => geometry.roots.translucent_instances = root,
                }
            }
        }
        geometry.translucent = crate::translucent_records(&casters.transmittance);
        geometry
    }

    /// Appends a hierarchy over instances (each with its mesh's root node) and the instances
    /// in its leaf order; its root, or `None` without instances.
    fn append_instances(&mut self, members: &[(&CasterInstance, u32)]) -> Option<u32> {
        let boxes: Vec<(Vec3, Vec3)> = (members.iter())
            .map(|(instance, root)| {
                let node = &self.nodes[*root as usize];
                zoo_host::judge::placed_box(instance.to_world, node.min, node.max)
            })
            .collect();
        let bvh = FlatBvh::over_boxes(&boxes);
        if bvh.nodes.is_empty() {
            return None;
        }
        let (node_base, instance_base) = (self.nodes.len() as u32, self.instances.len() as u32);
        self.nodes.extend(bvh.nodes.iter().map(|n| GpuNode {
            min: n.min,
            first: n.first
                + if n.count > 0 {
                    instance_base
                } else {
                    node_base
                },
            max: n.max,
            count: n.count,
        }));
        for &source in &bvh.triangles {
            let (instance, root) = members[source as usize];
            let rows = instance.to_world.inverse().transpose();
            self.instances.push(GpuInstance {
                to_local: [rows.x_axis, rows.y_axis, rows.z_axis],
                root,
                translucent: instance.translucent.unwrap_or(NO_OBJECT),
            });
            self.objects.instances.push(instance.object);
        }
        self.hierarchies.push(node_base);
        Some(node_base)
    }

    /// Appends a hierarchy over `casters`, its node and triangle indices offset past what is
    /// there; its root, or `None` without any.
    fn append_hierarchy(&mut self, casters: &[&CasterTriangle]) -> Option<u32> {
        let corners: Vec<_> = casters.iter().map(|c| c.corners).collect();
        let bvh = FlatBvh::build(&corners);
        if bvh.nodes.is_empty() {
            return None;
        }
        let (node_base, triangle_base) = (self.nodes.len() as u32, self.triangles.len() as u32);
        self.nodes.extend(bvh.nodes.iter().map(|n| GpuNode {
            min: n.min,
            first: n.first
                + if n.count > 0 {
                    triangle_base
                } else {
                    node_base
                },
            max: n.max,
            count: n.count,
        }));
        for &source in &bvh.triangles {
            let caster = casters[source as usize];
            let [a, b, c] = caster.corners;
            let mask = caster.mask;
            self.triangles.push(GpuTriangle {
                v0: a,
                translucent: caster.translucent.unwrap_or(0),
                e1: b - a,
                mask_layer: mask.map_or(-1, |m| m.layer as i32),
                e2: c - a,
                alpha_cutoff: mask.map_or(0.0, |m| m.cutoff),
            });
            self.texcoords.push(GpuTexcoords { uv: caster.uv });
            self.objects.triangles.push(caster.object);
        }
        self.hierarchies.push(node_base);
        let count = self.triangles.len() as u32 - triangle_base;
        self.triangle_runs.push((node_base, triangle_base, count));
        Some(node_base)
    }

    /// Levels of the deepest hierarchy (0 without casters): a traversal holds at most this
    /// many nodes plus one pending.
    pub fn depth(&self) -> u32 {
        let mut pending: Vec<(u32, u32)> = self.hierarchies.iter().map(|&r| (r, 1)).collect();
        let mut deepest = 0;
        while let Some((index, level)) = pending.pop() {
            deepest = deepest.max(level);
            let node = &self.nodes[index as usize];
            if node.count == 0 {
                pending.extend([(node.first, level + 1), (node.first + 1, level + 1)]);
            }
        }
        deepest
    }

    /// Every caster triangle as runs a per-triangle pass visits, numbered in one flat
    /// sequence: the blocking (opaque and masked) ones drawn once, in world space, then the
    /// translucent ones drawn once, then each instance's shared triangles once per instance
    /// (not copied).
    pub fn caster_batches(&self) -> Vec<GpuBatch> {
        let run = |root: u32| {
            let found = self.triangle_runs.iter().find(|(node, _, _)| *node == root);
            found.map(|&(_, first, count)| (first, count))
        };
        let drawn_once = [(NO_INSTANCE, 0), (NO_INSTANCE, self.roots.translucent)];
        let placed = (self.instances.iter().enumerate()).map(|(index, i)| (index as u32, i.root));
        let mut start = 0;
        (drawn_once.into_iter().chain(placed))
            .filter_map(|(instance, root)| {
                let (first, count) = run(root)?;
                let batch = GpuBatch {
                    first,
                    count,
                    start,
                    instance,
                };
                start += count;
                Some(batch)
            })
            .collect()
    }

    /// Shadow-casting triangles stored (the placeholder of a scene without blocking casters
    /// left out; an instance's shared triangles once).
    pub fn caster_count(&self) -> usize {
        let placeholder = self.triangles.first() == Some(&GpuTriangle::default());
        self.triangles.len() - usize::from(placeholder)
    }

    /// Shadow-casting triangles traced, an instance's each time.
    pub fn traced_count(&self) -> usize {
        self.traced
    }
}

/// The layout of the compute traversal's group.
pub(crate) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    bind_group_layout(device, "ray tracing layout (compute)", &entries())
}

/// The group's entries, binding by binding as `ray-tracing/trace.wgsl` declares them (the
/// vertex stage too: frustum-traced's raster path places caster triangles from them).
pub(crate) fn entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let stages = crate::STAGES | wgpu::ShaderStages::VERTEX;
    vec![
        storage(0, stages, true),
        storage(1, stages, true),
        storage(2, stages, true),
        texture(
            3,
            stages,
            wgpu::TextureSampleType::Float { filterable: true },
            wgpu::TextureViewDimension::D2Array,
        ),
        sampler(4, stages, wgpu::SamplerBindingType::Filtering),
        storage(5, stages, true),
        storage(6, stages, true),
        uniform(7, stages),
    ]
}

/// What [`upload`] makes: the group and its statistics, the casters' batches and the
/// surfaces' objects.
pub(crate) type Uploaded = (
    (wgpu::BindGroup, BuildStats),
    (Vec<GpuBatch>, SurfaceObjects),
);

/// Builds and uploads the hierarchy of `ctx`'s scene: its bind group and its size (without
/// the time), and its blocking casters' batches and surfaces' objects; an error when it is deeper than the
/// traversal's stack holds.
pub(crate) fn upload(
    ctx: &RenderContext<'_>,
    layout: &wgpu::BindGroupLayout,
) -> TechniqueResult<Uploaded> {
    let geometry = CasterGeometry::of(ctx.scene);
    let depth = geometry.depth();
    if depth >= STACK_SIZE {
        return Err(TechniqueError::Other(format!(
            "the casters' hierarchy has {depth} levels; GPU traversal holds {STACK_SIZE}"
        )));
    }
    let device = &ctx.gpu.device;
    let nodes = storage_buffer(device, "ray tracing nodes", &gpu_bytes(&geometry.nodes));
    let triangles = storage_buffer(
        device,
        "ray tracing triangles",
        &gpu_bytes(&geometry.triangles),
    );
    let texcoords = storage_buffer(
        device,
        "ray tracing texture coordinates",
        &gpu_bytes(&geometry.texcoords),
    );
    let translucent = storage_buffer(
        device,
        "ray tracing translucent objects",
        &gpu_bytes(&geometry.translucent),
    );
    let instances = storage_buffer(
        device,
        "ray tracing instances",
        &crate::or_one_zeroed(&geometry.instances),
    );
    let roots = wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("ray tracing roots"),
            // A whole 16-byte slot, as a uniform block holds it everywhere.
            contents: &gpu_bytes_padded(&geometry.roots, 16),
            usage: wgpu::BufferUsages::UNIFORM,
        },
    );
    let materials = &ctx.scene_buffers.materials;
    let bind_group = bind_group(
        device,
        "ray tracing bind group (compute)",
        layout,
        &[
            nodes.as_entire_binding(),
            triangles.as_entire_binding(),
            texcoords.as_entire_binding(),
            wgpu::BindingResource::TextureView(&materials.textures),
            wgpu::BindingResource::Sampler(&materials.sampler),
            translucent.as_entire_binding(),
            instances.as_entire_binding(),
            roots.as_entire_binding(),
        ],
    );
    let stats = BuildStats {
        tracer: Tracer::Compute,
        triangles: geometry.traced_count(),
        hierarchy: Some(Hierarchy {
            nodes: geometry.nodes.len(),
            depth,
        }),
        milliseconds: 0.0,
    };
    let batches = geometry.caster_batches();
    Ok(((bind_group, stats), (batches, geometry.objects)))
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_caster_triangle_is_stored_once_inside_its_leaf() {
        let scene = zoo_host::test_support::scene_from_ron(
            "casters.ron",
            r#"(camera: (position: (0, 3, 6), target: (0, 0, 0)),
                lights: [Point(position: (0, 4, 0))],
                objects: [
                    (mesh: Plane(size: 10), casts_shadows: false),
                    (mesh: Sphere(radius: 1, segments: 12, rings: 8)),
                    (mesh: Box(size: (1, 2, 1)), transform: (translation: (2, 1, 0))),
                ])"#,
        );
        let geometry = CasterGeometry::of(&scene);
        let casters = scene.objects[1..]
            .iter()
            .map(|o| o.indices.len() / 3)
            .sum::<usize>();
        assert_eq!(geometry.triangles.len(), casters);
        assert!(geometry.triangles.iter().all(|t| t.mask_layer == -1));
        let depth = geometry.depth();
        assert!((2..STACK_SIZE).contains(&depth), "{depth} levels");
        let mut covered = vec![0; geometry.triangles.len()];
        for node in geometry.nodes.iter().filter(|n| n.count > 0) {
            let (lo, hi) = (node.min, node.max);
            for t in &geometry.triangles[node.first as usize..(node.first + node.count) as usize] {
                let v0 = t.v0;
                for p in [v0, v0 + t.e1, v0 + t.e2] {
                    assert!(p.cmpge(lo - 1e-4).all() && p.cmple(hi + 1e-4).all());
                }
            }
            for c in &mut covered[node.first as usize..(node.first + node.count) as usize] {
                *c += 1;
            }
        }
        assert!(covered.iter().all(|&c| c == 1), "{covered:?}");
    }

    #[test]
    fn translucent_casters_get_a_hierarchy_of_their_own_and_their_colours() {
        let scene = zoo_host::test_support::scene_from_ron(
            "glass.ron",
            r#"(camera: (position: (0, 3, 6), target: (0, 0, 0)),
                lights: [Point(position: (0, 4, 0))],
                objects: [
                    (mesh: Plane(size: 10), casts_shadows: false),
                    (mesh: Box(size: (1, 1, 1)), opacity: 0.5, transmission: (1, 0.2, 0.1)),
                    (mesh: Box(size: (1, 2, 1)), transform: (translation: (2, 1, 0))),
                    (mesh: Box(size: (1, 1, 1)), transform: (translation: (-2, 1, 0)),
                     opacity: 0.25, transmission: (0.2, 0.4, 1.0)),
                ])"#,
        );
        let geometry = CasterGeometry::of(&scene);
        let root = geometry.roots.translucent;
        assert_ne!(root, NO_HIERARCHY, "two translucent boxes");
        assert_eq!(geometry.caster_count(), 36);
        assert_eq!(geometry.translucent.len(), 2);
        assert_eq!(
            geometry.translucent[0].transmittance,
            Vec3::new(0.5, 0.1, 0.05)
        );
        assert_eq!(
            geometry.translucent[1].transmittance,
            Vec3::new(0.15, 0.3, 0.75)
        );
        // The opaque box alone under node 0; each glass box's triangles name its object.
        let leaves_under = |root: u32| {
            let mut triangles = Vec::new();
            let mut pending = vec![root];
            while let Some(i) = pending.pop() {
                let n = geometry.nodes[i as usize];
                if n.count > 0 {
                    triangles.extend(n.first..n.first + n.count);
                } else {
                    pending.extend([n.first, n.first + 1]);
                }
            }
            triangles
        };
        assert_eq!(leaves_under(0).len(), 12);
        let glass = leaves_under(root);
        assert_eq!(glass.len(), 24);
        let objects: Vec<u32> = glass
            .iter()
            .map(|&t| geometry.triangles[t as usize].translucent)
            .collect();
        assert_eq!(objects.iter().filter(|&&o| o == 0).count(), 12);
        assert_eq!(objects.iter().filter(|&&o| o == 1).count(), 12);
        assert!((2..STACK_SIZE).contains(&geometry.depth()));

        // Without blocking casters node 0 is a leaf no ray hits, and the glass starts after.
        let only_glass = zoo_host::test_support::scene_from_ron(
            "only-glass.ron",
            r#"(camera: (position: (0, 3, 6), target: (0, 0, 0)),
                lights: [Point(position: (0, 4, 0))],
                objects: [(mesh: Box(size: (1, 1, 1)), opacity: 0.5)])"#,
        );
        let geometry = CasterGeometry::of(&only_glass);
        assert_eq!(geometry.nodes[0].count, 1);
        assert_eq!(geometry.triangles[0], GpuTriangle::default());
        assert_eq!(geometry.roots.translucent, 1);
        assert_eq!(geometry.caster_count(), 12);
    }

    #[test]
    fn instances_share_their_mesh_hierarchy_under_one_over_their_boxes() {
        let scene = zoo_host::test_support::scene_from_ron(
            "instances.ron",
            r#"(camera: (position: (0, 3, 6), target: (0, 0, 0)),
                lights: [Point(position: (0, 4, 0))],
                objects: [
                    (mesh: Plane(size: 10)),
                    (mesh: Box(size: (1, 1, 1)), instances: [
                        (translation: (2, 0.5, 0)),
                        (translation: (-2, 1, 0), rotation_degrees: (0, 30, 0), scale: (1, 2, 1)),
                        (translation: (0, 0.5, 3), scale: (0.5, 0.5, 0.5)),
                    ]),
                    (mesh: Sphere(radius: 0.5, segments: 8, rings: 4), opacity: 0.5,
                     instances: [(translation: (0, 2, 0)), (translation: (1, 2, 1))]),
                ])"#,
        );
        let geometry = CasterGeometry::of(&scene);
        let sphere = scene.objects[4].indices.len() / 3;
        // The plane, one box and one sphere stored; three boxes and two spheres traced.
        assert_eq!(geometry.caster_count(), 2 + 12 + sphere);
        assert_eq!(geometry.traced_count(), 2 + 3 * 12 + 2 * sphere);
        assert_eq!(geometry.instances.len(), 5);
        let roots = geometry.roots;
        assert_eq!(
            roots.translucent, NO_HIERARCHY,
            "no translucent caster drawn once"
        );
        assert!(
            roots.blocking_instances != NO_HIERARCHY && roots.translucent_instances != NO_HIERARCHY
        );
        // Each hierarchy over instances reaches each of its instances once.
        let leaves = |root: u32| {
            let mut found = Vec::new();
            let mut pending = vec![root];
            while let Some(i) = pending.pop() {
                let n = geometry.nodes[i as usize];
                match n.count {
                    0 => pending.extend([n.first, n.first + 1]),
                    _ => found.extend(n.first..n.first + n.count),
                }
            }
            found.sort();
            found
        };
        let (blocking, glass) = (
            leaves(roots.blocking_instances),
            leaves(roots.translucent_instances),
        );
        assert_eq!(blocking.len() + glass.len(), 5);
        assert!(blocking.iter().chain(&glass).all(|&i| (i as usize) < 5));
        // The blocking instances share a root, and undo their placements.
        let placements: Vec<_> = scene.objects[1..4].iter().map(|o| o.placement).collect();
        for &i in &blocking {
            let instance = geometry.instances[i as usize];
            assert_eq!(instance.root, geometry.instances[blocking[0] as usize].root);
            assert_eq!(instance.translucent, NO_OBJECT);
            let [x, y, z] = instance.to_local;
            let rows = zoo_host::glam::Mat4::from_cols(x, y, z, Vec4::W).transpose();
            assert!(
                placements
                    .iter()
                    .any(|p| (rows * *p).abs_diff_eq(zoo_host::glam::Mat4::IDENTITY, 1e-5))
            );
        }
        // Each glass instance filters as an object of its own.
        let mut objects: Vec<u32> = glass
            .iter()
            .map(|&i| geometry.instances[i as usize].translucent)
            .collect();
        objects.sort();
        assert_eq!(objects, [0, 1]);
        assert_eq!(geometry.translucent.len(), 2);
        assert!((2..STACK_SIZE).contains(&geometry.depth()));
    }

    #[test]
    fn batches_number_every_traced_triangle_once_and_each_instance_its_own() {
        let scene = zoo_host::test_support::scene_from_ron(
            "batches.ron",
            r#"(camera: (position: (0, 3, 6), target: (0, 0, 0)),
                lights: [Point(position: (0, 4, 0))],
                objects: [
                    (mesh: Plane(size: 10)),
                    (mesh: Box(size: (1, 1, 1)), opacity: 0.5),
                    (mesh: Box(size: (1, 1, 1)), instances: [
                        (translation: (2, 0.5, 0)),
                        (translation: (-2, 1, 0), scale: (1, 2, 1)),
                    ]),
                ])"#,
        );
        let geometry = CasterGeometry::of(&scene);
        let batches = geometry.caster_batches();
        // The plane and the glass box drawn once, then each box instance.
        let runs: Vec<(u32, u32)> = batches.iter().map(|b| (b.count, b.instance)).collect();
        assert_eq!(
            runs,
            [(2, NO_INSTANCE), (12, NO_INSTANCE), (12, 0), (12, 1)]
        );
        let mut start = 0;
        for batch in &batches {
            assert_eq!(batch.start, start, "{batches:?}");
            assert!((batch.first + batch.count) as usize <= geometry.triangles.len());
            start += batch.count;
        }
        assert_eq!(start as usize, geometry.traced_count());
        // The instances share their mesh's triangles.
        assert_eq!(batches[2].first, batches[3].first);

        // A scene of instances only: no stand-in triangle drawn once.
        let only_instances = zoo_host::test_support::scene_from_ron(
            "instances-only.ron",
            r#"(camera: (position: (0, 3, 6), target: (0, 0, 0)),
                lights: [Point(position: (0, 4, 0))],
                objects: [(mesh: Box(size: (1, 1, 1)), instances: [(translation: (2, 0.5, 0))])])"#,
        );
        let batches = CasterGeometry::of(&only_instances).caster_batches();
        assert_eq!(batches.len(), 1);
        assert_eq!((batches[0].count, batches[0].instance), (12, 0));
    }

    #[test]
    fn the_shader_holds_as_many_pending_nodes_as_declared() {
        let composed = zoo_host::ShaderLibrary::embedded()
            .compose("ray-tracing/trace.wgsl")
            .unwrap();
        let constant = |name| zoo_host::gpu::layout::wgsl_integer_constant(&composed.source, name);
        assert_eq!(constant("RT_STACK_SIZE"), Ok(i64::from(STACK_SIZE)));
        assert_eq!(constant("RT_NO_OBJECT"), Ok(i64::from(NO_OBJECT)));
    }
}
