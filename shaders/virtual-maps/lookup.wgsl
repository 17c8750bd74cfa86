// Virtual shadow maps, the lookup of one light: each pixel finds the level it needs (the same
// choice as `cs_mark`), or the first coarser level resident there when the pool had no room,
// and filters its depth through the shadow-map library's filters (`shadow-maps/filters.wgsl`:
// PCF grids, Poisson discs, PCSS), whose every tap finds its own page through the page table
// at that level (or a coarser one where its page is not resident): filters cross pages.

#import "common/fullscreen.wgsl"
#import "common/gbuffer.wgsl"
#import "virtual-maps/tables.wgsl"
#import "virtual-maps/virtual_lookup.wgsl"
#import "shadow-maps/filters.wgsl"

@group(2) @binding(0) var<uniform> virtual_lookup: VirtualLookup;
@group(3) @binding(3) var<storage, read> page_table: array<u32>;
// The pool three times over: GLSL pairs each texture with one sampler and cannot read texels
// of depth textures.
@group(3) @binding(4) var pool: texture_depth_2d;
@group(3) @binding(5) var pool_linear: sampler_comparison;
@group(3) @binding(6) var pool_nearest: texture_depth_2d;
@group(3) @binding(7) var pool_compare: sampler_comparison;
@group(3) @binding(8) var pool_values: texture_2d<f32>;

// The light and level the current pixel's taps read.
var<private> tap_light: u32;
var<private> tap_level: u32;

// A world point's place in a resident page: at `tap_level`, or the first coarser level whose
// page is resident.
struct Resident {
    found: bool,
    at: PagePoint,
    page: u32,
}

fn resident(p: vec3<f32>) -> Resident {
    var out: Resident;
    let v = virtual_lights[tap_light];
    var face = 0u;
    if v.faces == 6u {
        face = cube_face(p - lights[tap_light].position);
    }
    for (var k = tap_level; k <= v.fallback_level; k++) {
        let at = page_point(layer_of(tap_light, face, k), p);
        if at.found {
            let page = page_table[at.entry];
            if page != NO_PAGE {
                out.found = true;
                out.at = at;
                out.page = page;
                return out;
            }
        }
    }
    return out;
}

// The pool coordinates of a resident point.
fn pool_uv(r: Resident) -> vec2<f32> {
    let corner = vec2<f32>(slot_origin(r.page) + virtual_frame.gutter);
    let texel = corner + r.at.local * f32(virtual_frame.page_size);
    return texel / f32(virtual_frame.pool_texels);
}

fn shadow_tap(p: vec3<f32>, linear: bool) -> f32 {
    let r = resident(p);
    if !r.found {
        return 1.0;
    }
    if linear {
        return textureSampleCompareLevel(pool, pool_linear, pool_uv(r), r.at.depth);
    }
    return textureSampleCompareLevel(pool_nearest, pool_compare, pool_uv(r), r.at.depth);
}

// A depth of the light's layers along its axis.
fn linear_depth(d: f32) -> f32 {
    let v = virtual_lights[tap_light];
    if v.clipmap == 0u {
        return v.near * v.far / (v.far - d * (v.far - v.near));
    }
    return v.near + d * (v.far - v.near);
}

fn shadow_depths(p: vec3<f32>) -> vec3<f32> {
    let r = resident(p);
    if !r.found {
        return vec3<f32>(0.0);
    }
    let texel = vec2<i32>(pool_uv(r) * f32(virtual_frame.pool_texels));
    let stored = textureLoad(pool_values, texel, 0).r;
    return vec3<f32>(1.0, linear_depth(r.at.depth), linear_depth(stored));
}

@fragment
fn fs_lookup(in: FullscreenOut) -> @location(0) vec4<f32> {
    let light = virtual_lookup.light;
    let s = load_surface(vec2<i32>(in.position.xy));
    if !s.valid || !in_range(light, s.position) {
        return vec4<f32>(1.0);
    }
    let wanted = wanted_level(light, s.position, pixel_footprint(s.position));
    let found = find_page(light, s.position, s.normal, wanted);
    if !found.found {
        return vec4<f32>(1.0);
    }
    // The level of the page read: the wanted one, or the first coarser one resident.
    tap_light = light;
    tap_level = found.level;
    let towards = towards_light(light, s.position) * offset_texels(light, s.position, s.normal);
    var lookup = s.position + towards * texel_size(light, found.level, s.position);
    let first = resident(lookup);
    if !first.found {
        return vec4<f32>(1.0);
    }
    // A coarser page read in its place: the offset in its texels (along the light's ray, so
    // the same page).
    tap_level = first.at.level;
    lookup = s.position + towards * texel_size(light, tap_level, s.position);
    let l = lights[light];
    let parallel = l.kind == LIGHT_DIRECTIONAL;
    let ray = select(normalize(lookup - l.position), l.direction, parallel);
    let plane = TapPlane(lookup, s.normal, select(l.position, l.direction, parallel), parallel);
    let texel = texel_size(light, tap_level, s.position);
    let noise = filter_noise(in.position.xy, camera.frame);
    let v = virtual_lights[light];
    let visibility = filter_map(v.map_filter, plane, tangent_frame(ray), texel, noise, v.near, !parallel);
    return vec4<f32>(visibility);
}
