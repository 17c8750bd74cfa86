// Injection (seed 002 §5.1, §5.2): every reflective-shadow-map texel is a virtual point light
// whose clamped-cosine lobe of intensity goes into the cell it lies in, after moving half a
// cell along its normal (so a surface does not light itself); its surfel goes into the
// occluders (`lpv/occluders.wgsl`). The camera's G-buffer adds occluders the light does not
// see. Sums are fixed point (integer atomics), resolved by `resolve.wgsl`.

#import "lpv/volume.wgsl"
#import "lpv/occluders.wgsl"

@group(0) @binding(0) var<storage, read> lpv: LpvData;
@group(0) @binding(1) var rsm_flux: texture_2d_array<f32>;
@group(0) @binding(2) var rsm_normal: texture_2d_array<f32>;
@group(0) @binding(3) var rsm_position: texture_2d_array<f32>;
// Light: (cell x 3 + channel) x 4 + coefficient. Occluders: (source x cells + cell) x 4 +
// coefficient, source 0 the light's view, 1 the camera's.
@group(0) @binding(4) var<storage, read_write> light_sums: array<atomic<i32>>;
@group(0) @binding(5) var<storage, read_write> occluder_sums: array<atomic<i32>>;
// Emitters' normal moments: (cell x 3 + channel) x 4 + (flux x normal xyz, flux).
@group(0) @binding(6) var<storage, read_write> moment_sums: array<atomic<i32>>;

// Adds `value` in fixed point to a cell's channel: its light SH, or with `moment` its
// emitters' moments.
fn add_sums(moment: bool, cell: u32, channel: u32, value: vec4<f32>) {
    let base = (cell * 3u + channel) * 4u;
    let scaled = vec4<i32>(round(value * lpv.settings.light_scale));
    for (var k = 0u; k < 4u; k++) {
        if scaled[k] == 0 {
            continue;
        }
        if moment {
            atomicAdd(&moment_sums[base + k], scaled[k]);
        } else {
            atomicAdd(&light_sums[base + k], scaled[k]);
        }
    }
}

@compute @workgroup_size(8, 8, 1)
fn cs_inject(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(rsm_flux);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let texel = vec2<i32>(id.xy);
    let layer = i32(id.z);
    let stored = textureLoad(rsm_position, texel, layer, 0);
    if stored.w == 0.0 {
        return;
    }
    let position = vec4<f32>(stored.xyz + lpv.origin.xyz, 1.0);
    let flux = textureLoad(rsm_flux, texel, layer, 0).rgb;
    let normal = textureLoad(rsm_normal, texel, layer, 0);
    let n = normal.xyz;
    let lobe = sh_cosine_lobe(n);
    for (var k = 0u; k < lpv.settings.cascade_count; k++) {
        let g = lpv.cascades[k];
        let c = cell_of(k, position.xyz + n * (0.5 * g.cell));
        if !inside_grid(c) || all(flux == vec3<f32>(0.0)) {
            continue;
        }
        let cell = cell_index(k, c);
        add_sums(false, cell, 0u, flux.r * lobe);
        add_sums(false, cell, 1u, flux.g * lobe);
        add_sums(false, cell, 2u, flux.b * lobe);
        if lpv.settings.params.emitter_orientation != 0u {
            let moment = vec4<f32>(n, 1.0);
            add_sums(true, cell, 0u, flux.r * moment);
            add_sums(true, cell, 1u, flux.g * moment);
            add_sums(true, cell, 2u, flux.b * moment);
        }
    }
    // Every map sees the same surfaces: their surfels count once between them.
    let share = 1.0 / f32(max(lpv.settings.map_count, 1u));
    add_occluder(0u, position.xyz, n, normal.w, share);
}
