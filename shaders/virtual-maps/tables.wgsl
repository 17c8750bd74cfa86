// Virtual shadow maps: the frame's settings, every light's layers and the choice of a layer
// and page for a surface point, shared by marking, drawing and lookups
// (`plugins/virtual-maps/src/layers.rs` lays the layers out).
//
// A light's layers: `faces` x `levels`, face by face, finest level first. A directional
// light's levels are clipmap levels, each twice the size of the one before; a spot or point
// light's are mip levels of its face (level k: `pages` >> k pages a side). The page table
// holds one entry per page of every layer.

#import "common/frame.wgsl"
#import "shadow-maps/layers.wgsl"
#import "virtual-maps/virtual_frame.wgsl"
#import "virtual-maps/virtual_layer.wgsl"
#import "virtual-maps/virtual_light.wgsl"

// Group 3 holds the tables at bindings 0 to 2 and each pass's own bindings from 3 on (WebGPU
// gives a pipeline four groups: frame, G-buffer or materials, a per-light or per-run slot, and
// this one).
@group(3) @binding(0) var<uniform> virtual_frame: VirtualFrame;
@group(3) @binding(1) var<storage, read> virtual_layers: array<VirtualLayer>;
@group(3) @binding(2) var<storage, read> virtual_lights: array<VirtualLight>;

// A page-table entry or physical page that holds nothing.
const NO_PAGE: u32 = 0xffffffffu;

// Which pages of a layer a frame frees first (`Invalidate` in the plugin's Rust): none, every
// one (the layer moved), or those that left its window (a clipmap level that scrolled).
const INVALIDATE_NONE: u32 = 0u;
const INVALIDATE_ALL: u32 = 1u;
const INVALIDATE_SCROLLED: u32 = 2u;

// Candidate lists of the allocation: free pages, then pages unused for at least 64, 16, 4
// and 1 frames (`pool_side`² places each); the entries drawn this frame follow them.
const CANDIDATE_LISTS: u32 = 5u;

// Where the page lists keep the `slot`-th entry drawn this frame.
fn drawn_place(slot: u32) -> u32 {
    return CANDIDATE_LISTS * virtual_frame.pool_side * virtual_frame.pool_side + slot;
}

// The item of a 64-wide invocation of a dispatch spread over rows of workgroups (more than a
// dispatch takes along one axis: `spread` in the plugin's Rust).
fn item(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * 64u;
}

// Where a point falls in one layer.
struct PagePoint {
    // False outside the layer (beside it, nearer than its near plane or past its far one).
    found: bool,
    layer: u32,
    level: u32,
    // Its page in the layer's window, that page's page-table entry, and the point's position
    // in the page in [0, 1).
    page: vec2<u32>,
    entry: u32,
    local: vec2<f32>,
    // Its depth in the layer.
    depth: f32,
}

// The layer of `light`'s face `face` at level `level`.
fn layer_of(light: u32, face: u32, level: u32) -> u32 {
    let v = virtual_lights[light];
    return v.first_layer + face * v.levels + level;
}

// `v` modulo `n`, in [0, n).
fn wrap(v: vec2<i32>, n: i32) -> vec2<i32> {
    return ((v % n) + n) % n;
}

// The page-table entry of page `page` of layer `l`'s window. A layer's entries hold the pages
// of its endless page grid modulo its size: a clipmap level whose window scrolls (its `origin`)
// keeps the entries of the pages still inside it.
fn layer_entry(l: VirtualLayer, page: vec2<u32>) -> u32 {
    let at = wrap(vec2<i32>(page) + l.origin, i32(l.pages));
    return l.first_entry + u32(at.y) * l.pages + u32(at.x);
}

// The page of layer `l`'s window that entry `entry` holds.
fn window_page(l: VirtualLayer, entry: u32) -> vec2<u32> {
    let index = entry - l.first_entry;
    let at = vec2<i32>(vec2<u32>(index % l.pages, index / l.pages));
    return vec2<u32>(wrap(at - l.origin, i32(l.pages)));
}

