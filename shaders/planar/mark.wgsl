// Planar projected shadows, first pass: mark a receiver plane's visible pixels in the
// stencil (the shadow pass, `planar/shadow.wgsl`, then draws the casters flattened onto it).

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "planar/projection.wgsl"
#import "common/vertices.wgsl"

@vertex
fn vs_mark(@location(0) position: vec3<f32>, placement: Placement) -> @builtin(position) vec4<f32> {
    return camera.view_proj * vec4<f32>(placed_position(placement, position), 1.0);
}

// Marks pixels whose G-buffer surface is this plane (the depth test already rejected pixels
// where something stands in front of it).
@fragment
fn fs_mark(@builtin(position) frag: vec4<f32>) -> Targets {
    let s = load_surface(vec2<i32>(frag.xy));
    if !s.valid || abs(dot(projection.plane.xyz, s.position) + projection.plane.w) > projection.params.z {
        discard;
    }
    var out: Targets;
    out.visibility = vec4<f32>(1.0);
    out.plane_id = u32(projection.params.y);
    return out;
}
