// The README's example technique: a surface facing away from the light is shadowed.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "common/fullscreen.wgsl"

// `Pass`, declared in examples/backfacing/src/lib.rs.
#import "backfacing/pass.wgsl"

@group(2) @binding(0) var<uniform> pass_data: Pass;

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let s = load_surface(vec2<i32>(in.position.xy));
    let light = lights[pass_data.light];
    if !s.valid || dot(s.normal, light_vector(light, s.position)) > 0.0 {
        discard;
    }
    // Every channel: the pass's blend constant keeps only this light's.
    return vec4<f32>(pass_data.darkness);
}
