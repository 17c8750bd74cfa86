// Shadow-map lookup: one full-screen pass per light writes that light's visibility, filtered by
// the shadow-map library's filters (`shadow-maps/filters.wgsl`) through `shadow_tap` and
// `shadow_depths` below, which project each tap by itself (for point lights into whichever
// cube face it falls in), so filtering is seamless across cube faces. The maps are read
// through the library's depth lookup group (`shadow-maps/depth_lookup.wgsl`).

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/fullscreen.wgsl"
#import "shadow-maps/filters.wgsl"
#import "shadow-maps/depth_lookup.wgsl"

// Filter modes, one per variant of the Rust `Filter` parameter (`FILTER_` and its name in
// capitals). The plugin reads their values from this module, so no number is kept twice.
const FILTER_NONE: u32 = 0u;
const FILTER_HARDWARE2X2: u32 = 1u;
const FILTER_PCF3X3: u32 = 2u;
const FILTER_PCF5X5: u32 = 3u;
const FILTER_PCF7X7: u32 = 4u;
const FILTER_PCF9X9: u32 = 5u;
const FILTER_POISSON: u32 = 6u;
const FILTER_PCSS: u32 = 7u;

struct ShadowLight {
    first_layer: u32,
    // 1 (spot, directional) or 6 (point: cube faces).
    layer_count: u32,
    filter_mode: u32,
    // Index of the scene light.
    light: u32,
    // World size of a texel: per unit of distance along the face axis (perspective) or
    // absolute (orthographic).
    texel_scale: f32,
    perspective: u32,
    near: f32,
    far: f32,
    normal_offset: f32,
    kernel_texels: f32,
    // Light radius (point, spot) or tangent of the angular radius (directional).
    light_size: f32,
    search_texels: f32,
    position: vec3<f32>,
    // 1 when this light's diagnostics are written.
    debug: u32,
    direction: vec3<f32>,
    _pad: f32,
}

// The light being looked up; the maps come from `shadow-maps/depth_lookup.wgsl` (group 3).
@group(2) @binding(0) var<uniform> shadow_light: ShadowLight;

fn project(sl: ShadowLight, p: vec3<f32>) -> MapPoint {
    return map_point(light_layer(sl.first_layer, sl.layer_count, sl.position, p), p);
}

// Distance along the map's axis for a [0, 1] depth value.
fn linear_depth(sl: ShadowLight, d: f32) -> f32 {
    if sl.perspective == 1u {
        return sl.near * sl.far / (sl.far - d * (sl.far - sl.near));
    }
    return sl.near + d * (sl.far - sl.near);
}


// Unit direction light rays travel at p.
fn ray_direction(sl: ShadowLight, p: vec3<f32>) -> vec3<f32> {
    if sl.perspective == 1u {
        return normalize(p - sl.position);
    }
    return sl.direction;
}

// World size of one shadow-map texel at p.
fn texel_world(sl: ShadowLight, p: vec3<f32>) -> f32 {
    if sl.perspective == 0u {
        return sl.texel_scale;
    }
    let d = p - sl.position;
    if sl.layer_count == 6u {
        let a = abs(d);
        return sl.texel_scale * max(a.x, max(a.y, a.z));
    }
    return sl.texel_scale * dot(d, sl.direction);
}

// The light being looked up (set first thing in `fs_lookup`), for the filters' map access.
var<private> looked_up: ShadowLight;

// One comparison tap (the filters' map access): 1 = lit; outside the map = lit.
fn shadow_tap(p: vec3<f32>, linear: bool) -> f32 {
    return compare_map(project(looked_up, p), linear);
}

// (inside, receiver depth, stored depth) at p, depths along the map's axis.
fn shadow_depths(p: vec3<f32>) -> vec3<f32> {
    let m = project(looked_up, p);
    if !m.inside {
        return vec3<f32>(0.0);
    }
    return vec3<f32>(1.0, linear_depth(looked_up, m.depth), linear_depth(looked_up, stored_map_depth(m)));
}

struct Outputs {
    @location(0) visibility: vec4<f32>,
    // r: inside the map (coverage), g: receiver minus stored depth in texels.
    @location(1) diagnostics: vec4<f32>,
}

@fragment
fn fs_lookup(in: FullscreenOut) -> Outputs {
    var out: Outputs;
    out.visibility = vec4<f32>(1.0);
    out.diagnostics = vec4<f32>(0.0);
    let s = load_surface(vec2<i32>(in.position.xy));
    if !s.valid {
        return out;
    }
    let sl = shadow_light;
    looked_up = sl;
    // Write only where the light reaches, so lights with disjoint influence can share a slot.
    let light = lights[sl.light];
    if light.kind != LIGHT_DIRECTIONAL {
        let to_surface = s.position - light.position;
        let distance = length(to_surface);
        if distance >= light.range
            || (light.kind == LIGHT_SPOT && dot(to_surface, light.direction) <= light.cos_outer * distance) {
            discard;
        }
    }
    let texel = texel_world(sl, s.position);
    // Normal offset: move the lookup point off the surface by a number of texels.
    let p = s.position + s.normal * (sl.normal_offset * texel);
    let frame = tangent_frame(ray_direction(sl, p));
    let r = rotation(in.position.xy);
    var visibility = 1.0;
    switch sl.filter_mode {
        case FILTER_NONE: { visibility = shadow_tap(p, false); }
        case FILTER_HARDWARE2X2: { visibility = shadow_tap(p, true); }
        case FILTER_PCF3X3: { visibility = grid_pcf(p, frame, texel, 3); }
        case FILTER_PCF5X5: { visibility = grid_pcf(p, frame, texel, 5); }
        case FILTER_PCF7X7: { visibility = grid_pcf(p, frame, texel, 7); }
        case FILTER_PCF9X9: { visibility = grid_pcf(p, frame, texel, 9); }
        case FILTER_POISSON: { visibility = poisson_pcf(p, frame, sl.kernel_texels * texel, r); }
        default: {
            let light = PcssLight(sl.light_size, sl.near, sl.perspective == 1u, sl.search_texels);
            visibility = pcss(p, frame, texel, r, light);
        }
    }
    out.visibility = vec4<f32>(visibility);
    if sl.debug == 1u {
        let m = project(sl, s.position);
        if m.inside {
            let difference = linear_depth(sl, m.depth) - linear_depth(sl, stored_map_depth(m));
            out.diagnostics = vec4<f32>(1.0, difference / texel, 0.0, 1.0);
        }
    }
    return out;
}
