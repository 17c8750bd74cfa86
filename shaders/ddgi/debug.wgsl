// ddgi's debug views: every probe's irradiance and distance maps as tiles in rows of
// `grid.tiles_per_row` (probe order: x fastest, then y, then z), each probe's state as one
// texel, and what probe `grid.debug_probe`'s rays met this frame as an octahedral image.

#import "ddgi/probes.wgsl"

@group(2) @binding(5) var debug_out: texture_storage_2d<rgba16float, write>;

// Off probes' tiles are tinted by this.
const OFF_TINT: vec3<f32> = vec3<f32>(1.0, 0.2, 0.2);

// The probe whose tile of side `side` holds `texel`, the texel in the tile, and 1 where there
// is such a probe (0 past the rows' ends and the last probe).
fn tile_of(texel: vec2<u32>, side: u32) -> vec3<u32> {
    let tile = texel / side;
    let probe = tile.y * grid.tiles_per_row + tile.x;
    let at = texel % side;
    let valid = tile.x < grid.tiles_per_row && probe < probe_count();
    return vec3<u32>(probe, at.y * side + at.x, u32(valid));
}

@compute @workgroup_size(8, 8, 1)
fn cs_irradiance_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    let tile = tile_of(id.xy, IRRADIANCE_TEXELS + 2u);
    if tile.z == 0u {
        return;
    }
    var c = ddgi[irradiance_index(tile.x, tile.y)].rgb;
    if !probe_active(tile.x) {
        c = OFF_TINT * 0.25;
    }
    textureStore(debug_out, id.xy, vec4<f32>(c, 1.0));
}

// The mean distance over the clamp (white: as far as is kept).
@compute @workgroup_size(8, 8, 1)
fn cs_distance_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    let tile = tile_of(id.xy, DISTANCE_TEXELS + 2u);
    if tile.z == 0u {
        return;
    }
    let mean = ddgi[distance_index(tile.x, tile.y)].x / grid.max_distance;
    var c = vec3<f32>(mean);
    if !probe_active(tile.x) {
        c *= OFF_TINT;
    }
    textureStore(debug_out, id.xy, vec4<f32>(c, 1.0));
}

// Green: active at home; yellow: active, moved; red: off.
@compute @workgroup_size(8, 8, 1)
fn cs_states(@builtin(global_invocation_id) id: vec3<u32>) {
    let tile = tile_of(id.xy, 1u);
    if tile.z == 0u {
        return;
    }
    let moved = any(ddgi[tile.x].xyz != vec3<f32>(0.0));
    var c = select(vec3<f32>(0.1, 0.8, 0.2), vec3<f32>(0.9, 0.8, 0.1), moved);
    if !probe_active(tile.x) {
        c = OFF_TINT;
    }
    textureStore(debug_out, id.xy, vec4<f32>(c, 1.0));
}

// Each texel shows the light of the ray nearest its direction (black where it met the back of
// a surface: blue).
@compute @workgroup_size(8, 8, 1)
fn cs_rays(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(debug_out);
    let probe = grid.debug_probe;
    if any(id.xy >= size) || probe >= probe_count() {
        return;
    }
    let dir = oct_decode((vec2<f32>(id.xy) + 0.5) / vec2<f32>(size) * 2.0 - 1.0);
    var best = 0u;
    var closest = -2.0;
    for (var ray = 0u; ray < grid.rays; ray++) {
        let c = dot(dir, ray_direction(ray, grid.rays));
        if c > closest {
            closest = c;
            best = ray;
        }
    }
    let hit = ddgi[ray_index(probe, best)];
    let c = select(hit.rgb, vec3<f32>(0.1, 0.1, 0.6), hit.w < 0.0);
    textureStore(debug_out, id.xy, vec4<f32>(c, 1.0));
}
