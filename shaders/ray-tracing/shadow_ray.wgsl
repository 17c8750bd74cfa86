// Shadow rays from the G-buffer's surfaces, as the judge's rays leave them: rt-shadows traces
// them, and the exact per-triangle methods test them against each caster triangle.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "ray-tracing/origin.wgsl"

// Where rays from surface `s` start: off the surface on the camera's side (the G-buffer's
// normal faces the camera) by the bound on the position's rounding, as the judge's rays
// start (`ray-tracing/origin.wgsl`). A light behind the surface shadows its own points, which
// it does not light either; a light grazing it is not taken for one behind by the rounding.
fn ray_origin(s: Surface) -> vec3<f32> {
    return rt_gbuffer_ray_origin(s.position, s.normal, camera.position);
}

// A shadow ray from surface `s`: from `origin` along unit `direction` up to `reach`.
struct ShadowRay {
    origin: vec3<f32>,
    direction: vec3<f32>,
    reach: f32,
    // How far along the ray from `origin` it starts (past the rasteriser's error).
    skipped: f32,
}

// The ray from `origin` (`ray_origin(s)`) along `direction` toward a light `distance` away,
// started past the stretch where it could meet its own surface again
// (`rt_gbuffer_raster_skip`) and ended short of the light by the distance's rounding, as the
// judge's rays end (`RT_TO_LIGHT`): a caster through the light's point does not stop it.
fn shadow_ray(s: Surface, origin: vec3<f32>, direction: vec3<f32>, distance: f32) -> ShadowRay {
    let reach = distance * RT_TO_LIGHT;
    // A pixel's side at unit distance: the view plane's height over the pixels.
    let pixel = 2.0 / (camera.proj[1][1] * camera.size.y);
    let skip = min(rt_gbuffer_raster_skip(s.position, s.normal, camera.position, direction, pixel), reach);
    return ShadowRay(origin + direction * skip, direction, reach - skip, skip);
}

// The hard shadow ray from surface `s` to the centre of `light` (for the sun, along its
// direction, unbounded).
fn hard_shadow_ray(s: Surface, light: Light) -> ShadowRay {
    let origin = ray_origin(s);
    if light.kind == LIGHT_DIRECTIONAL {
        return shadow_ray(s, origin, normalize(light_vector(light, s.position)), 3.0e38);
    }
    let to_light = distance(light.position, origin);
    return shadow_ray(s, origin, (light.position - origin) / to_light, to_light);
}
