// Ray-traced shadows: from each pixel's surface, any-hit rays through the casters
// (`ray-tracing/trace.wgsl`, or ray queries) to the light: one to its centre (hard), or
// several to points of its disk (soft), the disk and its orientation those of the judge's area
// reference (a disk of the light's radius facing the point; for the sun, a cone of its angular
// radius). Translucent casters filter the rays no blocking caster stops (`fs_transmittance`).
// Hard lights go straight into their slots; soft ones into a history averaged over frames,
// which the filter (`rt-shadows/denoise.wgsl`) resolves into their slots.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "common/fullscreen.wgsl"
#import "ray-tracing/trace.wgsl"
#import "ray-tracing/shadow_ray.wgsl"
#import "ray-tracing/light_rays.wgsl"
#import "rt-shadows/light.wgsl"

// The light's visibility (and transmittance when `coloured`) from the surface at `pixel`.
fn trace(pixel: vec2<i32>, coloured: bool) -> RtTraced {
    let light = lights[rt_light.light];
    let rotation = rt_pixel_rotation(vec2<u32>(pixel));
    return rt_light_visibility(load_surface(pixel), light, rt_light.rays, rt_light.frame, rotation, coloured);
}

// Hard lights, into their slots (which hold 1, lit, until written).
@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    if rt_light.soft == 1u {
        discard;
    }
    let visibility = trace(vec2<i32>(in.position.xy), false).visibility;
    if visibility >= 1.0 {
        discard;
    }
    // Every channel: the pass's blend constant keeps only this light's.
    return vec4<f32>(visibility);
}

// Soft lights, into the history: the pass's blend weighs this frame against the frames
// before (and keeps only this light's channel).
@fragment
fn fs_accumulate(in: FullscreenOut) -> @location(0) vec4<f32> {
    return vec4<f32>(trace(vec2<i32>(in.position.xy), false).visibility);
}

// Every light's transmittance, into its transmittance slot (white until written), in scenes
// with translucent casters. Soft lights' colour is this frame's rays' alone (not averaged).
@fragment
fn fs_transmittance(in: FullscreenOut) -> @location(0) vec4<f32> {
    let transmittance = trace(vec2<i32>(in.position.xy), true).transmittance;
    if all(transmittance >= vec3<f32>(1.0)) {
        discard;
    }
    return vec4<f32>(transmittance, 1.0);
}

// The distance from the surface to the nearest blocking caster toward the light's centre (a
// closest-hit ray; 0 where nothing blocks it or the light does not reach), for the `blocker
// distance` debug view.
@fragment
fn fs_blocker_distance(in: FullscreenOut) -> @location(0) vec4<f32> {
    let s = load_surface(vec2<i32>(in.position.xy));
    let light = lights[rt_light.light];
    let toward = light_vector(light, s.position);
    if !s.valid || light_falloff(light, s.position) <= 0.0 {
        discard;
    }
    let origin = ray_origin(s);
    var to_light = 3.0e38;
    if light.kind != LIGHT_DIRECTIONAL {
        to_light = distance(light.position, origin);
    }
    let ray = shadow_ray(s, origin, normalize(toward), to_light);
    let hit = rt_closest(ray.origin, ray.direction, ray.reach);
    if !hit.found {
        discard;
    }
    return vec4<f32>(ray.skipped + hit.t, 0.0, 0.0, 1.0);
}
