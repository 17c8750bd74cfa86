// Second blur pass: blurs the first pass's results across its direction, on the same grid.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "ssss/data.wgsl"

@group(2) @binding(2) var occlusion_in: texture_2d_array<f32>;
@group(2) @binding(3) var light_in: texture_2d_array<f32>;
@group(2) @binding(4) var occlusion_out: texture_storage_2d_array<rgba16float, write>;
@group(2) @binding(5) var light_out: texture_storage_2d_array<rgba16float, write>;

fn occlusion_at(q: vec2<i32>, layer: u32) -> f32 {
    return textureLoad(occlusion_in, q, group_of(layer), 0)[layer % 4u];
}

fn light_at(q: vec2<i32>, layer: u32) -> vec3<f32> {
    return textureLoad(light_in, q, layer, 0).rgb;
}

#import "ssss/blur.wgsl"

@compute @workgroup_size(8, 8)
fn cs_blur_second(@builtin(global_invocation_id) id: vec3<u32>) {
    let q = vec2<i32>(id.xy);
    if any(q >= grid_size()) {
        return;
    }
    blur_all(q, BLUR_DIRECTIONS[1]);
}
