// Sample-distribution shadow maps (`sdsm` in plugins/pssm/src/sdsm.rs): the nearest and
// farthest view depth of the G-buffer's surfaces, over which the cascades are split. Positive
// f32s order as their bit patterns, so the reduction works on the bits: each workgroup folds
// its pixels into workgroup atomics, then one invocation folds those into `depth_range`, which
// starts at (0xffffffff, 0) and stays so when no pixel has a surface (sky does not count).

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"

struct DepthRange {
    near: atomic<u32>,
    far: atomic<u32>,
}

@group(2) @binding(0) var<storage, read_write> depth_range: DepthRange;

var<workgroup> group_near: atomic<u32>;
var<workgroup> group_far: atomic<u32>;

@compute @workgroup_size(16, 16, 1)
fn cs_depth_range(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    if local == 0u {
        atomicStore(&group_near, 0xffffffffu);
        atomicStore(&group_far, 0u);
    }
    workgroupBarrier();
    if all(id.xy < textureDimensions(gbuffer_view_depth)) {
        let bits = textureLoad(gbuffer_view_depth, vec2<i32>(id.xy), 0).r;
        // 0 on background pixels, as `load_surface`'s `valid`.
        if bitcast<f32>(bits) > 0.0 {
            atomicMin(&group_near, bits);
            atomicMax(&group_far, bits);
        }
    }
    workgroupBarrier();
    if local == 0u && atomicLoad(&group_far) != 0u {
        atomicMin(&depth_range.near, atomicLoad(&group_near));
        atomicMax(&depth_range.far, atomicLoad(&group_far));
    }
}
