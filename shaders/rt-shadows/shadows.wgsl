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
#import "rt-shadows/light.wgsl"

// Two unit vectors perpendicular to unit `w` and to each other.
fn basis(w: vec3<f32>) -> mat2x3<f32> {
    let helper = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(w.x) < 0.9);
    let u = normalize(cross(w, helper));
    return mat2x3<f32>(u, cross(w, u));
}

// A point of the unit disk for `square` in [0, 1)², area-preserving (Shirley and Chiu's
// concentric map).
fn concentric_disk(square: vec2<f32>) -> vec2<f32> {
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
fn r2(index: u32) -> vec2<f32> {
    return vec2<f32>(f32((index * 3242174889u) >> 8u), f32((index * 2447445413u) >> 8u)) / 16777216.0;
}

// A hash of the pixel in [0, 1)² (PCG), the rotation of its sample pattern.
fn pixel_rotation(pixel: vec2<u32>) -> vec2<f32> {
    var h = pixel.x * 747796405u + pixel.y * 2891336453u + 1u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    let a = (h >> 22u) ^ h;
    let b = a * 747796405u + 2891336453u;
    return vec2<f32>(f32(a >> 8u), f32(b >> 8u)) / 16777216.0;
}

// What the rays from a surface bring back: the fraction of the light no blocking caster stops
// (`visibility`), and the colour translucent casters let through of that (`transmittance`;
// white without them), so that their product is the colour fraction that arrives.
struct Traced {
    visibility: f32,
    transmittance: vec3<f32>,
}

// The light's visibility, and its transmittance when `coloured` (white otherwise), from the
// surface at `pixel` (1 where there is none or the light does not reach).
fn trace(pixel: vec2<i32>, coloured: bool) -> Traced {
    let s = load_surface(pixel);
    let light = lights[rt_light.light];
    let toward = light_vector(light, s.position);
    if !s.valid || light_falloff(light, s.position) <= 0.0 {
        return Traced(1.0, vec3<f32>(1.0));
    }
    let origin = ray_origin(s);

    let rays = select(rt_light.rays, 1u, light.radius <= 0.0);
    let disk = basis(toward);
    let rotation = pixel_rotation(vec2<u32>(pixel));
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
            offset = concentric_disk(fract(rotation + r2(rt_light.frame * rays + i)));
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
        return Traced(f32(lit) / f32(rays), select(vec3<f32>(1.0), colour_lit / f32(lit), lit > 0u));
    }
    return Traced(arrived / total, select(vec3<f32>(1.0), colour_arrived / arrived, arrived > 0.0));
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
