// The uniforms of one (light, receiver plane) pair, shared by the marking and the shadow
// passes of planar projected shadows.

#import "planar/projection_uniform.wgsl"

@group(2) @binding(0) var<uniform> projection: Projection;

// The two targets of both passes: the light's visibility slot and the plane ids.
struct Targets {
    @location(0) visibility: vec4<f32>,
    @location(1) plane_id: u32,
}
