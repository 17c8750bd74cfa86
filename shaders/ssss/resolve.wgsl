// Writes every layer's visibility (1 - occlusion) into the host's visibility slots and, in
// translucent scenes, the colour each light keeps into its transmittance slot. Layers with no
// penumbra at a pixel keep its full-resolution hard result; blurred layers come from the blur
// grid (at half resolution, interpolated from the four nearest grid pixels whose depth matches
// the pixel's).

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

struct Resolved {
    occlusion: f32,
    light: vec3<f32>,
}

fn view_depth_at(pixel: vec2<i32>) -> f32 {
    return bitcast<f32>(textureLoad(gbuffer_view_depth, pixel, 0).r);
}

// The hard result of screen pixel `p`.
fn hard(p: vec2<i32>, layer: u32) -> Resolved {
    var out: Resolved;
    let occluded = (textureLoad(bits, p, word_of(layer), 0).x & bit_of(layer)) != 0u;
    out.occlusion = select(0.0, 1.0, occluded);
    out.light = vec3<f32>(1.0 - out.occlusion);
    let tinted = (textureLoad(bits, p, word_count() + word_of(layer), 0).x & bit_of(layer)) != 0u;
    if tinted && !occluded {
        out.light = textureLoad(tints, p, layer, 0).rgb;
    }
    return out;
}

fn grid_value(q: vec2<i32>, layer: u32) -> Resolved {
    var out: Resolved;
    out.occlusion = textureLoad(occlusion_in, q, group_of(layer), 0)[layer % 4u];
    if data.settings.translucent == 1u {
        out.light = textureLoad(light_in, q, layer, 0).rgb;
    }
    return out;
}

// The blurred result at screen pixel `p`: its grid pixel at full resolution, else bilinear
// over the grid pixels around it whose depth is within the threshold of the pixel's.
fn blurred(p: vec2<i32>, layer: u32, depth: f32) -> Resolved {
    if grid_step() == 1 {
        return grid_value(p, layer);
    }
    let position = (vec2<f32>(p) + 0.5) / 2.0 - 0.5;
    let base = vec2<i32>(floor(position));
    let f = position - vec2<f32>(base);
    let size = grid_size();
    var out: Resolved;
    var weight_sum = 0.0;
    for (var k = 0; k < 4; k++) {
        let o = vec2<i32>(k % 2, k / 2);
        let q = clamp(base + o, vec2<i32>(0), size - vec2<i32>(1));
        let d = view_depth_at(min(q * 2, vec2<i32>(camera.size) - vec2<i32>(1)));
        if d <= 0.0 || abs(d - depth) > data.settings.depth_threshold * depth {
            continue;
        }
        let w = mix(1.0 - f.x, f.x, f32(o.x)) * mix(1.0 - f.y, f.y, f32(o.y)) + 1e-4;
        let v = grid_value(q, layer);
        out.occlusion += w * v.occlusion;
        out.light += w * v.light;
        weight_sum += w;
    }
    if weight_sum == 0.0 {
        return hard(p, layer);
    }
    out.occlusion /= weight_sum;
    out.light /= weight_sum;
    return out;
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
    for (var g = 0u; g < groups; g++) {
        let sigma = textureLoad(penumbra, p, g, 0);
        var visibility = vec4<f32>(1.0);
        for (var c = 0u; c < 4u; c++) {
            let layer = g * 4u + c;
            if layer >= settings.layer_count || depth <= 0.0 {
                break;
            }
            var r: Resolved;
            if sigma[c] > 0.0 {
                r = blurred(p, layer, depth);
            } else {
                r = hard(p, layer);
            }
            visibility[c] = 1.0 - r.occlusion;
            if settings.translucent == 1u {
                // What arrives is visibility times transmittance: keep the colour part.
                let t = saturate(r.light / max(visibility[c], 1e-3));
                textureStore(transmittance_out, p, layer, vec4<f32>(t, 1.0));
            }
        }
        textureStore(visibility_out, p, g, visibility);
    }
}
