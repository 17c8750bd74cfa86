// Virtual shadow maps, the lookup of one light: each pixel finds the page it needs (the same
// choice as `cs_mark`), or the first coarser page resident when the pool had no room, and
// compares its depth with the page's texels, (2r + 1)² of them for PCF radius r (inside the
// page and its gutter).

#import "common/fullscreen.wgsl"
#import "common/gbuffer.wgsl"
#import "virtual-maps/tables.wgsl"
#import "virtual-maps/virtual_lookup.wgsl"

@group(2) @binding(0) var<uniform> virtual_lookup: VirtualLookup;
@group(4) @binding(0) var<storage, read> page_table: array<u32>;
@group(4) @binding(1) var pool: texture_depth_2d;
// Nearest, `LessEqual`: 1 where the receiver is no deeper than the stored depth.
@group(4) @binding(2) var pool_compare: sampler_comparison;

// The fraction of the (2r + 1)² texels around `found` that do not occlude it.
fn pcf(found: PagePoint, page: u32) -> f32 {
    let size = f32(virtual_frame.page_size);
    let corner = vec2<i32>(slot_origin(page) + virtual_frame.gutter);
    let centre = corner + vec2<i32>(floor(found.local * size));
    let r = i32(virtual_frame.pcf_radius);
    let texels = f32(virtual_frame.pool_texels);
    var lit = 0.0;
    for (var j = -r; j <= r; j++) {
        for (var i = -r; i <= r; i++) {
            let uv = (vec2<f32>(centre + vec2<i32>(i, j)) + 0.5) / texels;
            lit += textureSampleCompareLevel(pool, pool_compare, uv, found.depth);
        }
    }
    let taps = f32((2 * r + 1) * (2 * r + 1));
    return lit / taps;
}

@fragment
fn fs_lookup(in: FullscreenOut) -> @location(0) vec4<f32> {
    let light = virtual_lookup.light;
    let s = load_surface(vec2<i32>(in.position.xy));
    if !s.valid || !in_range(light, s.position) {
        return vec4<f32>(1.0);
    }
    let fallback = virtual_lights[light].fallback_level;
    var level = wanted_level(light, s.position, pixel_footprint(s.position));
    loop {
        let found = find_page(light, s.position, s.normal, level);
        if !found.found {
            return vec4<f32>(1.0);
        }
        let page = page_table[found.entry];
        if page != NO_PAGE {
            return vec4<f32>(pcf(found, page));
        }
        if found.level >= fallback {
            return vec4<f32>(1.0);
        }
        level = found.level + 1u;
    }
    return vec4<f32>(1.0);
}
