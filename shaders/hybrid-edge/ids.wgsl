// Hybrid shadows, pass 1 with triangle ids: every caster triangle rendered from one shadow-map
// layer, writing depth and the id of the front-most triangle in each texel. Vertices are
// pulled from the scene's storage buffers; the id is the triangle's drawn index
// (`drawn_triangle_id`: instances counted).

#import "hybrid-edge/casters.wgsl"

struct IdVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) triangle: u32,
}

@vertex
fn vs_ids(@builtin(vertex_index) vertex: u32, @builtin(instance_index) object: u32) -> IdVertex {
    let triangle = vertex / 3u;
    var out: IdVertex;
    out.triangle = drawn_triangle_id(object, triangle);
    out.clip = layer_camera.view_proj * vec4<f32>(triangle_corner(object, triangle, vertex % 3u), 1.0);
    return out;
}

@fragment
fn fs_ids(in: IdVertex) -> @location(0) u32 {
    return in.triangle;
}
