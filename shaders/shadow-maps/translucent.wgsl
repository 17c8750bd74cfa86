// Translucent casters seen from one light layer: each texel keeps the smallest transmittance
// colour (rgb) and the nearest `light_depth` (a) of the translucent surfaces in front of the opaque
// depth map, by a min blend. Techniques look up the colour behind that depth (coloured
// shadows) and use the depth as a blocker (soft translucent shadows). Cleared to white, depth 1.
// The depth carries a slope-scaled bias, so lit translucent surfaces do not tint themselves.

#import "common/frame.wgsl"
#import "shadow-maps/layers.wgsl"
#import "common/vertices.wgsl"

@group(1) @binding(0) var<uniform> layer_camera: LayerCamera;

struct TranslucentVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) object: u32,
}

@vertex
fn vs_translucent(
    @location(0) position: vec3<f32>,
    @builtin(instance_index) object: u32,
    placement: Placement,
) -> TranslucentVertex {
    let world = placed_position(placement, position);
    var out: TranslucentVertex;
    out.clip = layer_camera.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.object = object;
    return out;
}

// Slope-scaled bias of the stored depth, in depth slopes (the depth pass's hardware bias does
// not apply to a colour channel).
const TRANSLUCENT_SLOPE_BIAS: f32 = 2.0;

// The depth is `light_depth` (distance over far, or the orthographic depth): linear, so the
// 16-bit channel keeps a relative precision of 1e-3 at every distance.
@fragment
fn fs_translucent(v: TranslucentVertex) -> @location(0) vec4<f32> {
    let d = light_depth(layer_camera, v.world);
    let slope = max(abs(dpdx(d)), abs(dpdy(d)));
    return vec4<f32>(objects[v.object].transmittance.rgb, d + TRANSLUCENT_SLOPE_BIAS * slope);
}
