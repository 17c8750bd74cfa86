// Shadow-map depth pass: casters rendered from one light layer's camera (depth only).

struct LayerCamera {
    view_proj: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> layer_camera: LayerCamera;

@vertex
fn vs_depth(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return layer_camera.view_proj * vec4<f32>(position, 1.0);
}
