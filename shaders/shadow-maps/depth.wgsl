// Shadow-map depth pass: casters rendered from one light layer's camera. `vs_depth` writes
// depth only; `vs_depth_world` also hands the world position to a fragment stage that writes
// a colour map (moments, for example: see `light_depth`).

#import "shadow-maps/layers.wgsl"

@group(0) @binding(0) var<uniform> layer_camera: LayerCamera;

@vertex
fn vs_depth(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return layer_camera.view_proj * vec4<f32>(position, 1.0);
}

struct DepthVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
}

@vertex
fn vs_depth_world(@location(0) position: vec3<f32>) -> DepthVertex {
    var out: DepthVertex;
    out.clip = layer_camera.view_proj * vec4<f32>(position, 1.0);
    out.world = position;
    return out;
}
