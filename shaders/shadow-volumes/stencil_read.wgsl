// Passes that read the stencil counts the volumes leave (`zoo_shadow_volumes::stencil`): the
// resolve, which shadows every pixel with a non-zero count, and the count view, drawn once per
// count level with the stencil test selecting the pixels.

#import "common/fullscreen.wgsl"

// Drawn where the stencil count is non-zero: the light is blocked.
@fragment
fn fs_shadowed() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0);
}

// The count view's triangle; the level's id comes in as the instance index.
struct CountVertex {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) level: u32,
}

@vertex
fn vs_count(@builtin(vertex_index) vertex: u32, @builtin(instance_index) level: u32) -> CountVertex {
    var out: CountVertex;
    out.position = fullscreen_position(vertex);
    out.level = level;
    return out;
}

@fragment
fn fs_count(in: CountVertex) -> @location(0) u32 {
    return in.level;
}
