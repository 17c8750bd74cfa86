// Second blur pass: blurs the first pass's results across its direction and writes every
// layer's visibility (1 - occlusion) into the host's visibility slots and, in translucent
// scenes, the colour each light keeps into its transmittance slot.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "ssss/data.wgsl"

@group(2) @binding(2) var occlusion_in: texture_2d_array<f32>;
@group(2) @binding(3) var light_in: texture_2d_array<f32>;
@group(2) @binding(4) var visibility_out: texture_storage_2d_array<rgba8unorm, write>;
@group(2) @binding(5) var transmittance_out: texture_storage_2d_array<rgba8unorm, write>;

fn occlusion_at(q: vec2<i32>, layer: u32) -> f32 {
    return textureLoad(occlusion_in, q, group_of(layer), 0)[layer % 4u];
}

fn light_at(q: vec2<i32>, layer: u32) -> vec3<f32> {
    return textureLoad(light_in, q, layer, 0).rgb;
}

#import "ssss/blur.wgsl"

@compute @workgroup_size(8, 8)
fn cs_blur_second(@builtin(global_invocation_id) id: vec3<u32>) {
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
        var visibility = vec4<f32>(1.0);
        for (var c = 0u; c < 4u; c++) {
            let layer = g * 4u + c;
            if layer >= settings.layer_count || depth <= 0.0 {
                break;
            }
            let b = blur_layer(pixel, layer, sigma[c], BLUR_DIRECTIONS[1], depth);
            visibility[c] = 1.0 - b.occlusion;
            if settings.translucent == 1u {
                // What arrives is visibility times transmittance: keep the colour part.
                let t = saturate(b.light / max(visibility[c], 1e-3));
                textureStore(transmittance_out, pixel, layer, vec4<f32>(t, 1.0));
            }
        }
        textureStore(visibility_out, pixel, g, visibility);
    }
}
