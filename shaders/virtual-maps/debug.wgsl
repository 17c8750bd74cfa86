// Virtual shadow maps, debug views of a frame's bookkeeping (recorded after the page draws,
// only while a view is shown):
// - `cs_page_table`: the page table of one light's level (`debug_light`, `debug_level`), its
//   faces side by side, a texel per entry;
// - `cs_pool`: the physical pool, a texel per page.
// Colours: drawn this frame yellow (orange where it evicted another page), needed and cached
// green, needed without room red, cached but not needed blue (darker the longer unused),
// empty dark.

#import "virtual-maps/tables.wgsl"

@group(3) @binding(3) var<storage, read> page_table: array<u32>;
@group(3) @binding(4) var<storage, read> needed: array<u32>;
// Per physical page: owner entry, last frame needed, last frame drawn, last frame it evicted
// a page (`bookkeeping.wgsl`).
@group(3) @binding(5) var<storage, read> pool_pages: array<vec4<u32>>;
@group(3) @binding(6) var page_table_image: texture_storage_2d<rgba8unorm, write>;
@group(3) @binding(7) var pool_image: texture_storage_2d<rgba8unorm, write>;

const EMPTY: vec4<f32> = vec4<f32>(0.1, 0.1, 0.1, 1.0);
const DRAWN: vec4<f32> = vec4<f32>(1.0, 0.85, 0.1, 1.0);
const DRAWN_OVER_EVICTED: vec4<f32> = vec4<f32>(1.0, 0.45, 0.0, 1.0);
const CACHED: vec4<f32> = vec4<f32>(0.2, 0.8, 0.25, 1.0);
const NO_ROOM: vec4<f32> = vec4<f32>(0.9, 0.1, 0.1, 1.0);
const IDLE: vec4<f32> = vec4<f32>(0.2, 0.4, 1.0, 1.0);

// The state of a resident physical page.
fn page_color(state: vec4<u32>) -> vec4<f32> {
    let frame = virtual_frame.frame;
    if state.z == frame {
        return select(DRAWN, DRAWN_OVER_EVICTED, state.w == frame);
    }
    if state.y == frame {
        return CACHED;
    }
    let unused = f32(frame - state.y);
    return vec4<f32>(IDLE.rgb * (0.3 + 0.7 * exp(-unused / 16.0)), 1.0);
}

@compute @workgroup_size(8, 8)
fn cs_page_table(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(page_table_image);
    if any(id.xy >= size) {
        return;
    }
    var color = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    let light = virtual_frame.debug_light;
    if light < virtual_frame.light_count {
        let v = virtual_lights[light];
        let side = size.y;
        let face = id.x / side;
        if face < v.faces && virtual_frame.debug_level < v.levels {
            let layer = virtual_layers[layer_of(light, face, virtual_frame.debug_level)];
            let page = vec2<u32>(id.x % side, id.y);
            if all(page < vec2<u32>(layer.pages)) {
                let entry = layer_entry(layer, page);
                let physical = page_table[entry];
                let wanted = needed[entry] != 0u;
                if physical != NO_PAGE {
                    color = page_color(pool_pages[physical]);
                } else if wanted {
                    color = NO_ROOM;
                } else {
                    color = EMPTY;
                }
            }
        }
    }
    textureStore(page_table_image, id.xy, color);
}

@compute @workgroup_size(8, 8)
fn cs_pool(@builtin(global_invocation_id) id: vec3<u32>) {
    let side = virtual_frame.pool_side;
    if any(id.xy >= vec2<u32>(side)) {
        return;
    }
    let state = pool_pages[id.y * side + id.x];
    var color = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    if state.x != NO_PAGE {
        color = page_color(state);
    }
    textureStore(pool_image, id.xy, color);
}
