// Shadow-map depth pass: casters rendered from one light layer's camera. `vs_depth` writes
// depth only; `vs_depth_world` also hands the world position to a fragment stage that writes
// a colour map (moments, for example: see `light_depth`).

#import "shadow-maps/layers.wgsl"
#import "common/vertices.wgsl"

@group(0) @binding(0) var<uniform> layer_camera: LayerCamera;

@vertex
fn vs_depth(@location(0) position: vec3<f32>, placement: Placement) -> @builtin(position) vec4<f32> {
    return layer_camera.view_proj * vec4<f32>(placed_position(placement, position), 1.0);
}

struct DepthVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
}

@vertex
fn vs_depth_world(@location(0) position: vec3<f32>, placement: Placement) -> DepthVertex {
    let world = placed_position(placement, position);
    var out: DepthVertex;
    out.clip = layer_camera.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    return out;
}
