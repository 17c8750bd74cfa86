// First blur pass: reads the layered hard shadows and tints of the penumbra pass (at half
// resolution, the mean of each 2 x 2 block: a gathered supersample of the full-resolution
// hard shadows) and writes blurred occlusion (four layers per texel) and, in translucent
// scenes, the blurred colour that arrives per layer.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "ssss/data.wgsl"

@group(2) @binding(2) var bits: texture_2d_array<u32>;
@group(2) @binding(3) var tints: texture_2d_array<f32>;
@group(2) @binding(4) var occlusion_out: texture_storage_2d_array<rgba16float, write>;
@group(2) @binding(5) var light_out: texture_storage_2d_array<rgba16float, write>;

fn pixel_occlusion(p: vec2<i32>, layer: u32) -> f32 {
    let word = textureLoad(bits, p, word_of(layer), 0).x;
    return select(0.0, 1.0, (word & bit_of(layer)) != 0u);
}

// Colour of the light that arrives at screen pixel `p`: none where occluded, the tint behind
// translucent casters, white elsewhere.
fn pixel_light(p: vec2<i32>, layer: u32) -> vec3<f32> {
    if pixel_occlusion(p, layer) > 0.0 {
        return vec3<f32>(0.0);
    }
    let tinted = textureLoad(bits, p, word_count() + word_of(layer), 0).x;
    if (tinted & bit_of(layer)) != 0u {
        return textureLoad(tints, p, layer, 0).rgb;
    }
    return vec3<f32>(1.0);
}

// The screen pixels of grid pixel `q` that count: all surface pixels of its block.
fn block_pixel(q: vec2<i32>, k: i32) -> vec2<i32> {
    return min(q * grid_step() + vec2<i32>(k % 2, k / 2), vec2<i32>(camera.size) - vec2<i32>(1));
}

fn block_size() -> i32 {
    return grid_step() * grid_step();
}

fn occlusion_at(q: vec2<i32>, layer: u32) -> f32 {
    var sum = 0.0;
    var count = 0.0;
    for (var k = 0; k < block_size(); k++) {
        let p = block_pixel(q, k);
        if view_depth_at(p) > 0.0 {
            sum += pixel_occlusion(p, layer);
            count += 1.0;
        }
    }
    return sum / max(count, 1.0);
}

fn light_at(q: vec2<i32>, layer: u32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    var count = 0.0;
    for (var k = 0; k < block_size(); k++) {
        let p = block_pixel(q, k);
        if view_depth_at(p) > 0.0 {
            sum += pixel_light(p, layer);
            count += 1.0;
        }
    }
    return sum / max(count, 1.0);
}

#import "ssss/blur.wgsl"

@compute @workgroup_size(8, 8)
fn cs_blur_first(@builtin(global_invocation_id) id: vec3<u32>) {
    let q = vec2<i32>(id.xy);
    if any(q >= grid_size()) {
        return;
    }
    blur_all(q, BLUR_DIRECTIONS[0]);
}
