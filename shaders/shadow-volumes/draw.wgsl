// Drawing shadow volumes built by `shadow-volumes/volumes.wgsl`: vertices with w = 0 are points
// at infinity; pipelines draw them with unclipped (clamped) depth and touch only the stencil.

#import "common/frame.wgsl"

@vertex
fn vs_volume(@location(0) position: vec4<f32>) -> @builtin(position) vec4<f32> {
    return camera.view_proj * position;
}

// Volumes write no colour (their pipelines mask every channel).
@fragment
fn fs_volume() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0);
}
