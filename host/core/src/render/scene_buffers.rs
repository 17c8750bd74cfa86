//! The scene's geometry on the GPU: shared vertex and index buffers, edge adjacency and the
//! materials.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::materials::MaterialBindings;
use crate::gpu::GpuContext;
use crate::scene::{Scene, SceneObject};

/// One vertex: world-space position, normal and texture coordinates (32 bytes).
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
#[repr(C)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

impl Vertex {
    /// Vertex buffer layout: location 0 position, location 1 normal, location 2 texture
    /// coordinates.
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2],
    };
}

/// Geometry buffers, built once per scene.
pub struct SceneBuffers {
    /// All vertices (`VERTEX | STORAGE`).
    pub vertices: wgpu::Buffer,
    /// Triangle indices, u32 (`INDEX | STORAGE`).
    pub indices: wgpu::Buffer,
    /// [`crate::scene::EdgeRecord`]s (`STORAGE`).
    pub edges: wgpu::Buffer,
    /// Edge incidences `triangle << 1 | reversed` (`STORAGE`).
    pub edge_faces: wgpu::Buffer,
    /// Object index of each triangle (`STORAGE`).
    pub triangle_objects: wgpu::Buffer,
    /// Textures and alpha tests (`common/materials.wgsl`).
    pub materials: MaterialBindings,
    pub vertex_count: u32,
    pub index_count: u32,
    pub edge_count: u32,
}

impl SceneBuffers {
    /// Uploads `scene`'s geometry.
    pub fn new(gpu: &GpuContext, scene: &Scene) -> SceneBuffers {
        let vertices: Vec<Vertex> = scene
            .mesh
            .positions
            .iter()
            .zip(&scene.mesh.normals)
            .enumerate()
            .map(|(i, (p, n))| Vertex {
                position: p.to_array(),
                normal: n.to_array(),
                uv: scene
                    .mesh
                    .uvs
                    .get(i)
                    .copied()
                    .unwrap_or_default()
                    .to_array(),
            })
            .collect();
        let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            // Storage bindings must not be empty.
            let padded;
            let contents = if contents.is_empty() {
                padded = [0u8; 16];
                &padded[..]
            } else {
                contents
            };
            gpu.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage,
                })
        };
        let storage = wgpu::BufferUsages::STORAGE;
        SceneBuffers {
            vertices: init(
                "scene vertices",
                bytemuck::cast_slice(&vertices),
                wgpu::BufferUsages::VERTEX | storage,
            ),
            indices: init(
                "scene indices",
                bytemuck::cast_slice(&scene.mesh.indices),
                wgpu::BufferUsages::INDEX | storage,
            ),
            edges: init(
                "scene edges",
                bytemuck::cast_slice(&scene.adjacency.edges),
                storage,
            ),
            edge_faces: init(
                "scene edge faces",
                bytemuck::cast_slice(&scene.adjacency.edge_faces),
                storage,
            ),
            triangle_objects: init(
                "scene triangle objects",
                bytemuck::cast_slice(&scene.triangle_objects()),
                storage,
            ),
            materials: MaterialBindings::new(gpu, scene),
            vertex_count: vertices.len() as u32,
            index_count: scene.mesh.indices.len() as u32,
            edge_count: scene.adjacency.edges.len() as u32,
        }
    }

    /// Draws the objects `keep(index, object)` accepts whose alpha test is `masked` (for
    /// passes that draw alpha-tested objects with a pipeline of their own).
    pub fn draw_objects_masked(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &Scene,
        masked: bool,
        keep: impl Fn(usize, &SceneObject) -> bool,
    ) {
        self.draw_objects_where(pass, scene, |i, o| {
            o.alpha_mask.is_some() == masked && keep(i, o)
        });
    }

    /// Draws every object (or only shadow casters) with `first_instance` = object index, so
    /// shaders find the object's data through `@builtin(instance_index)`.
    pub fn draw_objects(&self, pass: &mut wgpu::RenderPass<'_>, scene: &Scene, casters_only: bool) {
        self.draw_objects_where(pass, scene, |_, o| o.casts_shadows || !casters_only);
    }

    /// As [`Self::draw_objects`] for the objects `keep(index, object)` accepts.
    pub fn draw_objects_where(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &Scene,
        keep: impl Fn(usize, &SceneObject) -> bool,
    ) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for (i, object) in scene.objects.iter().enumerate() {
            if keep(i, object) {
                let range = object.indices.start as u32..object.indices.end as u32;
                pass.draw_indexed(range, 0, i as u32..i as u32 + 1);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shaders_read_vertices_with_their_size() {
        let composed = crate::ShaderLibrary::embedded()
            .compose("common/vertices.wgsl")
            .unwrap();
        let floats = crate::gpu::layout::wgsl_integer_constant(&composed.source, "VERTEX_FLOATS");
        assert_eq!(floats, Ok((size_of::<Vertex>() / 4) as i64));
    }
}
