// Hybrid shadows, the `Stencil` restriction's mark (seed 003's own): the band pass left each
// edge pixel's depth in the band's depth image and 1 everywhere else; this full-screen pass
// over the G-buffer's depth-stencil keeps the edge pixels, whose stencil gets the mark bit
// (`zoo_shadow_volumes::mark_depth_stencil`), and discards the rest. Writes no colour.

#import "common/fullscreen.wgsl"

// The band's depth bound as unfilterable float (GLSL cannot fetch texels of depth textures).
@group(2) @binding(0) var band_depth: texture_2d<f32>;

@fragment
fn fs_mark(in: FullscreenOut) -> @location(0) vec4<f32> {
    if textureLoad(band_depth, vec2<i32>(in.position.xy), 0).r >= 1.0 {
        discard;
    }
    return vec4<f32>(0.0);
}
