//! The portable traversal: the casters in the judge's own hierarchy
//! ([`zoo_host::judge::FlatBvh`]), uploaded as storage buffers and walked in WGSL
//! (`ray-tracing/trace.wgsl`), so it runs on every adapter with storage buffers.

use bytemuck::{Pod, Zeroable};
use zoo_host::judge::FlatBvh;
use zoo_host::kit::{bind_group, bind_group_layout, sampler, storage, texture};
use zoo_host::scene::Scene;
use zoo_host::{RenderContext, TechniqueError, TechniqueResult, wgpu};

use crate::{BuildStats, CasterTriangle, Hierarchy, Tracer, or_one_zeroed, storage_buffer};

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

/// `RtTriangle` in `ray-tracing/trace.wgsl`: a corner and the two edges from it, and its alpha
/// test (mask layer, -1 for none, and cutoff).
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuTriangle {
    pub v0: [f32; 3],
    pub _pad: u32,
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
    pub nodes: Vec<GpuNode>,
    pub triangles: Vec<GpuTriangle>,
    pub texcoords: Vec<GpuTexcoords>,
}

impl CasterGeometry {
    /// Every shadow caster of `scene` (degenerate triangles left out).
    pub fn of(scene: &Scene) -> CasterGeometry {
        let casters = crate::caster_triangles(scene);
        let corners: Vec<_> = casters.iter().map(|c| c.corners).collect();
        let bvh = FlatBvh::build(&corners);
        let nodes = bvh
            .nodes
            .iter()
            .map(|n| GpuNode {
                min: n.min.to_array(),
                first: n.first,
                max: n.max.to_array(),
                count: n.count,
            })
            .collect();
        let (triangles, texcoords) = bvh
            .triangles
            .iter()
            .map(|&source| {
                let CasterTriangle { corners, mask, uv } = &casters[source as usize];
                let [a, b, c] = *corners;
                let triangle = GpuTriangle {
                    v0: a.to_array(),
                    _pad: 0,
                    e1: (b - a).to_array(),
                    mask_layer: mask.map_or(-1, |m| m.layer as i32),
                    e2: (c - a).to_array(),
                    alpha_cutoff: mask.map_or(0.0, |m| m.cutoff),
                };
                let texcoords = GpuTexcoords {
                    uv: uv.map(|t| t.to_array()),
                    _pad: [0.0; 2],
                };
                (triangle, texcoords)
            })
            .unzip();
        CasterGeometry {
            nodes,
            triangles,
            texcoords,
        }
    }

    /// Levels of the hierarchy (0 without casters): a traversal holds at most this many
    /// nodes plus one pending.
    pub fn depth(&self) -> u32 {
        let mut deepest = 0;
        let mut pending = if self.nodes.is_empty() {
            vec![]
        } else {
            vec![(0, 1)]
        };
        while let Some((index, level)) = pending.pop() {
            deepest = deepest.max(level);
            let node = &self.nodes[index as usize];
            if node.count == 0 {
                pending.extend([(node.first, level + 1), (node.first + 1, level + 1)]);
            }
        }
        deepest
    }
}

/// The layout of the compute traversal's group.
pub(crate) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let stages = crate::STAGES;
    bind_group_layout(
        device,
        "ray tracing layout (compute)",
        &[
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
        ],
    )
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
    // Storage buffers cannot be empty: a scene without casters gets one leaf over one
    // triangle without area, which no ray hits.
    let empty = GpuNode {
        min: [0.0; 3],
        first: 0,
        max: [0.0; 3],
        count: 1,
    };
    let nodes = if geometry.nodes.is_empty() {
        vec![empty]
    } else {
        geometry.nodes.clone()
    };
    let nodes = storage_buffer(device, "ray tracing nodes", bytemuck::cast_slice(&nodes));
    let triangles = storage_buffer(
        device,
        "ray tracing triangles",
        &or_one_zeroed::<GpuTriangle>(&geometry.triangles),
    );
    let texcoords = storage_buffer(
        device,
        "ray tracing texture coordinates",
        &or_one_zeroed::<GpuTexcoords>(&geometry.texcoords),
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
        ],
    );
    let stats = BuildStats {
        tracer: Tracer::Compute,
        triangles: geometry.triangles.len(),
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
            _pad,
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
