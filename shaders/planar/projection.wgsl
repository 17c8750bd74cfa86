// The uniforms of one (light, receiver plane) pair, shared by the marking and the shadow
// passes of planar projected shadows.

struct Projection {
    shadow_matrix: mat4x4<f32>,
    // Receiver plane (n, d): n . x + d = 0, n pointing to the lit side.
    plane: vec4<f32>,
    // Homogeneous light: (position, 1) or (direction toward the light, 0).
    light: vec4<f32>,
    // x: visibility written in shadow, y: plane id, z: distance tolerance for plane pixels.
    params: vec4<f32>,
}

@group(2) @binding(0) var<uniform> projection: Projection;

// The two targets of both passes: the light's visibility slot and the plane ids.
struct Targets {
    @location(0) visibility: vec4<f32>,
    @location(1) plane_id: u32,
}
