// Translucent casters seen from one light layer: each texel keeps the smallest transmittance
// colour (rgb) and the nearest depth (a) of the translucent surfaces in front of the opaque
// depth map, by a min blend. Techniques look up the colour behind that depth (coloured
// shadows) and use the depth as a blocker (soft translucent shadows). Cleared to white, depth 1.

#import "common/frame.wgsl"
#import "shadow-maps/layers.wgsl"

@group(1) @binding(0) var<uniform> layer_camera: LayerCamera;

struct TranslucentVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) object: u32,
}

@vertex
fn vs_translucent(
    @location(0) position: vec3<f32>,
    @builtin(instance_index) object: u32,
) -> TranslucentVertex {
    var out: TranslucentVertex;
    out.clip = layer_camera.view_proj * vec4<f32>(position, 1.0);
    out.object = object;
    return out;
}

@fragment
fn fs_translucent(v: TranslucentVertex) -> @location(0) vec4<f32> {
    return vec4<f32>(objects[v.object].transmittance.rgb, v.clip.z);
}
