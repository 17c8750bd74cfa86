//! The portable traversal: the casters in the judge's own hierarchy
//! ([`zoo_host::judge::FlatBvh`]), uploaded as storage buffers and walked in WGSL
//! (`ray-tracing/trace.wgsl`), so it runs on every adapter with storage buffers.

use bytemuck::{Pod, Zeroable};
use zoo_host::judge::FlatBvh;
use zoo_host::kit::{bind_group, bind_group_layout, sampler, storage, texture};
use zoo_host::scene::Scene;
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};

use crate::{
    BuildStats, CasterTriangle, Casters, GpuTranslucent, Hierarchy, Tracer, storage_buffer,
};

/// Nodes a traversal can hold pending (`RT_STACK_SIZE` in `ray-tracing/trace.wgsl`): a
/// hierarchy at most this deep is traversed exactly.
pub const STACK_SIZE: u32 = 64;

/// `RtNode` in `ray-tracing/trace.wgsl`: a box, and its children (`first`, `first + 1`) or,
/// for a leaf (`count` > 0), its triangles `first..first + count`.
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuNode {
    pub min: [f32; 3],
    pub first: u32,
    pub max: [f32; 3],
    pub count: u32,
}

/// `RtTriangle` in `ray-tracing/trace.wgsl`: a corner and the two edges from it, its
/// translucent object (in the translucent hierarchy) and its alpha test (mask layer, -1 for
/// none, and cutoff).
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuTriangle {
    pub v0: [f32; 3],
    pub translucent: u32,
    pub e1: [f32; 3],
    pub mask_layer: i32,
    pub e2: [f32; 3],
    pub alpha_cutoff: f32,
}

/// `RtTexcoords` in `ray-tracing/trace.wgsl`: a triangle's corners' texture coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuTexcoords {
    pub uv: [[f32; 2]; 3],
    pub _pad: [f32; 2],
}

/// The shadow casters as the GPU traces them, triangles in the hierarchy's leaf order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CasterGeometry {
    /// The hierarchy of opaque and masked casters from node 0, then that of translucent ones
    /// from [`Self::translucent_root`].
    pub nodes: Vec<GpuNode>,
    pub triangles: Vec<GpuTriangle>,
    pub texcoords: Vec<GpuTexcoords>,
    /// The first node of the translucent casters' hierarchy, if there are any.
    pub translucent_root: Option<u32>,
    /// The translucent objects' records ([`crate::translucent_records`]).
    pub translucent: Vec<GpuTranslucent>,
}

impl CasterGeometry {
    /// Every shadow caster of `scene` (degenerate triangles left out): opaque and masked ones
    /// in one hierarchy, translucent ones in a second.
    pub fn of(scene: &Scene) -> CasterGeometry {
        let casters = Casters::of(scene);
        let (translucent, blocking): (Vec<&CasterTriangle>, Vec<&CasterTriangle>) =
            (casters.triangles.iter()).partition(|c| c.translucent.is_some());
        let mut geometry = CasterGeometry::default();
        geometry.append_hierarchy(&blocking);
        if geometry.nodes.is_empty() {
            // Node 0 is where `rt_occluded` starts: without blocking casters, a leaf over a
            // triangle without area, which no ray hits.
            geometry.nodes.push(GpuNode {
                min: [0.0; 3],
                first: 0,
                max: [0.0; 3],
                count: 1,
            });
            geometry.triangles.push(GpuTriangle::zeroed());
            geometry.texcoords.push(GpuTexcoords::zeroed());
        }
        let first_translucent = geometry.nodes.len() as u32;
        geometry.append_hierarchy(&translucent);
        // (None where every translucent triangle is degenerate and left out.)
        geometry.translucent_root =
            (geometry.nodes.len() as u32 > first_translucent).then_some(first_translucent);
        let root = geometry.translucent_root.unwrap_or(crate::NO_HIERARCHY);
        geometry.translucent = crate::translucent_records(&casters.transmittance, root);
        geometry
    }

    /// Appends a hierarchy over `casters` (nothing without any), its node and triangle
    /// indices offset past what is there.
    fn append_hierarchy(&mut self, casters: &[&CasterTriangle]) {
        let corners: Vec<_> = casters.iter().map(|c| c.corners).collect();
        let bvh = FlatBvh::build(&corners);
        if bvh.nodes.is_empty() {
            return;
        }
        let (node_base, triangle_base) = (self.nodes.len() as u32, self.triangles.len() as u32);
        self.nodes.extend(bvh.nodes.iter().map(|n| GpuNode {
            min: n.min.to_array(),
            first: n.first
                + if n.count > 0 {
                    triangle_base
                } else {
                    node_base
                },
            max: n.max.to_array(),
            count: n.count,
        }));
        for &source in &bvh.triangles {
            let caster = casters[source as usize];
            let [a, b, c] = caster.corners;
            let mask = caster.mask;
            self.triangles.push(GpuTriangle {
                v0: a.to_array(),
                translucent: caster.translucent.unwrap_or(0),
                e1: (b - a).to_array(),
                mask_layer: mask.map_or(-1, |m| m.layer as i32),
                e2: (c - a).to_array(),
                alpha_cutoff: mask.map_or(0.0, |m| m.cutoff),
            });
            self.texcoords.push(GpuTexcoords {
                uv: caster.uv.map(|t| t.to_array()),
                _pad: [0.0; 2],
            });
        }
    }

