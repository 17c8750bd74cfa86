//! The scene's geometry on the GPU: shared vertex and index buffers, edge adjacency and the
//! materials.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::materials::MaterialBindings;
use crate::gpu::GpuContext;
use crate::scene::{Scene, SceneObject};

/// One stored vertex: position, normal and texture coordinates (32 bytes); world space unless
/// its object is an instance ([`Placement`]).
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

/// Each object's placement ([`crate::scene::SceneObject::placement`], column-major), read
/// per instance by vertex stages (locations 3 to 6, `Placement` in `common/vertices.wgsl`).
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
#[repr(C)]
pub struct Placement {
    pub columns: [[f32; 4]; 4],
}

impl Placement {
    /// Instance-rate buffer layout: locations 3 to 6, one column each.
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: size_of::<Placement>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &wgpu::vertex_attr_array![
            3 => Float32x4, 4 => Float32x4, 5 => Float32x4, 6 => Float32x4
        ],
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
    /// Each object's [`Placement`] (`VERTEX`).
    pub placements: wgpu::Buffer,
    /// Textures and alpha tests (`common/materials.wgsl`).
    pub materials: MaterialBindings,
    pub vertex_count: u32,
    pub index_count: u32,
    pub edge_count: u32,
}

impl SceneBuffers {
    /// The vertex buffers a pass that draws objects binds: [`Vertex`] at slot 0 and
    /// [`Placement`] at slot 1.
    pub const VERTEX_LAYOUTS: [Option<wgpu::VertexBufferLayout<'static>>; 2] =
        [Some(Vertex::LAYOUT), Some(Placement::LAYOUT)];

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
        let placements: Vec<Placement> = (scene.objects.iter())
            .map(|o| Placement {
                columns: o.placement.to_cols_array_2d(),
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
            placements: init(
                "scene placements",
                bytemuck::cast_slice(&placements),
                wgpu::BufferUsages::VERTEX,
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

    /// Draws every object (or only shadow casters) with instance index = object index, so
    /// shaders find the object's data through `@builtin(instance_index)` and its placement in
    /// vertex buffer 1.
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
        pass.set_vertex_buffer(1, self.placements.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for (range, objects) in drawn_runs(scene, keep) {
            pass.draw_indexed(range, 0, objects);
        }
    }
}

/// The draws of the objects `keep` accepts: index range and object (instance) range, with
/// consecutive objects of one range (instances) in one draw.
pub fn drawn_runs(
    scene: &Scene,
    keep: impl Fn(usize, &SceneObject) -> bool,
) -> Vec<(std::ops::Range<u32>, std::ops::Range<u32>)> {
    let mut runs: Vec<(std::ops::Range<u32>, std::ops::Range<u32>)> = Vec::new();
    for (i, object) in scene.objects.iter().enumerate() {
        if !keep(i, object) {
            continue;
        }
        let range = object.indices.start as u32..object.indices.end as u32;
        let i = i as u32;
        match runs.last_mut() {
            Some((last, objects)) if *last == range && objects.end == i => objects.end += 1,
            _ => runs.push((range, i..i + 1)),
        }
    }
    runs
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
