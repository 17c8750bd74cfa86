// First blur pass: reads the layered hard shadows and tints of the penumbra pass, writes
// blurred occlusion (four layers per texel) and, in translucent scenes, the blurred colour
// that arrives per layer.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "ssss/data.wgsl"

@group(2) @binding(2) var bits: texture_2d_array<u32>;
@group(2) @binding(3) var tints: texture_2d_array<f32>;
@group(2) @binding(4) var occlusion_out: texture_storage_2d_array<rgba16float, write>;
@group(2) @binding(5) var light_out: texture_storage_2d_array<rgba16float, write>;

fn occlusion_at(q: vec2<i32>, layer: u32) -> f32 {
    let word = textureLoad(bits, q, word_of(layer), 0).x;
    return select(0.0, 1.0, (word & bit_of(layer)) != 0u);
}

// Colour of the light that arrives: none where occluded, the tint behind translucent
// casters, white elsewhere.
fn light_at(q: vec2<i32>, layer: u32) -> vec3<f32> {
    if occlusion_at(q, layer) > 0.0 {
        return vec3<f32>(0.0);
    }
    let tinted = textureLoad(bits, q, word_count() + word_of(layer), 0).x;
    if (tinted & bit_of(layer)) != 0u {
        return textureLoad(tints, q, layer, 0).rgb;
    }
    return vec3<f32>(1.0);
}

#import "ssss/blur.wgsl"

@compute @workgroup_size(8, 8)
fn cs_blur_first(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.size);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let settings = data.settings;
    let depth = view_depth_at(pixel);
    let groups = (settings.layer_count + 3u) / 4u;
    for (var g = 0u; g < groups; g++) {
        let sigma = textureLoad(penumbra, pixel, g, 0);
        var occlusion = vec4<f32>(0.0);
        for (var c = 0u; c < 4u; c++) {
            let layer = g * 4u + c;
            if layer >= settings.layer_count || depth <= 0.0 {
                break;
            }
            let b = blur_layer(pixel, layer, sigma[c], BLUR_DIRECTIONS[0], depth);
            occlusion[c] = b.occlusion;
            if settings.translucent == 1u {
                textureStore(light_out, pixel, layer, vec4<f32>(b.light, 1.0));
            }
        }
        textureStore(occlusion_out, pixel, g, occlusion);
    }
}
