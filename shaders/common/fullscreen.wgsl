// A triangle covering the screen; draw with 3 vertices.

struct FullscreenOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

// Texture coordinates (0..2) of vertex `index` of the screen-covering triangle.
fn fullscreen_uv(index: u32) -> vec2<f32> {
    return vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
}

// Clip position of vertex `index` of the screen-covering triangle.
fn fullscreen_position(index: u32) -> vec4<f32> {
    return vec4<f32>(fullscreen_uv(index) * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
}

@vertex
fn fullscreen_vs(@builtin(vertex_index) index: u32) -> FullscreenOut {
    var out: FullscreenOut;
    out.position = fullscreen_position(index);
    out.uv = fullscreen_uv(index);
    return out;
}
