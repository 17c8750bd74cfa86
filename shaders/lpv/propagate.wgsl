// One propagation step (seed 002 §5.3, Kaplanyan and Dachsbacher's face scheme), as a gather:
// every cell collects, from each of its six neighbours, the intensity that neighbour sends
// through the cell's faces. The flux onto a face is its solid angle from the neighbour's
// centre times the neighbour's intensity towards the face's centre (front face 0.4006696846
// sr, side faces 0.4234413544 sr); it is re-emitted from the cell's centre as a clamped-cosine
// lobe towards that face (intensity flux/pi). With occlusion, light crossing into the cell is
// attenuated by the occluders between the two cells (`lpv/blocking.wgsl`).
// The step's result is added to the accumulated light.

#import "lpv/volume.wgsl"
#import "lpv/blocking.wgsl"

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
