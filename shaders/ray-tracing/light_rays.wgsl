// Shadow rays from a G-buffer surface to a light, as the judge's references trace them: one to
// its centre (hard), or several to points of its disk (soft: the disk and its orientation those
// of the judge's area reference, a disk of the light's radius facing the point, or for the sun
// a cone of its angular radius), each counted by its cosine to the normal. rt-shadows and ddgi
// trace their direct shadows with it. A shader imports `ray-tracing/trace.wgsl` (which the
// library swaps for ray queries) before this module.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "ray-tracing/shadow_ray.wgsl"

// Two unit vectors perpendicular to unit `w` and to each other.
fn rt_basis(w: vec3<f32>) -> mat2x3<f32> {
    let helper = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(w.x) < 0.9);
    let u = normalize(cross(w, helper));
    return mat2x3<f32>(u, cross(w, u));
}

// A point of the unit disk for `square` in [0, 1)², area-preserving (Shirley and Chiu's
// concentric map).
fn rt_concentric_disk(square: vec2<f32>) -> vec2<f32> {
    let a = square * 2.0 - 1.0;
    if all(a == vec2<f32>(0.0)) {
        return a;
    }
    let quarter = 0.78539816;
    if abs(a.x) > abs(a.y) {
        let phi = quarter * a.y / a.x;
        return a.x * vec2<f32>(cos(phi), sin(phi));
    }
    let phi = 2.0 * quarter - quarter * a.x / a.y;
    return a.y * vec2<f32>(cos(phi), sin(phi));
}

// Point `index` of the R2 low-discrepancy sequence (stratified for any count), in 0.32 fixed
// point so that it stays exact however long frames accumulate.
fn rt_r2(index: u32) -> vec2<f32> {
    return vec2<f32>(f32((index * 3242174889u) >> 8u), f32((index * 2447445413u) >> 8u)) / 16777216.0;
}

// A hash of the pixel in [0, 1)² (PCG), the rotation of its sample pattern.
fn rt_pixel_rotation(pixel: vec2<u32>) -> vec2<f32> {
    var h = pixel.x * 747796405u + pixel.y * 2891336453u + 1u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    let a = (h >> 22u) ^ h;
    let b = a * 747796405u + 2891336453u;
    return vec2<f32>(f32(a >> 8u), f32(b >> 8u)) / 16777216.0;
}

// What the rays from a surface bring back: the fraction of the light no blocking caster stops
// (`visibility`), and the colour translucent casters let through of that (`transmittance`;
// white without them), so that their product is the colour fraction that arrives.
struct RtTraced {
    visibility: f32,
    transmittance: vec3<f32>,
}

// The visibility of `light` from surface `s` and, when `coloured`, its transmittance (white
// otherwise): 1 where there is no surface or the light does not reach. `rays_asked` rays toward
// its disk (one to its centre for a light without a radius), the rotated R2 sequence from point
// `sequence * rays` on (`sequence` continues it frame after frame), turned by `rotation`.
fn rt_light_visibility(s: Surface, light: Light, rays_asked: u32, sequence: u32, rotation: vec2<f32>, coloured: bool) -> RtTraced {
    let toward = light_vector(light, s.position);
    if !s.valid || light_falloff(light, s.position) <= 0.0 {
        return RtTraced(1.0, vec3<f32>(1.0));
    }
    let origin = ray_origin(s);

    let rays = select(rays_asked, 1u, light.radius <= 0.0);
    let disk = rt_basis(toward);
    // Each ray counts with its cosine to the normal, as the judge's area reference: the part
    // of the light below the surface's horizon lights nothing, shadowed or not.
    var lit = 0u;
    var arrived = 0.0;
    var total = 0.0;
    // The colour the unblocked rays bring, counted as `lit` and as `arrived`.
    var colour_lit = vec3<f32>(0.0);
    var colour_arrived = vec3<f32>(0.0);
    for (var i = 0u; i < rays; i++) {
        // The rotated R2 sequence, continued frame after frame.
        var offset = vec2<f32>(0.0);
        if rays > 1u {
            offset = rt_concentric_disk(fract(rotation + rt_r2(sequence * rays + i)));
        }
        var direction: vec3<f32>;
        var to_light: f32;
        if light.kind == LIGHT_DIRECTIONAL {
            direction = normalize(toward + tan(light.radius) * (disk * offset));
            to_light = 3.0e38;
        } else {
            let target_point = light.position + light.radius * (disk * offset);
            to_light = distance(target_point, origin);
            direction = (target_point - origin) / to_light;
        }
        let weight = max(dot(s.normal, direction), 0.0);
        total += weight;
        let ray = shadow_ray(s, origin, direction, to_light);
        if !rt_occluded(ray.origin, direction, ray.reach) {
            var colour = vec3<f32>(1.0);
            if coloured {
                colour = rt_transmittance(ray.origin, direction, ray.reach);
            }
            lit += 1u;
            arrived += weight;
            colour_lit += colour;
            colour_arrived += weight * colour;
        }
    }
    if rays == 1u || total <= 0.0 {
        return RtTraced(f32(lit) / f32(rays), select(vec3<f32>(1.0), colour_lit / f32(lit), lit > 0u));
    }
    return RtTraced(arrived / total, select(vec3<f32>(1.0), colour_arrived / arrived, arrived > 0.0));
}
