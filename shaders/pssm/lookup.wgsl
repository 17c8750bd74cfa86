// Parallel-split shadow maps: the lookup. Each pixel picks its split by view depth and filters
// that split's map with the shadow-map library's filters; in the last `blend` fraction of a
// split it blends with the next split's result, so split borders do not show. Diagnostics
// (for the debug light): split colours and the effective texel density.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/fullscreen.wgsl"
#import "shadow-maps/filters.wgsl"
#import "shadow-maps/depth_lookup.wgsl"
#import "pssm/density.wgsl"

// One light's splits, filter and diagnostics switch (`PssmLight` in the plugin's Rust).
#import "pssm/pssm_light.wgsl"

@group(2) @binding(0) var<uniform> pssm: PssmLight;

const SPLIT_COLOURS: array<vec3<f32>, 8> = array<vec3<f32>, 8>(
    vec3<f32>(0.95, 0.3, 0.25),
    vec3<f32>(0.3, 0.85, 0.3),
    vec3<f32>(0.3, 0.5, 1.0),
    vec3<f32>(0.95, 0.85, 0.2),
    vec3<f32>(0.85, 0.35, 0.95),
    vec3<f32>(0.2, 0.9, 0.9),
    vec3<f32>(1.0, 0.6, 0.2),
    vec3<f32>(0.7, 0.7, 0.7),
);

fn distance_at(i: u32) -> f32 {
    return pssm.distances[i / 4u][i % 4u];
}

// The split a lookup reads (set before calling the filters).
var<private> tap_layer: u32;
var<private> tap_near: f32;
var<private> tap_far: f32;

// One comparison tap in the current split (the filters' map access).
fn shadow_tap(p: vec3<f32>, linear: bool) -> f32 {
    return compare_map(map_point(tap_layer, p), linear);
}

// (inside, receiver depth, stored depth) at p in the current split, depths along the light.
fn shadow_depths(p: vec3<f32>) -> vec3<f32> {
    let m = map_point(tap_layer, p);
    if !m.inside {
        return vec3<f32>(0.0);
    }
    let range = tap_far - tap_near;
    return vec3<f32>(1.0, tap_near + m.depth * range, tap_near + stored_map_depth(m) * range);
}

fn split_visibility(s: Surface, split: u32, direction: vec3<f32>, noise: FilterNoise) -> f32 {
    tap_layer = pssm.first_layer + split;
    tap_near = pssm.depth_near[split / 4u][split % 4u];
    tap_far = pssm.depth_far[split / 4u][split % 4u];
    let texel = pssm.texel[split / 4u][split % 4u];
    let p = s.position + s.normal * (pssm.normal_offset * texel);
    let frame = tangent_frame(direction);
    return filter_map(pssm.map_filter, TapPlane(p, s.normal, direction, true), frame, texel, noise, tap_near, false);
}

struct Outputs {
    @location(0) visibility: vec4<f32>,
    // Split colour, shaded by visibility.
    @location(1) splits: vec4<f32>,
    // Effective texel density in false colour.
    @location(2) density: vec4<f32>,
}

@fragment
fn fs_pssm(in: FullscreenOut) -> Outputs {
    var out: Outputs;
    out.visibility = vec4<f32>(1.0);
    out.splits = vec4<f32>(0.0);
    out.density = vec4<f32>(0.0);
    let s = load_surface(vec2<i32>(in.position.xy));
    if !s.valid {
        return out;
    }
    let direction = lights[pssm.light].direction;
    let depth = -(camera.view * vec4<f32>(s.position, 1.0)).z;
    var split = 0u;
    while split + 1u < pssm.splits && depth > distance_at(split + 1u) {
        split += 1u;
    }
    let noise = filter_noise(in.position.xy, camera.frame);
    var visibility = split_visibility(s, split, direction, noise);
    var weight = 0.0;
    if split + 1u < pssm.splits {
        let end = distance_at(split + 1u);
        let band = pssm.blend * (end - distance_at(split));
        if band > 0.0 {
            weight = clamp((depth - (end - band)) / band, 0.0, 1.0);
        }
        if weight > 0.0 {
            visibility = mix(visibility, split_visibility(s, split + 1u, direction, noise), weight);
        }
    }
    out.visibility = vec4<f32>(visibility);
    if pssm.diagnostics == 1u {
        let next = min(split + 1u, 7u);
        let colour = mix(SPLIT_COLOURS[split], SPLIT_COLOURS[next], weight);
        out.splits = vec4<f32>(colour * (0.45 + 0.55 * visibility), 1.0);
        let texel = pssm.texel[split / 4u][split % 4u];
        out.density = vec4<f32>(density_colour(texels_per_pixel(depth, texel)), 1.0);
    }
    return out;
}
