// Virtual shadow maps, the page bookkeeping of a frame, all on the GPU (nothing read back):
// 1. `cs_invalidate`: the pages of layers that moved (a light that moved or turned) are
//    freed, and of a clipmap level that scrolled with the camera, those that left its window;
// 2. `cs_mark`: every pixel marks the page each light needs there, and its light's fallback
//    level's page too;
// 3. `cs_age`: needed pages already resident are kept (their last use is this frame);
// 4. `cs_gather`: physical pages are listed as candidates, free ones first, then the pages no
//    pixel needs, least recently used first (in buckets of age);
// 5. `cs_allocate_fallback`, then `cs_allocate_finer`: every needed page without one takes
//    the next candidate (evicting its owner), fallback levels first, so a full pool leaves a
//    pixel a coarser page, never none; the pages taken are listed to be drawn;
// 6. `cs_draw_args`: the indirect arguments of the clear and caster draws (the casters'
//    instances counted by `cull.wgsl`, which runs next);
// 7. `cs_count_fallback` (after the draws): the pixels whose wanted page found no room.

#import "virtual-maps/tables.wgsl"
#import "common/gbuffer.wgsl"

@group(3) @binding(3) var<storage, read_write> page_table: array<u32>;
// Per entry: 1 when a pixel needs its page this frame.
@group(3) @binding(4) var<storage, read_write> needed: array<atomic<u32>>;
// Per physical page: its owning entry (NO_PAGE when free), the last frame it was needed, the
// last frame it was drawn and the last frame it was taken from another entry (the debug views).
@group(3) @binding(5) var<storage, read_write> pool_pages: array<vec4<u32>>;
// CANDIDATE_LISTS lists of candidate pages (`pool_side`² places each), then the entries
// whose pages are drawn this frame.
@group(3) @binding(6) var<storage, read_write> lists: array<u32>;
@group(3) @binding(7) var<storage, read_write> counts: array<atomic<u32>>;
@group(3) @binding(8) var<storage, read> entry_layers: array<u32>;
// The clear draw's arguments, then one caster draw's per run.
@group(3) @binding(9) var<storage, read_write> draw_args: array<u32>;
// Per caster run: its vertex count, first vertex, object count and first instance.
@group(3) @binding(10) var<storage, read> caster_runs: array<vec4<u32>>;

// `counts`: the candidate lists' lengths, then these (`Counts` in the plugin's Rust).
const COUNT_CURSOR: u32 = 5u;
const COUNT_DRAWN: u32 = 6u;
const COUNT_NEEDED: u32 = 7u;
const COUNT_HITS: u32 = 8u;
const COUNT_EVICTED: u32 = 9u;
const COUNT_NO_ROOM: u32 = 10u;
const COUNT_FALLBACK_PIXELS: u32 = 11u;
const COUNT_RESIDENT_BEFORE: u32 = 12u;
const COUNTS: u32 = 16u;

fn pool_pages_count() -> u32 {
    return virtual_frame.pool_side * virtual_frame.pool_side;
}

@compute @workgroup_size(64)
fn cs_invalidate(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = item(id, groups);
    if e >= arrayLength(&entry_layers) {
        return;
    }
    let l = virtual_layers[entry_layers[e]];
    let page = page_table[e];
    if page == NO_PAGE || l.invalidate == INVALIDATE_NONE {
        return;
    }
    if l.invalidate == INVALIDATE_SCROLLED {
        // The grid page the entry held in the last window stays if the new window holds it.
        let n = i32(l.pages);
        let last = l.origin - l.scrolled;
        let held = last + vec2<i32>(window_page_at(l, e, last));
        if all(held >= l.origin) && all(held < l.origin + n) {
            return;
        }
    }
    pool_pages[page].x = NO_PAGE;
    page_table[e] = NO_PAGE;
}

// The page of a window at `origin` over layer `l`'s grid that entry `e` holds.
fn window_page_at(l: VirtualLayer, e: u32, origin: vec2<i32>) -> vec2<u32> {
    var at = l;
    at.origin = origin;
    return window_page(at, e);
}

fn mark(found: PagePoint) {
    if found.found {
        atomicStore(&needed[found.entry], 1u);
    }
}

@compute @workgroup_size(8, 8)
fn cs_mark(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    if any(id.xy >= vec2<u32>(camera.size)) {
        return;
    }
    let s = load_surface(pixel);
    if !s.valid {
        return;
    }
    let footprint = pixel_footprint(s.position);
    for (var light = 0u; light < virtual_frame.light_count; light++) {
        if !in_range(light, s.position) {
            continue;
        }
        let level = wanted_level(light, s.position, footprint);
        let found = find_page(light, s.position, s.normal, level);
        mark(found);
        mark(find_page(light, s.position, s.normal, virtual_lights[light].fallback_level));
        if found.found {
            mark_reach(light, found.level, s.position, s.normal);
        }
    }
}

