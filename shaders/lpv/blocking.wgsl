// How much light gets from one cell into the next through the occluders (`lpv/occluders.wgsl`
// writes them). The importer declares `occluder_sums: array<i32>`.

// The occluders of `source` (0 light's view, 1 camera's) in occluder cell `c` of grid k.
// Out of the grid: none. Cells on the grid's far planes (index n) read the nearest inner ones.
fn occluders(k: u32, source: u32, corner: vec3<i32>) -> vec4<f32> {
    let n = i32(lpv.settings.params.grid_size);
    if any(corner < vec3<i32>(0)) || any(corner > vec3<i32>(n)) {
        return vec4<f32>(0.0);
    }
    let c = min(corner, vec3<i32>(n - 1));
    let total = cells_per_grid() * lpv.settings.cascade_count;
    let base = (source * total + cell_index(k, c)) * 4u;
    return vec4<f32>(
        f32(occluder_sums[base]),
        f32(occluder_sums[base + 1u]),
        f32(occluder_sums[base + 2u]),
        f32(occluder_sums[base + 3u]),
    ) / lpv.settings.occluder_scale;
}

// The light's occluders and, with `camera_occluders`, the camera's.
fn view_count() -> u32 {
    return select(1u, 2u, lpv.settings.params.camera_occluders != 0u);
}

// With Faces: how much light gets between neighbouring cells a and b of grid k, 1 - the
// covered share of the face box between their centres times `coverage_gain`.
fn face_transmittance(k: u32, a: vec3<i32>, b: vec3<i32>) -> f32 {
    let lower = min(a, b);
    if !inside_grid(lower) {
        return 1.0;
    }
    let axis = select(select(2u, 1u, a.y != b.y), 0u, a.x != b.x);
    var covered = 0.0;
    let total = cells_per_grid() * lpv.settings.cascade_count;
    for (var s = 0u; s < view_count(); s++) {
        let entry = (s * total + cell_index(k, lower)) * 4u + axis;
        covered = max(covered, f32(occluder_sums[entry]) / lpv.settings.occluder_scale);
    }
    return 1.0 - clamp(lpv.settings.params.coverage_gain * covered, 0.0, 1.0);
}

// How much light flowing along unit axis `d` gets from cell c - d into cell c of grid k.
// Faces: through the face box between their centres. GeometryVolume: 1 - B(-d), B the
// blocking potential at the shared face's centre, the mean of its four corners' occluder
// cells (surfaces facing where the light comes from block it), times `coverage_gain`.
fn transmittance(k: u32, c: vec3<i32>, d: vec3<i32>) -> f32 {
    let mode = lpv.settings.params.occlusion;
    if mode == OCCLUSION_OFF {
        return 1.0;
    }
    if mode == OCCLUSION_FACES {
        return face_transmittance(k, c - d, c);
    }
    // The face lies on the corner plane of c on the side facing the neighbour.
    let plane = select(c, c - d, any(d < vec3<i32>(0)));
    var u = vec3<i32>(0, 1, 0);
    var v = vec3<i32>(0, 0, 1);
    if d.y != 0 {
        u = vec3<i32>(1, 0, 0);
    } else if d.z != 0 {
        u = vec3<i32>(1, 0, 0);
        v = vec3<i32>(0, 1, 0);
    }
    let towards_source = sh_basis(-vec3<f32>(d));
    var blocked = 0.0;
    for (var s = 0u; s < view_count(); s++) {
        let b = 0.25 * (occluders(k, s, plane) + occluders(k, s, plane + u)
            + occluders(k, s, plane + v) + occluders(k, s, plane + u + v));
        blocked = max(blocked, lpv.settings.params.coverage_gain * dot(b, towards_source));
    }
    return 1.0 - clamp(blocked, 0.0, 1.0);
}
