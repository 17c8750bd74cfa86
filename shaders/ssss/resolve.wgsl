// Writes every layer's visibility (1 - occlusion) into the host's visibility slots and, in
// translucent scenes, the colour each light keeps into its transmittance slot. Layers with no
// penumbra at a pixel keep its full-resolution hard result; blurred layers come from the blur
// grid (at half resolution, interpolated from the four nearest grid pixels whose depth matches
// the pixel's). The bits, the interpolation weights and each group's grid texels are read once
// per pixel and shared by its layers.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "ssss/data.wgsl"

@group(2) @binding(1) var penumbra: texture_2d_array<f32>;
@group(2) @binding(2) var bits: texture_2d_array<u32>;
@group(2) @binding(3) var tints: texture_2d_array<f32>;
@group(2) @binding(4) var occlusion_in: texture_2d_array<f32>;
@group(2) @binding(5) var light_in: texture_2d_array<f32>;
@group(2) @binding(6) var visibility_out: texture_storage_2d_array<rgba8unorm, write>;
@group(2) @binding(7) var transmittance_out: texture_storage_2d_array<rgba8unorm, write>;

fn view_depth_at(pixel: vec2<i32>) -> f32 {
    return bitcast<f32>(textureLoad(gbuffer_view_depth, pixel, 0).r);
}

// The grid pixels a screen pixel reads and their weights (all zero when none matches its
// depth): itself at full resolution, else the four around it, bilinear and depth-aware.
struct Taps {
    at: array<vec2<i32>, 4>,
    weight: vec4<f32>,
}

fn grid_taps(p: vec2<i32>, depth: f32) -> Taps {
    var taps: Taps;
    if grid_step() == 1 {
        taps.at[0] = p;
        taps.weight = vec4<f32>(1.0, 0.0, 0.0, 0.0);
        return taps;
    }
    let position = (vec2<f32>(p) + 0.5) / 2.0 - 0.5;
    let base = vec2<i32>(floor(position));
    let f = position - vec2<f32>(base);
    let size = grid_size();
    var sum = 0.0;
    for (var k = 0; k < 4; k++) {
        let o = vec2<i32>(k % 2, k / 2);
        let q = clamp(base + o, vec2<i32>(0), size - vec2<i32>(1));
        taps.at[k] = q;
        let d = view_depth_at(min(q * 2, vec2<i32>(camera.size) - vec2<i32>(1)));
        if d <= 0.0 || abs(d - depth) > data.settings.params.depth_threshold * depth {
            continue;
        }
        let w = mix(1.0 - f.x, f.x, f32(o.x)) * mix(1.0 - f.y, f.y, f32(o.y)) + 1e-4;
        taps.weight[k] = w;
        sum += w;
    }
    if sum > 0.0 {
        taps.weight /= sum;
    }
    return taps;
}

@compute @workgroup_size(8, 8)
fn cs_resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.size);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let p = vec2<i32>(id.xy);
    let settings = data.settings;
    let depth = view_depth_at(p);
    let groups = (settings.layer_count + 3u) / 4u;
    let colored = settings.translucent == 1u;
    let words = word_count();
    var occluded: array<u32, MAX_WORDS>;
    var tinted: array<u32, MAX_WORDS>;
    for (var w = 0u; w < words; w++) {
        occluded[w] = textureLoad(bits, p, w, 0).x;
        if colored {
            tinted[w] = textureLoad(bits, p, words + w, 0).x;
        }
    }
    let taps = grid_taps(p, depth);
    let interpolated = any(taps.weight > vec4<f32>(0.0));
    for (var g = 0u; g < groups; g++) {
        let sigma = textureLoad(penumbra, p, g, 0);
        var visibility = vec4<f32>(1.0);
        if depth > 0.0 {
            // This group's blurred occlusion, interpolated once for its four layers.
            var blurred = vec4<f32>(0.0);
            if any(sigma > vec4<f32>(0.0)) && interpolated {
                for (var k = 0; k < 4; k++) {
                    if taps.weight[k] > 0.0 {
                        blurred += taps.weight[k] * textureLoad(occlusion_in, taps.at[k], g, 0);
                    }
                }
            }
            for (var c = 0u; c < 4u; c++) {
                let layer = g * 4u + c;
                if layer >= settings.layer_count {
                    break;
                }
                let bit = bit_of(layer);
                let hard = select(0.0, 1.0, (occluded[word_of(layer)] & bit) != 0u);
                let soft = sigma[c] > 0.0 && interpolated;
                let occlusion = select(hard, blurred[c], soft);
                visibility[c] = 1.0 - occlusion;
                if colored {
                    var light = vec3<f32>(1.0 - hard);
                    if soft {
                        light = vec3<f32>(0.0);
                        for (var k = 0; k < 4; k++) {
                            if taps.weight[k] > 0.0 {
                                light += taps.weight[k] * textureLoad(light_in, taps.at[k], layer, 0).rgb;
                            }
                        }
                    } else if hard == 0.0 && (tinted[word_of(layer)] & bit) != 0u {
                        light = textureLoad(tints, p, layer, 0).rgb;
                    }
                    // What arrives is visibility times transmittance: keep the colour part.
                    let t = saturate(light / max(visibility[c], 1e-3));
                    textureStore(transmittance_out, p, settings.layer_base + layer, vec4<f32>(t, 1.0));
                }
            }
        }
        textureStore(visibility_out, p, settings.layer_base / 4u + g, visibility);
    }
}
