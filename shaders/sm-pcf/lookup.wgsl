// Shadow-map lookup: one full-screen pass per light writes that light's visibility.
// Filter taps are placed in world space, perpendicular to the light direction, and each tap is
// projected by itself (for point lights into whichever cube face it falls in), so filtering is
// seamless across cube faces.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/fullscreen.wgsl"

const FILTER_NONE: u32 = 0u;
const FILTER_HARDWARE_2X2: u32 = 1u;
const FILTER_PCF_3X3: u32 = 2u;
const FILTER_PCF_5X5: u32 = 3u;
const FILTER_PCF_7X7: u32 = 4u;
const FILTER_PCF_9X9: u32 = 5u;
const FILTER_POISSON: u32 = 6u;
const FILTER_PCSS: u32 = 7u;

// One layer's camera, in a 256-byte slot (shared with the depth pass's dynamic uniform).
struct Slot {
    view_proj: mat4x4<f32>,
    _pad: array<vec4<f32>, 12>,
}

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
    map_size: f32,
    position: vec3<f32>,
    search_texels: f32,
    direction: vec3<f32>,
    _pad: f32,
}

struct Current {
    index: u32,
    // 1 when this light's diagnostics are written.
    debug: u32,
    _pad: vec2<u32>,
}

@group(2) @binding(0) var shadow_maps: texture_depth_2d_array;
@group(2) @binding(1) var compare_linear: sampler_comparison;
@group(2) @binding(2) var compare_nearest: sampler_comparison;
@group(2) @binding(3) var<storage, read> slots: array<Slot>;
@group(2) @binding(4) var<storage, read> shadow_lights: array<ShadowLight>;
@group(2) @binding(5) var<uniform> current: Current;
// The maps again as plain floats: GLSL cannot fetch texels of depth textures.
@group(2) @binding(6) var shadow_depths: texture_2d_array<f32>;
// And once more for the nearest comparison sampler: GLSL pairs each texture with one sampler.
@group(2) @binding(7) var shadow_maps_nearest: texture_depth_2d_array;

// Poisson disc, 16 points in the unit disk, minimum spacing 0.423.
const POISSON_16: array<vec2<f32>, 16> = array<vec2<f32>, 16>(
    vec2<f32>(0.0118, -0.1794),
    vec2<f32>(-0.8401, -0.1568),
    vec2<f32>(-0.0068, 0.3801),
    vec2<f32>(0.4789, 0.3546),
    vec2<f32>(0.8432, -0.1561),
    vec2<f32>(0.6935, -0.7197),
    vec2<f32>(0.1784, -0.9475),
    vec2<f32>(-0.6969, -0.5744),
    vec2<f32>(0.2624, 0.7274),
    vec2<f32>(-0.6019, 0.7281),
    vec2<f32>(-0.6308, 0.2454),
    vec2<f32>(0.2945, -0.4959),
    vec2<f32>(-0.2507, -0.8731),
    vec2<f32>(-0.1435, 0.9813),
    vec2<f32>(0.8964, 0.4394),
    vec2<f32>(-0.4136, -0.1654),
);

// Poisson disc, 32 points in the unit disk, minimum spacing 0.282.
const POISSON_32: array<vec2<f32>, 32> = array<vec2<f32>, 32>(
    vec2<f32>(-0.6682, -0.6513),
    vec2<f32>(0.4346, 0.9006),
    vec2<f32>(-0.2654, -0.2610),
    vec2<f32>(-0.1212, 0.9853),
    vec2<f32>(-0.5647, 0.0362),
    vec2<f32>(0.8074, -0.2949),
    vec2<f32>(-0.2463, -0.9410),
    vec2<f32>(0.1881, 0.3581),
    vec2<f32>(-0.6987, -0.2835),
    vec2<f32>(-0.3201, 0.6051),
    vec2<f32>(-0.7995, 0.5465),
    vec2<f32>(0.4193, -0.5893),
    vec2<f32>(-0.0013, -0.7142),
    vec2<f32>(0.0254, -0.2954),
    vec2<f32>(-0.9079, 0.1392),
    vec2<f32>(0.5672, 0.5483),
    vec2<f32>(-0.0402, 0.1679),
    vec2<f32>(0.5645, 0.1509),
    vec2<f32>(0.8734, 0.4058),
    vec2<f32>(0.2160, 0.0168),
    vec2<f32>(-0.3108, -0.5523),
    vec2<f32>(0.7254, -0.6554),
    vec2<f32>(0.0343, 0.7370),
    vec2<f32>(0.9795, 0.1444),
    vec2<f32>(0.2523, -0.8969),
    vec2<f32>(-0.5561, 0.3951),
    vec2<f32>(0.3312, -0.3040),
    vec2<f32>(-0.5921, 0.7865),
    vec2<f32>(-0.9631, -0.1598),
    vec2<f32>(-0.3184, 0.2193),
    vec2<f32>(0.5695, -0.1380),
    vec2<f32>(-0.0765, 0.4555),
);

struct MapPoint {
    uv: vec2<f32>,
    depth: f32,
    layer: u32,
    inside: bool,
}

fn cube_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}

fn project(sl: ShadowLight, p: vec3<f32>) -> MapPoint {
    var layer = sl.first_layer;
    if sl.layer_count == 6u {
        layer += cube_face(p - sl.position);
    }
    let clip = slots[layer].view_proj * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    var m: MapPoint;
    m.uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    m.depth = ndc.z;
    m.layer = layer;
    m.inside = clip.w > 0.0 && abs(ndc.x) <= 1.0 && abs(ndc.y) <= 1.0 && ndc.z >= 0.0 && ndc.z <= 1.0;
    return m;
}

