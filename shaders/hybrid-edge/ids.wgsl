// Hybrid shadows, pass 1 with triangle ids: every caster triangle rendered from one shadow-map
// layer, writing depth and the id of the front-most triangle in each texel. Vertices are
// pulled from the scene's storage buffers, so the id is simply the triangle's index.

#import "hybrid-edge/casters.wgsl"

struct IdVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) triangle: u32,
}

@vertex
fn vs_ids(@builtin(vertex_index) vertex: u32) -> IdVertex {
    var out: IdVertex;
    out.triangle = vertex / 3u;
    out.clip = OUTSIDE_CLIP;
    if casts_shadows(out.triangle) {
        out.clip = layer_camera.view_proj * vec4<f32>(triangle_corner(out.triangle, vertex % 3u), 1.0);
    }
    return out;
}

@fragment
fn fs_ids(in: IdVertex) -> @location(0) u32 {
    return in.triangle;
}