// Where `p` falls in layer `layer`.
fn page_point(layer: u32, p: vec3<f32>) -> PagePoint {
    var out: PagePoint;
    let l = virtual_layers[layer];
    let clip = l.view_proj * vec4<f32>(p, 1.0);
    if clip.w <= 0.0 {
        return out;
    }
    let ndc = clip.xyz / clip.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0)) || ndc.z < 0.0 || ndc.z > 1.0 {
        return out;
    }
    let pages = f32(l.pages);
    let page = min(vec2<u32>(uv * pages), vec2<u32>(l.pages - 1u));
    out.found = true;
    out.layer = layer;
    out.level = l.level;
    out.page = page;
    out.entry = layer_entry(l, page);
    out.local = uv * pages - vec2<f32>(page);
    out.depth = ndc.z;
    return out;
}

// World size of a texel of `light`'s level `level` at `p`.
fn texel_size(light: u32, level: u32, p: vec3<f32>) -> f32 {
    let v = virtual_lights[light];
    var size = v.first_texel * exp2(f32(level));
    if v.clipmap == 0u {
        size *= distance(p, lights[light].position);
    }
    return size;
}

// The finest level of `light` whose texels at `p` are no smaller than `footprint` (the world
// size of the pixel there) times the level bias.
fn wanted_level(light: u32, p: vec3<f32>, footprint: f32) -> u32 {
    let v = virtual_lights[light];
    let ratio = footprint * virtual_frame.level_bias / max(texel_size(light, 0u, p), 1e-30);
    let level = ceil(log2(max(ratio, 1.0)));
    return u32(min(level, f32(v.fallback_level)));
}

// The direction from `p` towards `light`.
fn towards_light(light: u32, p: vec3<f32>) -> vec3<f32> {
    let l = lights[light];
    if l.kind == LIGHT_DIRECTIONAL {
        return -l.direction;
    }
    return normalize(l.position - p);
}

// How far towards the light a receiver's lookup moves, in texels of the level it reads: half a
// texel, and the depth its surface spans across one texel (tan of the light's incidence,
// at most 32), times the normal offset. Moving along the light's ray leaves the point's place in
// the map where it was, so the shadow does not shift, only its depth is biased.
fn offset_texels(light: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let c = clamp(dot(n, towards_light(light, p)), 0.02, 1.0);
    let slope = min(sqrt(1.0 - c * c) / c, 32.0);
    return virtual_frame.normal_offset * (0.5 + slope);
}

// The page `light` needs for the surface point `p` (normal `n`) at level `level`, or at the
// first coarser level that holds it: the point moved towards the light by the level's offset
// (`offset_texels`), in the cube face it then lies in. Levels past the light's fallback level
// are not used.
fn find_page(light: u32, p: vec3<f32>, n: vec3<f32>, level: u32) -> PagePoint {
    let v = virtual_lights[light];
    let towards = towards_light(light, p) * offset_texels(light, p, n);
    for (var k = level; k <= v.fallback_level; k++) {
        let q = p + towards * texel_size(light, k, p);
        var face = 0u;
        if v.faces == 6u {
            face = cube_face(q - lights[light].position);
        }
        let found = page_point(layer_of(light, face, k), q);
        if found.found {
            return found;
        }
    }
    return PagePoint();
}

// The world size of the pixel that shows `p`.
fn pixel_footprint(p: vec3<f32>) -> f32 {
    return distance(p, camera.position) * virtual_frame.pixel_angle;
}

// Whether `light` can light `p` at all (within a local light's range).
fn in_range(light: u32, p: vec3<f32>) -> bool {
    let l = lights[light];
    return l.kind == LIGHT_DIRECTIONAL || distance(p, l.position) <= l.range;
}

// The top-left texel of physical page `page` in the pool (its gutter included).
fn slot_origin(page: u32) -> vec2<u32> {
    let side = virtual_frame.pool_side;
    return vec2<u32>(page % side, page / side) * virtual_frame.slot_size;
}
