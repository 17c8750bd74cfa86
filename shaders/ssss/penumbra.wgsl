// Layered penumbra pass (seed 001 §6), all lights in one compute pass: for every pixel and
// every light that reaches it, a hard shadow test against the light's depth map, a blocker
// search for the penumbra width, and the colour of translucent casters in front. Written per
// layer (the light's visibility slot): the blur sigma in pixels (0 = no blur), occlusion and
// tint bits, and the tint colour.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "shadow-maps/filters.wgsl"
#import "shadow-maps/depth_lookup.wgsl"
#import "ssss/data.wgsl"

// Blur sigma per layer, four layers per texel.
@group(2) @binding(1) var penumbra_out: texture_storage_2d_array<rgba16float, write>;
// Occluded bits, 32 layers per texel, then tinted bits (behind translucent casters).
@group(2) @binding(2) var bits_out: texture_storage_2d_array<r32uint, write>;
// Tint colour per layer (rgb), where its tinted bit is set.
@group(2) @binding(3) var tint_out: texture_storage_2d_array<rgba16float, write>;
// Translucent casters per map layer: min transmittance (rgb), nearest depth (a).
@group(2) @binding(4) var translucency: texture_2d_array<f32>;
// Min-filtered depth maps (`ssss/min_depth.wgsl`), for the min-filter estimate.
@group(2) @binding(5) var min_maps: texture_2d_array<f32>;

// The light being looked up, for the filters' map access.
var<private> current: SsssLight;
var<private> current_position: vec3<f32>;
var<private> current_axis: vec3<f32>;

fn project(p: vec3<f32>) -> MapPoint {
    let layer = light_layer(current.first_layer, current.layer_count, current_position, p);
    return map_point(layer, p);
}

// Distance along the map's axis for a [0, 1] depth value.
fn linear_depth(d: f32) -> f32 {
    if current.perspective == 1u {
        return current.near * current.far / (current.far - d * (current.far - current.near));
    }
    return current.near + d * (current.far - current.near);
}

// The translucency map's texel under `m`: min transmittance (rgb), nearest `light_depth` (a).
fn translucency_at(m: MapPoint) -> vec4<f32> {
    return textureLoad(translucency, tile_texel(m.tile, m.uv), m.tile.page, 0);
}

// The nearest translucent caster on the light ray through `p` (which projects to `m`), as a
// distance along the map's axis like `linear_depth`; very far where there is none.
fn translucent_depth(m: MapPoint, p: vec3<f32>) -> f32 {
    if data.settings.translucent == 0u {
        return 1e30;
    }
    let stored = translucency_at(m).a;
    if stored >= 1.0 {
        return 1e30;
    }
    let eye = layer_cameras[m.layer].camera.eye;
    if eye.w > 0.0 {
        // Distance over far along the ray; scaled to the axis like p's own distance.
        return stored / eye.w * linear_depth(m.depth) / max(length(p - eye.xyz), 1e-6);
    }
    return linear_depth(stored);
}

fn shadow_tap(p: vec3<f32>, linear: bool) -> f32 {
    return compare_map(project(p), linear);
}

// (inside, receiver depth, nearest blocker depth: opaque or translucent), along the map axis.
fn shadow_depths(p: vec3<f32>) -> vec3<f32> {
    let m = project(p);
    // Taps in a culled cube face read nothing (no receiver, no blocker).
    let kept = (current.kept_faces >> (m.layer - current.first_layer)) & 1u;
    if !m.inside || kept == 0u {
        return vec3<f32>(0.0);
    }
    let stored = min(linear_depth(stored_map_depth(m)), translucent_depth(m, p));
    return vec3<f32>(1.0, linear_depth(m.depth), stored);
}

// World size of one map texel at p.
fn texel_world(p: vec3<f32>) -> f32 {
    return map_texel_world(current.perspective == 1u, current.layer_count, current.texel_scale, current_position, current_axis, p);
}

// The blocker-search radius in world units for a receiver at `receiver` along the map axis:
// the light's size projected through the near plane (perspective) or along its rays.
fn search_radius(receiver: f32, texel: f32) -> f32 {
    var search = current.size * (receiver - current.near);
    if current.perspective == 1u {
        search /= max(current.near, 1e-30);
    }
    return clamp(search, texel, data.settings.params.search_texels * texel);
}

// The penumbra width for blockers at `blocker` and a receiver at `receiver` (along the map
// axis): w = 2 R (d_r - d_b) / d_b for lights of radius R, 2 tan(theta) (d_r - d_b) for
// directional lights of angular radius theta (PCSS's estimate).
fn width_for(receiver: f32, blocker: f32) -> f32 {
    var width = 2.0 * current.size * (receiver - blocker);
    if current.perspective == 1u {
        width /= max(blocker, 1e-30);
    }
    return width;
}

// Penumbra width by a 16-tap blocker search around p (0: no blocker found), averaging the
// blockers' depths.
fn width_by_search(p: vec3<f32>, receiver: f32, frame: mat2x3<f32>, texel: f32, r: mat2x2<f32>) -> f32 {
    let search = search_radius(receiver, texel);
    var blockers = 0.0;
    var blocker_sum = 0.0;
    for (var k = 0u; k < 16u; k++) {
        let o = r * POISSON_16[k] * search;
        let d = shadow_depths(p + frame[0] * o.x + frame[1] * o.y);
        if d.x > 0.0 && d.z < d.y - texel {
            blockers += 1.0;
            blocker_sum += d.z;
        }
    }
    if blockers == 0.0 {
        return 0.0;
    }
    return width_for(receiver, blocker_sum / blockers);
}

