// Virtual shadow maps, casters culled per page: every pair of a page drawn this frame and a
// caster object whose world box meets the page (its gutter included) becomes one instance of
// the object's run (`draw.wgsl`), so a page draws only the casters that can reach it. Runs
// after `cs_draw_args`, which left each run's instance count at 0.

#import "virtual-maps/tables.wgsl"
#import "virtual-maps/caster_box.wgsl"

@group(3) @binding(3) var<storage, read> entry_layers: array<u32>;
// The entries drawn this frame, after the candidate lists.
@group(3) @binding(4) var<storage, read> lists: array<u32>;
// The clear draw's arguments (its instances: the pages drawn), then one caster draw's per run.
@group(3) @binding(5) var<storage, read_write> draw_args: array<atomic<u32>>;
// Per caster run: its vertex count, first vertex, object count and first instance.
@group(3) @binding(6) var<storage, read> caster_runs: array<vec4<u32>>;
@group(3) @binding(7) var<storage, read> caster_boxes: array<CasterBox>;
@group(3) @binding(8) var<storage, read_write> instances: array<u32>;
@group(3) @binding(9) var<storage, read_write> counts: array<atomic<u32>>;

// `counts`: the (page, caster) instances drawn (`COUNT_INSTANCES` in the plugin's Rust; the
// bookkeeping's counters come before it).
const COUNT_INSTANCES: u32 = 13u;

// Whether the box `lo`..`hi` meets the page of `entry` or its gutter, in the page's layer: its
// corners' bounds on the layer against the page's square, and in depth against the layer's
// range. A box reaching behind a perspective layer's eye is kept.
fn page_meets(entry: u32, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let layer = virtual_layers[entry_layers[entry]];
    var low = vec3<f32>(1e30);
    var high = vec3<f32>(-1e30);
    for (var c = 0u; c < 8u; c++) {
        let corner = select(lo, hi, vec3<bool>((c & 1u) != 0u, (c & 2u) != 0u, (c & 4u) != 0u));
        let clip = layer.view_proj * vec4<f32>(corner, 1.0);
        if clip.w <= 0.0 {
            return true;
        }
        let ndc = clip.xyz / clip.w;
        let at = vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, ndc.z);
        low = min(low, at);
        high = max(high, at);
    }
    let pages = f32(layer.pages);
    let page = vec2<f32>(window_page(layer, entry));
    let gutter = f32(virtual_frame.gutter) / f32(virtual_frame.page_size);
    let page_lo = vec3<f32>((page - gutter) / pages, 0.0);
    let page_hi = vec3<f32>((page + 1.0 + gutter) / pages, 1.0);
    return all(high >= page_lo) && all(low <= page_hi);
}

@compute @workgroup_size(64)
fn cs_cull(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let casters = arrayLength(&caster_boxes);
    let i = item(id, groups);
    let slot = i / max(casters, 1u);
    if casters == 0u || slot >= atomicLoad(&draw_args[1]) {
        return;
    }
    let b = caster_boxes[i % casters];
    let entry = lists[drawn_place(slot)];
    if !page_meets(entry, b.lo, b.hi) {
        return;
    }
    let run = caster_runs[b.run];
    let at = atomicAdd(&draw_args[4u * (b.run + 1u) + 1u], 1u);
    instances[run.w + at] = slot * run.z + b.local;
    atomicAdd(&counts[COUNT_INSTANCES], 1u);
}
