// Debug views: one grid as a 3D image (the accumulated light's mean intensity per channel, the
// occluders, or the emitters' mean normal), and the grid bounds on screen.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "lpv/volume.wgsl"
#import "lpv/blocking.wgsl"

@group(2) @binding(0) var<storage, read> lpv: LpvData;
@group(2) @binding(1) var<storage, read> accumulated: array<vec4<f32>>;
@group(2) @binding(2) var<storage, read> occluder_sums: array<i32>;
@group(2) @binding(3) var volume_out: texture_storage_3d<rgba16float, write>;
@group(2) @binding(4) var bounds_out: texture_storage_2d<rgba8unorm, write>;
@group(2) @binding(5) var<storage, read> moments: array<vec4<f32>>;

// What the volume view shows (`lpv.settings.debug_source`): the plugin's volume views in
// order (its test reads these).
const DEBUG_SOURCE_LIGHT: u32 = 0u;
const DEBUG_SOURCE_OCCLUDERS: u32 = 1u;
const DEBUG_SOURCE_EMITTERS: u32 = 2u;

// The mean of an SH4 over the sphere is its band-0 coefficient times y00.
@compute @workgroup_size(4, 4, 4)
fn cs_volume(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = lpv.settings.params.grid_size;
    if any(id >= vec3<u32>(n)) {
        return;
    }
    let k = min(lpv.settings.debug_cascade, lpv.settings.cascade_count - 1u);
    let cell = cell_index(k, vec3<i32>(id));
    var value = vec3<f32>(0.0);
    if lpv.settings.debug_source == DEBUG_SOURCE_LIGHT {
        let i = cell * 3u;
        value = SH_Y0 * vec3<f32>(accumulated[i].x, accumulated[i + 1u].x, accumulated[i + 2u].x);
    } else if lpv.settings.debug_source == DEBUG_SOURCE_EMITTERS {
        // The emitters' mean normal (flux-weighted over the channels) as 0.5 + 0.5 n, scaled
        // by its length: grey where normals cancel, black without emitters.
        let i = cell * 3u;
        let m = moments[i] + moments[i + 1u] + moments[i + 2u];
        if m.w > 0.0 && lpv.settings.params.emitter_orientation != 0u {
            let mean = m.xyz / m.w;
            value = length(mean) * (0.5 + 0.5 * normalize(mean));
        }
    } else {
        // Faces: the covered share of the cell's face box along x, y and z as red, green and
        // blue; the geometry volume: its mean blocking potential, grey.
        let c = vec3<i32>(id);
        for (var s = 0u; s < view_count(); s++) {
            let o = occluders(k, s, c);
            if lpv.settings.params.occlusion == OCCLUSION_FACES {
                value = max(value, o.xyz);
            } else {
                value = max(value, vec3<f32>(SH_Y0 * o.x));
            }
        }
    }
    textureStore(volume_out, vec3<i32>(id), vec4<f32>(value, 1.0));
}

// Which grid is used at each pixel: red the finest, green the next, blue the third, grey the
// fourth, darker where a grid fades into the next.
@compute @workgroup_size(8, 8, 1)
fn cs_bounds(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.size);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let s = load_surface(pixel);
    var color = vec3<f32>(0.0);
    if s.valid {
        let palette = array<vec3<f32>, 4>(
            vec3<f32>(1.0, 0.25, 0.2),
            vec3<f32>(0.25, 0.9, 0.3),
            vec3<f32>(0.25, 0.4, 1.0),
            vec3<f32>(0.7, 0.7, 0.7),
        );
        for (var j = 0u; j < lpv.settings.cascade_count; j++) {
            let k = lpv.settings.cascade_count - 1u - j;
            let g = lpv.cascades[k];
            let u = (s.position - g.min) / g.cell;
            let n = f32(lpv.settings.params.grid_size);
            if all(u >= vec3<f32>(0.0)) && all(u <= vec3<f32>(n)) {
                color = palette[k];
            }
        }
        color *= 0.4 + 0.6 * abs((camera.view * vec4<f32>(s.normal, 0.0)).z);
    }
    textureStore(bounds_out, pixel, vec4<f32>(color, 1.0));
}
