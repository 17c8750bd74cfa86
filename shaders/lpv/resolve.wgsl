// Turns the injected fixed-point sums into the first propagation step's light, and starts the
// accumulated light with it (G_r = sum of G_i from i = 0, seed 002 eq. 5.10); the emitters'
// normal moments likewise.

#import "lpv/volume.wgsl"

@group(0) @binding(0) var<storage, read> lpv: LpvData;
@group(0) @binding(1) var<storage, read> light_sums: array<i32>;
@group(0) @binding(2) var<storage, read_write> light: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> accumulated: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> moment_sums: array<i32>;
@group(0) @binding(5) var<storage, read_write> moments: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn cs_resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    let entries = cells_per_grid() * lpv.settings.cascade_count * 3u;
    if id.x >= entries {
        return;
    }
    let base = id.x * 4u;
    let sums = vec4<f32>(
        f32(light_sums[base]),
        f32(light_sums[base + 1u]),
        f32(light_sums[base + 2u]),
        f32(light_sums[base + 3u]),
    );
    let value = sums / lpv.settings.light_scale;
    light[id.x] = value;
    accumulated[id.x] = value;
    let moment = vec4<f32>(
        f32(moment_sums[base]),
        f32(moment_sums[base + 1u]),
        f32(moment_sums[base + 2u]),
        f32(moment_sums[base + 3u]),
    );
    moments[id.x] = moment / lpv.settings.light_scale;
}
