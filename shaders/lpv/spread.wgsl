// Spreads the emitters' normal moments (per cell and colour: the flux-weighted sum of the
// virtual point lights' normals, and their flux) over a box of `orientation_cells` cells each
// way, one axis per pass; run twice, the boxes make a tent whose weights fall to zero at twice
// that, so that each cell knows the mean normal of the emitters whose light reaches it, the
// nearer ones weighing more. The lookup uses it to restore the flux direction propagation
// diffuses away.

#import "lpv/volume.wgsl"

@group(0) @binding(0) var<storage, read> lpv: LpvData;
@group(0) @binding(1) var<storage, read> source: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> destination: array<vec4<f32>>;

// Sums the moments of the cells within `orientation_cells` of `id` along `axis`.
fn spread(id: vec3<u32>, axis: vec3<i32>) {
    let n = lpv.settings.params.grid_size;
    let k = id.z / n;
    if id.x >= n || id.y >= n || k >= lpv.settings.cascade_count {
        return;
    }
    let c = vec3<i32>(vec3<u32>(id.x, id.y, id.z % n));
    let r = i32(lpv.settings.params.orientation_cells);
    var sum: array<vec4<f32>, 3>;
    for (var t = -r; t <= r; t++) {
        let other = c + axis * t;
        if !inside_grid(other) {
            continue;
        }
        let i = cell_index(k, other) * 3u;
        sum[0] += source[i];
        sum[1] += source[i + 1u];
        sum[2] += source[i + 2u];
    }
    let o = cell_index(k, c) * 3u;
    destination[o] = sum[0];
    destination[o + 1u] = sum[1];
    destination[o + 2u] = sum[2];
}

@compute @workgroup_size(4, 4, 4)
fn cs_spread_x(@builtin(global_invocation_id) id: vec3<u32>) {
    spread(id, vec3<i32>(1, 0, 0));
}

@compute @workgroup_size(4, 4, 4)
fn cs_spread_y(@builtin(global_invocation_id) id: vec3<u32>) {
    spread(id, vec3<i32>(0, 1, 0));
}

@compute @workgroup_size(4, 4, 4)
fn cs_spread_z(@builtin(global_invocation_id) id: vec3<u32>) {
    spread(id, vec3<i32>(0, 0, 1));
}