// One comparison tap: 1 = lit. Points outside the map are lit.
fn tap(sl: ShadowLight, p: vec3<f32>, linear: bool) -> f32 {
    let m = project(sl, p);
    if !m.inside {
        return 1.0;
    }
    if linear {
        return textureSampleCompareLevel(shadow_maps, compare_linear, m.uv, m.layer, m.depth);
    }
    return textureSampleCompareLevel(shadow_maps_nearest, compare_nearest, m.uv, m.layer, m.depth);
}

// Distance along the map's axis for a [0, 1] depth value.
fn linear_depth(sl: ShadowLight, d: f32) -> f32 {
    if sl.perspective == 1u {
        return sl.near * sl.far / (sl.far - d * (sl.far - sl.near));
    }
    return sl.near + d * (sl.far - sl.near);
}

fn stored_depth(m: MapPoint) -> f32 {
    let size = vec2<i32>(textureDimensions(shadow_maps));
    let texel = clamp(vec2<i32>(m.uv * vec2<f32>(size)), vec2<i32>(0), size - vec2<i32>(1));
    return textureLoad(shadow_depths, texel, m.layer, 0).r;
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

fn interleaved_gradient_noise(pixel: vec2<f32>) -> f32 {
    return fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
}

fn rotation(pixel: vec2<f32>) -> mat2x2<f32> {
    let angle = 6.2831853 * interleaved_gradient_noise(pixel);
    let c = cos(angle);
    let s = sin(angle);
    return mat2x2<f32>(c, s, -s, c);
}

fn grid_pcf(sl: ShadowLight, p: vec3<f32>, u: vec3<f32>, v: vec3<f32>, texel: f32, n: i32) -> f32 {
    var sum = 0.0;
    let h = n / 2;
    for (var j = -h; j <= h; j++) {
        for (var i = -h; i <= h; i++) {
            sum += tap(sl, p + (u * f32(i) + v * f32(j)) * texel, true);
        }
    }
    return sum / f32(n * n);
}

fn poisson_pcf(sl: ShadowLight, p: vec3<f32>, u: vec3<f32>, v: vec3<f32>, radius: f32, r: mat2x2<f32>) -> f32 {
    var sum = 0.0;
    for (var k = 0u; k < 32u; k++) {
        let o = r * POISSON_32[k] * radius;
        sum += tap(sl, p + u * o.x + v * o.y, true);
    }
    return sum / 32.0;
}

// Percentage-closer soft shadows: average blocker distance, then a kernel sized by the
// penumbra the light's size gives at that blocker distance.
fn pcss(sl: ShadowLight, p: vec3<f32>, u: vec3<f32>, v: vec3<f32>, texel: f32, r: mat2x2<f32>) -> f32 {
    let center = project(sl, p);
    if !center.inside {
        return 1.0;
    }
    let receiver = linear_depth(sl, center.depth);
    var search = sl.light_size * (receiver - sl.near);
    if sl.perspective == 1u {
        search /= max(sl.near, 1e-4);
    }
    search = clamp(search, texel, sl.search_texels * texel);
    var blockers = 0.0;
    var blocker_sum = 0.0;
    for (var k = 0u; k < 16u; k++) {
        let o = r * POISSON_16[k] * search;
        let m = project(sl, p + u * o.x + v * o.y);
        if m.inside {
            let stored = stored_depth(m);
            if stored < m.depth {
                blockers += 1.0;
                blocker_sum += linear_depth(sl, stored);
            }
        }
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let blocker = blocker_sum / blockers;
    var penumbra = sl.light_size * (receiver - blocker);
    if sl.perspective == 1u {
        penumbra /= max(blocker, 1e-4);
    }
    return poisson_pcf(sl, p, u, v, clamp(penumbra, texel, sl.search_texels * texel), r);
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
    let sl = shadow_lights[current.index];
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
    let w = ray_direction(sl, p);
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(w.x) > 0.9);
    let u = normalize(cross(w, helper));
    let v = cross(w, u);
    let r = rotation(in.position.xy);
    var visibility = 1.0;
    switch sl.filter_mode {
        case FILTER_NONE: { visibility = tap(sl, p, false); }
        case FILTER_HARDWARE_2X2: { visibility = tap(sl, p, true); }
        case FILTER_PCF_3X3: { visibility = grid_pcf(sl, p, u, v, texel, 3); }
        case FILTER_PCF_5X5: { visibility = grid_pcf(sl, p, u, v, texel, 5); }
        case FILTER_PCF_7X7: { visibility = grid_pcf(sl, p, u, v, texel, 7); }
        case FILTER_PCF_9X9: { visibility = grid_pcf(sl, p, u, v, texel, 9); }
        case FILTER_POISSON: { visibility = poisson_pcf(sl, p, u, v, sl.kernel_texels * texel, r); }
        default: { visibility = pcss(sl, p, u, v, texel, r); }
    }
    out.visibility = vec4<f32>(visibility);
    if current.debug == 1u {
        let m = project(sl, s.position);
        if m.inside {
            let difference = linear_depth(sl, m.depth) - linear_depth(sl, stored_depth(m));
            out.diagnostics = vec4<f32>(1.0, difference / texel, 0.0, 1.0);
        }
    }
    return out;
}
