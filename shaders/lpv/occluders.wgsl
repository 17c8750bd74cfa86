// Adding surfels to the occluders (seed 002 §5.2), for the light's view (reflective shadow
// maps) and the camera's (G-buffer). The importer declares
// `occluder_sums: array<atomic<i32>>`, laid out (source x cells + cell) x 4 + k, source 0 the
// light's view and 1 the camera's. With `occlusion` GeometryVolume, k is a coefficient of the
// blocking potential B(w) = A s^-2 <n, w>+ in two-band SH, on cells centred on the light
// grid's corners. With Faces, k < 3 is an axis: the surfels' area projected across that axis
// over the face box of the cell, the box between its centre and the next cell's centre along
// the axis, as a fraction of a cell face (so a wall through the box covers it whole, whichever
// side the surfels were seen from, when every reflective shadow map sees it: each map's
// surfels count 1 / map count).

// Adds a surfel of area `area` and unit normal `n` at `p` to the occluders of `source` in
// every grid, weighted by `share`.
fn add_occluder(source: u32, p: vec3<f32>, n: vec3<f32>, area: f32, share: f32) {
    let total = cells_per_grid() * lpv.settings.cascade_count;
    for (var k = 0u; k < lpv.settings.cascade_count; k++) {
        let g = lpv.cascades[k];
        let u = (p - g.min) / g.cell;
        let coverage = share * min(area / (g.cell * g.cell), 1.0);
        if lpv.settings.params.occlusion == OCCLUSION_FACES {
            let projected = coverage * abs(n);
            for (var axis = 0u; axis < 3u; axis++) {
                // The face box along `axis` holding p starts at the centre of cell c.
                var c = vec3<i32>(floor(u));
                c[axis] = i32(floor(u[axis] - 0.5));
                if inside_grid(c) {
                    add_fixed(source, total, cell_index(k, c), axis, projected[axis]);
                }
            }
        } else {
            // Occluder cells are centred on light-cell corners: round, not floor.
            let c = vec3<i32>(round(u));
            if inside_grid(c) {
                let b = coverage * sh_cosine_lobe(n);
                for (var j = 0u; j < 4u; j++) {
                    add_fixed(source, total, cell_index(k, c), j, b[j]);
                }
            }
        }
    }
}

// Adds `value` in fixed point to entry `k` of `cell`'s occluders of `source`.
fn add_fixed(source: u32, total: u32, cell: u32, k: u32, value: f32) {
    let scaled = i32(round(value * lpv.settings.occluder_scale));
    if scaled != 0 {
        atomicAdd(&occluder_sums[(source * total + cell) * 4u + k], scaled);
    }
}
