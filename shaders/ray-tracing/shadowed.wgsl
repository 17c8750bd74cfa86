// The exact per-triangle methods' resolve (per-triangle volumes, frustum-traced shadows): each
// pixel whose shadow ray a caster stopped gets visibility 0 in the light's slot (which holds 1,
// lit, until written).

#import "common/frame.wgsl"
#import "common/fullscreen.wgsl"

// 1 where a caster stops the pixel's ray.
@group(2) @binding(0) var<storage, read> shadowed: array<u32>;

@fragment
fn fs_resolve(in: FullscreenOut) -> @location(0) vec4<f32> {
    let pixel = vec2<u32>(in.position.xy);
    if shadowed[pixel.y * u32(camera.size.x) + pixel.x] == 0u {
        discard;
    }
    return vec4<f32>(0.0);
}
