// Virtual shadow maps, drawing the pages allocated this frame into the physical pool, all
// from indirect arguments (`cs_draw_args`): `vs_clear` clears each page's slot (its gutter
// included) to the far plane, `vs_caster` draws each caster run's instances, one per (page,
// object) whose object meets the page (`cull.wgsl`): the layer's projection carried onto the
// page's slot of the pool,
// clipped by clip distances to the page and its gutter (the texels filters read beside it);
// `vs_caster_masked` and `fs_caster_masked` draw alpha-tested casters, whose holes write no
// depth (`covered`, the judge's rule).

enable clip_distances;

#import "virtual-maps/tables.wgsl"
#import "virtual-maps/caster_run.wgsl"
#import "common/vertices.wgsl"
#import "common/materials.wgsl"

@group(2) @binding(0) var<uniform> caster_run: CasterRun;
@group(3) @binding(3) var<storage, read> page_table: array<u32>;
@group(3) @binding(4) var<storage, read> entry_layers: array<u32>;
// The entries whose pages are drawn this frame, after the candidate lists.
@group(3) @binding(5) var<storage, read> lists: array<u32>;
@group(3) @binding(6) var<storage, read> scene_vertices: array<f32>;
@group(3) @binding(7) var<storage, read> scene_indices: array<u32>;
// Each run's instances from its `instances_at`: drawn slot times its objects, plus the object.
@group(3) @binding(8) var<storage, read> instances: array<u32>;

@vertex
fn vs_clear(@builtin(vertex_index) vertex: u32, @builtin(instance_index) slot: u32) -> @builtin(position) vec4<f32> {
    let origin = vec2<f32>(slot_origin(page_table[lists[drawn_place(slot)]]));
    let corner = vec2<f32>(f32((0x32u >> vertex) & 1u), f32((0x2cu >> vertex) & 1u));
    let texel = origin + corner * f32(virtual_frame.slot_size);
    let ndc = texel / f32(virtual_frame.pool_texels) * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    return vec4<f32>(ndc, 1.0, 1.0);
}

struct PageVertex {
    @builtin(position) clip: vec4<f32>,
    @builtin(clip_distances) distances: array<f32, 4>,
}

fn scene_position(index: u32) -> vec3<f32> {
    let base = index * VERTEX_FLOATS;
    return vec3<f32>(scene_vertices[base], scene_vertices[base + 1u], scene_vertices[base + 2u]);
}

// The entry and scene object of a caster run's instance `instance`.
fn drawn_pair(instance: u32) -> vec2<u32> {
    let pair = instances[caster_run.instances_at + instance];
    let entry = lists[drawn_place(pair / caster_run.objects)];
    return vec2<u32>(entry, caster_run.first_object + pair % caster_run.objects);
}

// The scene vertex `vertex` of a caster run's instance `instance`, on its page's slot.
fn page_vertex(vertex: u32, instance: u32) -> PageVertex {
    let pair = drawn_pair(instance);
    let entry = pair.x;
    let object = pair.y;
    let layer = virtual_layers[entry_layers[entry]];
    let world = object_world(object, scene_position(scene_indices[vertex]));
    let clip = layer.view_proj * vec4<f32>(world, 1.0);
    // The page's position in its layer, and the point's in the page times w (v from the top).
    let page = vec2<f32>(window_page(layer, entry));
    let pages = f32(layer.pages);
    let u = (clip.x + clip.w) * 0.5 * pages - page.x * clip.w;
    let v = (clip.w - clip.y) * 0.5 * pages - page.y * clip.w;
    // Onto the page's slot of the pool.
    let gutter = f32(virtual_frame.gutter);
    let size = f32(virtual_frame.page_size);
    let corner = vec2<f32>(slot_origin(page_table[entry])) + gutter;
    let pool = f32(virtual_frame.pool_texels);
    let x = (corner.x * clip.w + u * size) / pool;
    let y = (corner.y * clip.w + v * size) / pool;
    var out: PageVertex;
    out.clip = vec4<f32>(2.0 * x - clip.w, clip.w - 2.0 * y, clip.z, clip.w);
    let g = gutter / size * clip.w;
    out.distances = array<f32, 4>(u + g, clip.w + g - u, v + g, clip.w + g - v);
    return out;
}

@vertex
fn vs_caster(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> PageVertex {
    return page_vertex(vertex, instance);
}

struct MaskedVertex {
    @builtin(position) clip: vec4<f32>,
    @builtin(clip_distances) distances: array<f32, 4>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) object: u32,
}

@vertex
fn vs_caster_masked(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> MaskedVertex {
    let placed = page_vertex(vertex, instance);
    let base = scene_indices[vertex] * VERTEX_FLOATS;
    var out: MaskedVertex;
    out.clip = placed.clip;
    out.distances = placed.distances;
    out.uv = vec2<f32>(scene_vertices[base + 6u], scene_vertices[base + 7u]);
    out.object = drawn_pair(instance).y;
    return out;
}

// What the masked fragment reads of `MaskedVertex`.
struct MaskedFragment {
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) object: u32,
}

@fragment
fn fs_caster_masked(in: MaskedFragment) {
    if !covered(in.object, in.uv) {
        discard;
    }
}