    /// Levels of the deeper hierarchy (0 without casters): a traversal holds at most this
    /// many nodes plus one pending.
    pub fn depth(&self) -> u32 {
        let roots = [Some(0), self.translucent_root].into_iter().flatten();
        let mut pending: Vec<(u32, u32)> = roots
            .filter(|&r| (r as usize) < self.nodes.len())
            .map(|r| (r, 1))
            .collect();
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

    /// Shadow-casting triangles stored (the placeholder of a scene without blocking casters
    /// left out).
    pub fn caster_count(&self) -> usize {
        let placeholder = self.triangles.first() == Some(&GpuTriangle::zeroed());
        self.triangles.len() - usize::from(placeholder)
    }
}

/// The layout of the compute traversal's group.
pub(crate) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    bind_group_layout(device, "ray tracing layout (compute)", &entries())
}

/// The group's entries, binding by binding as `ray-tracing/trace.wgsl` declares them.
pub(crate) fn entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let stages = crate::STAGES;
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
    ]
}

/// Builds and uploads the hierarchy of `ctx`'s scene: its bind group and its size (without
/// the time); an error when it is deeper than the traversal's stack holds.
pub(crate) fn upload(
    ctx: &RenderContext<'_>,
    layout: &wgpu::BindGroupLayout,
) -> TechniqueResult<(wgpu::BindGroup, BuildStats)> {
    let geometry = CasterGeometry::of(ctx.scene);
    let depth = geometry.depth();
    if depth >= STACK_SIZE {
        return Err(TechniqueError::Other(format!(
            "the casters' hierarchy has {depth} levels; GPU traversal holds {STACK_SIZE}"
        )));
    }
    let device = &ctx.gpu.device;
    let nodes = storage_buffer(
        device,
        "ray tracing nodes",
        bytemuck::cast_slice(&geometry.nodes),
    );
    let triangles = storage_buffer(
        device,
        "ray tracing triangles",
        bytemuck::cast_slice(&geometry.triangles),
    );
    let texcoords = storage_buffer(
        device,
        "ray tracing texture coordinates",
        bytemuck::cast_slice(&geometry.texcoords),
    );
    let translucent = storage_buffer(
        device,
        "ray tracing translucent objects",
        bytemuck::cast_slice(&geometry.translucent),
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
        ],
    );
    let stats = BuildStats {
        tracer: Tracer::Compute,
        triangles: geometry.caster_count(),
        hierarchy: Some(Hierarchy {
            nodes: geometry.nodes.len(),
            depth,
        }),
        milliseconds: 0.0,
    };
    Ok((bind_group, stats))
}
#[cfg(test)]
mod tests {
    use super::*;
    use zoo_host::gpu::layout::{SizeRule, check_embedded_mirror};

    #[test]
    fn records_mirror_the_shader() {
        let node = zoo_host::mirror_fields!(GpuNode {
            min,
            first,
            max,
            count
        });
        check_embedded_mirror("ray-tracing/trace.wgsl", "RtNode", node, SizeRule::Equal).unwrap();
        let triangle = zoo_host::mirror_fields!(GpuTriangle {
            v0,
            translucent,
            e1,
            mask_layer,
            e2,
            alpha_cutoff
        });
        check_embedded_mirror(
            "ray-tracing/trace.wgsl",
            "RtTriangle",
            triangle,
            SizeRule::Equal,
        )
        .unwrap();
        let texcoords = zoo_host::mirror_fields!(GpuTexcoords { uv, _pad });
        check_embedded_mirror(
            "ray-tracing/trace.wgsl",
            "RtTexcoords",
            texcoords,
            SizeRule::Equal,
        )
        .unwrap();
    }

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
            let (lo, hi) = (glam_vec(node.min), glam_vec(node.max));
            for t in &geometry.triangles[node.first as usize..(node.first + node.count) as usize] {
                let v0 = glam_vec(t.v0);
                for p in [v0, v0 + glam_vec(t.e1), v0 + glam_vec(t.e2)] {
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
        let root = geometry.translucent_root.expect("two translucent boxes");
        assert_eq!(geometry.caster_count(), 36);
        assert_eq!(geometry.translucent.len(), 2);
        assert!(geometry.translucent.iter().all(|t| t.hierarchy == root));
        assert_eq!(geometry.translucent[0].transmittance, [0.5, 0.1, 0.05]);
        assert_eq!(geometry.translucent[1].transmittance, [0.15, 0.3, 0.75]);
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
        assert_eq!(geometry.triangles[0], GpuTriangle::zeroed());
        assert_eq!(geometry.translucent_root, Some(1));
        assert_eq!(geometry.caster_count(), 12);
    }

    #[test]
    fn the_shader_holds_as_many_pending_nodes_as_declared() {
        let composed = zoo_host::ShaderLibrary::embedded()
            .compose("ray-tracing/trace.wgsl")
            .unwrap();
        let size = zoo_host::gpu::layout::wgsl_integer_constant(&composed.source, "RT_STACK_SIZE");
        assert_eq!(size, Ok(i64::from(STACK_SIZE)));
    }

    fn glam_vec(v: [f32; 3]) -> zoo_host::glam::Vec3 {
        zoo_host::glam::Vec3::from(v)
    }
}
