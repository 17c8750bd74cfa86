// Shadow-map lookup: one full-screen pass per light writes that light's visibility, filtered by
// the shadow-map library's filters (`shadow-maps/filters.wgsl`) through `shadow_tap` and
// `shadow_depths` below, which project each tap by itself (for point lights into whichever
// cube face it falls in), so filtering is seamless across cube faces. The maps are read
// through the library's depth lookup group (`shadow-maps/depth_lookup.wgsl`).

#import "common/fullscreen.wgsl"
#import "shadow-maps/receiver.wgsl"
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
    map: MapHeader,
    filter_mode: u32,
    kernel_texels: f32,
    // Light radius (point, spot) or tangent of the angular radius (directional).
    light_size: f32,
    search_texels: f32,
    // 1 when this light's diagnostics are written.
    debug: u32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

// The light being looked up; the maps come from `shadow-maps/depth_lookup.wgsl` (group 3).
@group(2) @binding(0) var<uniform> shadow_light: ShadowLight;

fn project(sl: ShadowLight, p: vec3<f32>) -> MapPoint {
    return map_point(header_layer(sl.map, p), p);
}

// Distance along the map's axis for a [0, 1] depth value.
fn linear_depth(sl: ShadowLight, d: f32) -> f32 {
    let near = sl.map.near;
    let far = sl.map.far;
    if sl.map.perspective == 1u {
        return near * far / (far - d * (far - near));
    }
    return near + d * (far - near);
}

// Unit direction light rays travel at p.
fn ray_direction(sl: ShadowLight, p: vec3<f32>) -> vec3<f32> {
    let light = lights[sl.map.light];
    if sl.map.perspective == 1u {
        return normalize(p - light.position);
    }
    return light.direction;
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
    let sl = shadow_light;
    looked_up = sl;
    let receiver = map_receiver(sl.map, in.position.xy);
    let texel = receiver.texel;
    let p = receiver.lookup;
    let frame = tangent_frame(ray_direction(sl, p));
    let r = rotation(in.position.xy);
    var out: Outputs;
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
            let light = PcssLight(sl.light_size, sl.map.near, sl.map.perspective == 1u, sl.search_texels);
            visibility = pcss(p, frame, texel, r, light);
        }
    }
    out.visibility = vec4<f32>(visibility);
    out.diagnostics = vec4<f32>(0.0);
    let position = receiver.surface.position;
    if sl.debug == 1u {
        let m = project(sl, position);
        if m.inside {
            let difference = linear_depth(sl, m.depth) - linear_depth(sl, stored_map_depth(m));
            out.diagnostics = vec4<f32>(1.0, difference / texel, 0.0, 1.0);
        }
    }
    return out;
}
