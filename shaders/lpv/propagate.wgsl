// One propagation step (seed 002 §5.3, Kaplanyan and Dachsbacher's face scheme), as a gather:
// every cell collects, from each of its six neighbours, the intensity that neighbour sends
// through the cell's faces. The flux onto a face is its solid angle from the neighbour's
// centre times the neighbour's intensity towards the face's centre (front face 0.4006696846
// sr, side faces 0.4234413544 sr); it is re-emitted from the cell's centre as a clamped-cosine
// lobe towards that face (intensity flux/pi). With occlusion, light crossing into the cell is
// attenuated by 1 - B, the geometry volume's blocking potential at the shared face's centre
// towards where the light comes from (the larger of the light's and the camera's occluders).
// The step's result is added to the accumulated light.

#import "lpv/volume.wgsl"

@group(0) @binding(0) var<storage, read> lpv: LpvData;
@group(0) @binding(1) var<storage, read> source: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> destination: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> accumulated: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> occluder_sums: array<i32>;

const FRONT_SOLID_ANGLE: f32 = 0.4006696846;
const SIDE_SOLID_ANGLE: f32 = 0.4234413544;
const PI: f32 = 3.14159265;

const AXES: array<vec3<i32>, 6> = array<vec3<i32>, 6>(
    vec3<i32>(1, 0, 0),
    vec3<i32>(-1, 0, 0),
    vec3<i32>(0, 1, 0),
    vec3<i32>(0, -1, 0),
    vec3<i32>(0, 0, 1),
    vec3<i32>(0, 0, -1),
);

// The occluder SH of `source` (0 light's view, 1 camera's) at occluder cell `c` of cascade k.
// Corners on the grid's far planes (index n) are stored with the nearest inner ones.
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

// How much light flowing along `d` gets through the face cell `c` shares with `c - d`: the
// occluder cells sit on cell corners, so the face's centre is the mean of its four corners.
fn transmittance(k: u32, c: vec3<i32>, d: vec3<i32>) -> f32 {
    if lpv.settings.params.occlusion == 0u {
        return 1.0;
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
    // Blocked by surfaces facing where the light comes from.
    let towards_source = sh_basis(-vec3<f32>(d));
    var blocked = 0.0;
    for (var s = 0u; s < 2u; s++) {
        if s == 1u && lpv.settings.params.camera_occluders == 0u {
            break;
        }
        let b = 0.25 * (occluders(k, s, plane) + occluders(k, s, plane + u)
            + occluders(k, s, plane + v) + occluders(k, s, plane + u + v));
        blocked = max(blocked, dot(b, towards_source));
    }
    return 1.0 - clamp(blocked, 0.0, 1.0);
}

@compute @workgroup_size(4, 4, 4)
fn cs_propagate(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = lpv.settings.params.grid_size;
    let k = id.z / n;
    if id.x >= n || id.y >= n || k >= lpv.settings.cascade_count {
        return;
    }
    let c = vec3<i32>(vec3<u32>(id.x, id.y, id.z % n));
    var sum: array<vec4<f32>, 3>;
    for (var a = 0u; a < 6u; a++) {
        let d = AXES[a];
        let neighbour = c - d;
        if !inside_grid(neighbour) {
            continue;
        }
        // Cells light has not reached (band 0 of every channel zero) send nothing.
        let src = cell_index(k, neighbour) * 3u;
        let dark = source[src].x <= 0.0 && source[src + 1u].x <= 0.0 && source[src + 2u].x <= 0.0;
        if dark && lpv.settings.params.skip_dark_cells != 0u {
            continue;
        }
        let t = transmittance(k, c, d);
        if t <= 0.0 {
            continue;
        }
        let df = vec3<f32>(d);
        for (var ch = 0u; ch < 3u; ch++) {
            let sh = source[src + ch];
            let front = max(dot(sh, sh_basis(df)), 0.0);
            var gathered = FRONT_SOLID_ANGLE / PI * front * sh_cosine_lobe(df);
            for (var b = 0u; b < 6u; b++) {
                let side = vec3<f32>(AXES[b]);
                if dot(side, df) != 0.0 {
                    continue;
                }
                let towards = normalize(df + 0.5 * side);
                let through = max(dot(sh, sh_basis(towards)), 0.0);
                gathered += SIDE_SOLID_ANGLE / PI * through * sh_cosine_lobe(side);
            }
            sum[ch] += t * gathered;
        }
    }
    let dst = cell_index(k, c) * 3u;
    for (var ch = 0u; ch < 3u; ch++) {
        destination[dst + ch] = sum[ch];
        if any(sum[ch] != vec4<f32>(0.0)) {
            accumulated[dst + ch] += sum[ch];
        }
    }
}
