// Planar projected shadows: mark a receiver plane's visible pixels in the stencil, then draw
// the casters flattened onto it with Blinn's matrix M = (P.L) I - L P^T.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"

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

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
}

struct Targets {
    @location(0) visibility: vec4<f32>,
    @location(1) plane_id: u32,
}

@vertex
fn vs_mark(v: VertexIn) -> @builtin(position) vec4<f32> {
    return camera.view_proj * vec4<f32>(v.position, 1.0);
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

struct ShadowOut {
    @builtin(position) clip: vec4<f32>,
    // The unprojected caster point: exact per fragment, since the whole transform is one
    // projective map and interpolation is perspective-correct.
    @location(0) world: vec3<f32>,
}

@vertex
fn vs_shadow(v: VertexIn) -> ShadowOut {
    var out: ShadowOut;
    out.clip = camera.view_proj * (projection.shadow_matrix * vec4<f32>(v.position, 1.0));
    out.world = v.position;
    return out;
}

@fragment
fn fs_shadow(in: ShadowOut) -> Targets {
    let height = dot(projection.plane, vec4<f32>(in.world, 1.0));
    let light_height = dot(projection.plane, projection.light);
    // Below the plane: a false shadow. At or beyond the light: an anti-shadow.
    if height < 0.0 || (projection.light.w > 0.0 && height >= light_height) {
        discard;
    }
    var out: Targets;
    out.visibility = vec4<f32>(projection.params.x);
    out.plane_id = 0u;
    return out;
}