// Marks the pages the filter's taps can read around the pixel's lookup point: every page of
// the layer between those under the corners of the square of the filter's reach (at most a
// page: 2x2 pages), or, where the corners fall in other cube faces, each corner's page.
fn mark_reach(light: u32, level: u32, p: vec3<f32>, n: vec3<f32>) {
    let texel = texel_size(light, level, p);
    let towards = towards_light(light, p);
    let q = p + towards * (offset_texels(light, p, n) * texel);
    let frame = tangent_frame(-towards);
    let reach = virtual_frame.reach_texels * texel;
    let v = virtual_lights[light];
    var corners: array<PagePoint, 4>;
    var same = true;
    for (var corner = 0u; corner < 4u; corner++) {
        let sign = vec2<f32>(f32(corner & 1u), f32(corner >> 1u)) * 2.0 - 1.0;
        let c = q + (frame[0] * sign.x + frame[1] * sign.y) * reach;
        var face = 0u;
        if v.faces == 6u {
            face = cube_face(c - lights[light].position);
        }
        corners[corner] = page_point(layer_of(light, face, level), c);
        mark(corners[corner]);
        same = same && corners[corner].found && corners[corner].layer == corners[0].layer;
    }
    if !same {
        return;
    }
    // The page range the corners span (a square turned against the map's axes reaches into
    // pages no corner lies in).
    let l = virtual_layers[corners[0].layer];
    var lo = vec2<u32>(l.pages);
    var hi = vec2<u32>(0u);
    for (var corner = 0u; corner < 4u; corner++) {
        lo = min(lo, corners[corner].page);
        hi = max(hi, corners[corner].page);
    }
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            atomicStore(&needed[layer_entry(l, vec2<u32>(x, y))], 1u);
        }
    }
}

@compute @workgroup_size(64)
fn cs_age(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = item(id, groups);
    if e >= arrayLength(&entry_layers) || atomicLoad(&needed[e]) == 0u {
        return;
    }
    atomicAdd(&counts[COUNT_NEEDED], 1u);
    let page = page_table[e];
    if page != NO_PAGE {
        pool_pages[page].y = virtual_frame.frame;
        atomicAdd(&counts[COUNT_HITS], 1u);
    }
}

@compute @workgroup_size(64)
fn cs_gather(@builtin(global_invocation_id) id: vec3<u32>) {
    let page = id.x;
    if page >= pool_pages_count() {
        return;
    }
    let state = pool_pages[page];
    var list = 0u;
    if state.x != NO_PAGE {
        atomicAdd(&counts[COUNT_RESIDENT_BEFORE], 1u);
        let age = virtual_frame.frame - state.y;
        if age == 0u {
            return;
        }
        list = select(select(select(4u, 3u, age >= 4u), 2u, age >= 16u), 1u, age >= 64u);
    }
    let slot = atomicAdd(&counts[list], 1u);
    lists[list * pool_pages_count() + slot] = page;
}

// The `k`-th candidate over the lists in order, or NO_PAGE past the last.
fn candidate(k: u32) -> u32 {
    var rest = k;
    for (var list = 0u; list < CANDIDATE_LISTS; list++) {
        let length = atomicLoad(&counts[list]);
        if rest < length {
            return lists[list * pool_pages_count() + rest];
        }
        rest -= length;
    }
    return NO_PAGE;
}

// Whether entry `e` is of its light's fallback level.
fn of_fallback_level(e: u32) -> bool {
    let layer = virtual_layers[entry_layers[e]];
    return layer.level == virtual_lights[layer.light].fallback_level;
}

fn allocate(e: u32, fallback: bool) {
    if e >= arrayLength(&entry_layers) || of_fallback_level(e) != fallback {
        return;
    }
    if atomicLoad(&needed[e]) == 0u || page_table[e] != NO_PAGE {
        return;
    }
    let page = candidate(atomicAdd(&counts[COUNT_CURSOR], 1u));
    if page == NO_PAGE {
        atomicAdd(&counts[COUNT_NO_ROOM], 1u);
        return;
    }
    // The owner is needed by no pixel this frame (or it would not be a candidate).
    let owner = pool_pages[page].x;
    if owner != NO_PAGE {
        page_table[owner] = NO_PAGE;
        atomicAdd(&counts[COUNT_EVICTED], 1u);
    }
    let frame = virtual_frame.frame;
    let evicted = select(pool_pages[page].w, frame, owner != NO_PAGE);
    pool_pages[page] = vec4<u32>(e, frame, frame, evicted);
    page_table[e] = page;
    let drawn = atomicAdd(&counts[COUNT_DRAWN], 1u);
    lists[drawn_place(drawn)] = e;
}

@compute @workgroup_size(64)
fn cs_allocate_fallback(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    allocate(item(id, groups), true);
}

@compute @workgroup_size(64)
fn cs_allocate_finer(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    allocate(item(id, groups), false);
}

@compute @workgroup_size(1)
fn cs_draw_args() {
    let drawn = atomicLoad(&counts[COUNT_DRAWN]);
    // Six vertices clear each drawn page.
    draw_args[0] = 6u;
    draw_args[1] = drawn;
    draw_args[2] = 0u;
    draw_args[3] = 0u;
    for (var run = 0u; run < arrayLength(&caster_runs); run++) {
        let r = caster_runs[run];
        let at = 4u * (run + 1u);
        draw_args[at] = r.x;
        // Counted by the culling of casters per page.
        draw_args[at + 1u] = 0u;
        draw_args[at + 2u] = r.y;
        draw_args[at + 3u] = 0u;
    }
}

@compute @workgroup_size(8, 8)
fn cs_count_fallback(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= vec2<u32>(camera.size)) {
        return;
    }
    let s = load_surface(vec2<i32>(id.xy));
    if !s.valid {
        return;
    }
    let footprint = pixel_footprint(s.position);
    for (var light = 0u; light < virtual_frame.light_count; light++) {
        if !in_range(light, s.position) {
            continue;
        }
        let found = find_page(light, s.position, s.normal, wanted_level(light, s.position, footprint));
        if found.found && page_table[found.entry] == NO_PAGE {
            atomicAdd(&counts[COUNT_FALLBACK_PIXELS], 1u);
        }
    }
}
