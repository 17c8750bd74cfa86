// Hybrid shadows, pass 1 with triangle ids: every caster triangle rendered from one shadow-map
// layer, writing depth and the id of the front-most triangle in each texel. Vertices are
// pulled from the scene's storage buffers, so the id is simply the triangle's index.

#import "common/frame.wgsl"
#import "shadow-maps/layers.wgsl"

@group(1) @binding(0) var<uniform> layer_camera: LayerCamera;
// The scene's vertices (position, normal: six floats each) and triangle indices.
@group(1) @binding(1) var<storage, read> scene_vertices: array<f32>;
@group(1) @binding(2) var<storage, read> scene_indices: array<u32>;
// The object of each triangle.
@group(1) @binding(3) var<storage, read> triangle_objects: array<u32>;

struct IdVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) triangle: u32,
}

fn scene_position(index: u32) -> vec3<f32> {
    let base = index * 6u;
    return vec3<f32>(scene_vertices[base], scene_vertices[base + 1u], scene_vertices[base + 2u]);
}

@vertex
fn vs_ids(@builtin(vertex_index) vertex: u32) -> IdVertex {
    var out: IdVertex;
    out.triangle = vertex / 3u;
    // Triangles of objects that cast no shadows move outside the clip volume.
    if objects[triangle_objects[out.triangle]].material.y == 0.0 {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    out.clip = layer_camera.view_proj * vec4<f32>(scene_position(scene_indices[vertex]), 1.0);
    return out;
}

@fragment
fn fs_ids(in: IdVertex) -> @location(0) u32 {
    return in.triangle;
}