// Penumbra width from the min-filtered maps (0: no blocker near): the nearest depth over the
// min texels covering the search radius around `m` (at most 5 x 5 of them).
fn width_by_min_filter(m: MapPoint, receiver: f32, texel: f32) -> f32 {
    let block = textureDimensions(depth_values).x / textureDimensions(min_maps).x;
    let reach = clamp(i32(ceil(search_radius(receiver, texel) / (texel * f32(block)))), 1, 2);
    // The tile in min texels (tiles are whole blocks).
    var blocks = m.tile;
    blocks.origin /= block;
    blocks.size /= block;
    let center = tile_texel(blocks, m.uv);
    var nearest = 1.0;
    for (var y = -reach; y <= reach; y++) {
        for (var x = -reach; x <= reach; x++) {
            let t = clamp_to_tile(blocks, center + vec2<i32>(x, y));
            nearest = min(nearest, textureLoad(min_maps, t, m.tile.page, 0).r);
        }
    }
    let blocker = linear_depth(nearest);
    if blocker >= receiver - texel {
        return 0.0;
    }
    return width_for(receiver, blocker);
}

// Lights whose screen rectangle meets this workgroup's 8 x 8 tile (tiled light culling). When
// more meet it than the list holds, every light is visited.
const TILE_LIGHTS: u32 = 256u;
var<workgroup> tile_lights: array<u32, TILE_LIGHTS>;
var<workgroup> tile_count: atomic<u32>;

// Lists the shadowed lights whose screen rectangle meets the tile at `origin` (all invocations
// of the workgroup call it). Returns how many, or more than TILE_LIGHTS when they overflow.
fn cull_lights(origin: vec2<u32>, index: u32) -> u32 {
    if index == 0u {
        atomicStore(&tile_count, 0u);
    }
    workgroupBarrier();
    for (var i = index; i < arrayLength(&data.lights); i += 64u) {
        let r = data.lights[i].scissor;
        let meets = r.z > 0u && r.w > 0u && r.x < origin.x + 8u && origin.x < r.x + r.z
            && r.y < origin.y + 8u && origin.y < r.y + r.w;
        if data.lights[i].layer_count != 0u && meets {
            let k = atomicAdd(&tile_count, 1u);
            if k < TILE_LIGHTS {
                tile_lights[k] = i;
            }
        }
    }
    return workgroupUniformLoad(&tile_count);
}

@compute @workgroup_size(8, 8)
fn cs_penumbra(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
    @builtin(workgroup_id) tile: vec3<u32>,
) {
    let listed = cull_lights(tile.xy * 8u, index);
    let visit_all = listed > TILE_LIGHTS;
    let visits = select(listed, arrayLength(&data.lights), visit_all);
    let size = vec2<u32>(camera.size);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let settings = data.settings;
    let groups = (settings.layer_count + 3u) / 4u;
    let words = word_count();
    var sigma: array<vec4<f32>, MAX_GROUPS>;
    var occluded: array<u32, MAX_WORDS>;
    var tinted: array<u32, MAX_WORDS>;
    let s = load_surface(pixel);
    if s.valid {
        let view_depth = bitcast<f32>(textureLoad(gbuffer_view_depth, pixel, 0).r);
        let view_normal = (camera.view * vec4<f32>(s.normal, 0.0)).xyz;
        // Screen pixels per world unit on this surface: distance and the seed's
        // anisotropic factor sqrt(max(n_view.z, clamp)).
        let to_pixels = settings.pixel_scale / view_depth
            * sqrt(max(view_normal.z, settings.params.grazing_clamp));
        let r = rotation(vec2<f32>(pixel));
        for (var k = 0u; k < visits; k++) {
            let i = select(tile_lights[k], k, visit_all);
            let sl = data.lights[i];
            if sl.layer_count == 0u {
                continue;
            }
            let light = lights[i];
            if light_falloff(light, s.position) <= 0.0 {
                continue;
            }
            current = sl;
            current_position = light.position;
            current_axis = light.direction;
            let layer = sl.layer;
            let w = word_of(layer);
            // Surfaces facing away are in the light's self-shadow.
            let l = light_vector(light, s.position);
            if dot(s.normal, l) <= 0.0 {
                occluded[w] |= bit_of(layer);
                continue;
            }
            let texel = texel_world(s.position);
            let p = s.position + s.normal * (settings.params.normal_offset * texel);
            let m = project(p);
            if !m.inside {
                continue;
            }
            // The hard test: a nearest-texel comparison (the depth pass's slope bias is in the
            // stored depth).
            let receiver = linear_depth(m.depth);
            if m.depth > stored_map_depth(m) {
                occluded[w] |= bit_of(layer);
            } else if receiver > translucent_depth(m, p) + 2.0 * texel {
                tinted[w] |= bit_of(layer);
                textureStore(tint_out, pixel, layer, vec4<f32>(translucency_at(m).rgb, 1.0));
            }
            var width = 0.0;
            if settings.params.estimate == ESTIMATE_MINFILTER {
                width = width_by_min_filter(m, receiver, texel);
            } else {
                width = width_by_search(p, receiver, tangent_frame(-l), texel, r);
            }
            // A disk light's penumbra across a straight edge has a standard deviation of a
            // quarter of its width: the Gaussian's sigma.
            var px = 0.25 * width * settings.params.penumbra_scale * to_pixels;
            if px < 0.5 {
                px = 0.0;
            }
            sigma[group_of(layer)][layer % 4u] = min(px, settings.params.max_blur);
        }
    }
    for (var g = 0u; g < groups; g++) {
        textureStore(penumbra_out, pixel, g, sigma[g]);
    }
    for (var w = 0u; w < words; w++) {
        textureStore(bits_out, pixel, w, vec4<u32>(occluded[w]));
        textureStore(bits_out, pixel, words + w, vec4<u32>(tinted[w]));
    }
}
