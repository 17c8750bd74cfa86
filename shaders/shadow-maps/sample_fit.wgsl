// Where the view's samples are (`zoo_shadow_maps::sample_fit`), for maps fitted to them
// (sample-distribution shadow maps): the nearest and farthest view depth of the G-buffer's
// surfaces, and for each directional light (workgroup z) the light-space box of the surfaces in
// each of DEPTH_BINS logarithmic bins of view depth between the camera's clip planes.
// Floats are folded as order-preserving bits (`ordered`): each workgroup into workgroup
// atomics, then into `fit_result`, which starts with every minimum at 0xffffffff and every
// maximum at 0 and keeps them where no surface falls (sky does not count).

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "shadow-maps/fit_params.wgsl"

const DEPTH_BINS: u32 = 64u;
// Side of a workgroup's square of pixels.
const FIT_SIDE: u32 = 16u;
// Per bin: the smallest x, y and z, then the largest.
const BOX_WORDS: u32 = 6u;

struct FitResult {
    // View depths, as f32 bits (positive, so they order as they are).
    near: atomic<u32>,
    far: atomic<u32>,
    // Per light, per bin, BOX_WORDS ordered bits.
    boxes: array<atomic<u32>>,
}

@group(2) @binding(0) var<uniform> fit_params: FitParams;
// Per directional light: world to its light space (`fit_view` in the library).
@group(2) @binding(1) var<storage, read> fit_views: array<mat4x4<f32>>;
@group(2) @binding(2) var<storage, read_write> fit_result: FitResult;

var<workgroup> group_near: atomic<u32>;
var<workgroup> group_far: atomic<u32>;
var<workgroup> group_boxes: array<atomic<u32>, DEPTH_BINS * BOX_WORDS>;

// Bits of `x` that order as the floats do (`ordered_bits` in the library).
fn ordered(x: f32) -> u32 {
    let bits = bitcast<u32>(x);
    return select(bits | 0x80000000u, ~bits, (bits & 0x80000000u) != 0u);
}

// The bin of view depth `depth` (`depth_bin` in the library).
fn depth_bin(depth: f32) -> u32 {
    let t = log(depth / fit_params.near) / log(fit_params.far / fit_params.near);
    return min(u32(max(t, 0.0) * f32(DEPTH_BINS)), DEPTH_BINS - 1u);
}

@compute @workgroup_size(FIT_SIDE, FIT_SIDE, 1)
fn cs_sample_fit(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let words = DEPTH_BINS * BOX_WORDS;
    for (var i = local; i < words; i += FIT_SIDE * FIT_SIDE) {
        atomicStore(&group_boxes[i], select(0u, 0xffffffffu, i % BOX_WORDS < 3u));
    }
    if local == 0u {
        atomicStore(&group_near, 0xffffffffu);
        atomicStore(&group_far, 0u);
    }
    workgroupBarrier();
    let light = group.z;
    if all(id.xy < textureDimensions(gbuffer_view_depth)) {
        let pixel = vec2<i32>(id.xy);
        let bits = textureLoad(gbuffer_view_depth, pixel, 0).r;
        let surface = load_surface(pixel);
        if surface.valid {
            atomicMin(&group_near, bits);
            atomicMax(&group_far, bits);
            if light < fit_params.lights {
                let p = (fit_views[light] * vec4<f32>(surface.position, 1.0)).xyz;
                let base = depth_bin(bitcast<f32>(bits)) * BOX_WORDS;
                for (var k = 0u; k < 3u; k++) {
                    atomicMin(&group_boxes[base + k], ordered(p[k]));
                    atomicMax(&group_boxes[base + 3u + k], ordered(p[k]));
                }
            }
        }
    }
    workgroupBarrier();
    if local == 0u && atomicLoad(&group_far) != 0u {
        atomicMin(&fit_result.near, atomicLoad(&group_near));
        atomicMax(&fit_result.far, atomicLoad(&group_far));
    }
    if light < fit_params.lights {
        for (var i = local; i < words; i += FIT_SIDE * FIT_SIDE) {
            let value = atomicLoad(&group_boxes[i]);
            let slot = light * words + i;
            if i % BOX_WORDS < 3u {
                if value != 0xffffffffu {
                    atomicMin(&fit_result.boxes[slot], value);
                }
            } else if value != 0u {
                atomicMax(&fit_result.boxes[slot], value);
            }
        }
    }
}
