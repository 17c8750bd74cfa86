// One separable pass of the anisotropic Gaussian (seed 001 §7), all layers at once. Every
// layer blurs with its own sigma from the penumbra pass (taken at the centre pixel), along a
// rotated screen direction; taps whose view depth differs from the centre's by more than a
// fraction of it are skipped and the weights renormalised, so light does not leak across
// depth edges. The importer supplies the data it blurs:
//
//   fn occlusion_at(q: vec2<i32>, layer: u32) -> f32     1 = shadowed
//   fn light_at(q: vec2<i32>, layer: u32) -> vec3<f32>   colour that arrives (translucent
//                                                        scenes only)
//
// Expects `common/frame.wgsl`, `common/gbuffer.wgsl` and `ssss/data.wgsl` imported first.

@group(2) @binding(1) var penumbra: texture_2d_array<f32>;

struct Blurred {
    occlusion: f32,
    light: vec3<f32>,
}

fn view_depth_at(q: vec2<i32>) -> f32 {
    return bitcast<f32>(textureLoad(gbuffer_view_depth, q, 0).r);
}

// Layer `layer` at `pixel`, blurred along `direction` with `sigma` pixels.
fn blur_layer(pixel: vec2<i32>, layer: u32, sigma: f32, direction: vec2<f32>, depth: f32) -> Blurred {
    let settings = data.settings;
    let colored = settings.translucent == 1u;
    var out: Blurred;
    if sigma <= 0.0 {
        out.occlusion = occlusion_at(pixel, layer);
        if colored {
            out.light = light_at(pixel, layer);
        }
        return out;
    }
    let h = i32(settings.half_taps);
    // Taps cover +-2.5 sigma whatever their number.
    let spacing = 2.5 * sigma / f32(h);
    let size = vec2<i32>(camera.size);
    var weight_sum = 0.0;
    for (var i = -h; i <= h; i++) {
        let x = f32(i) * spacing;
        let q = clamp(pixel + vec2<i32>(round(direction * x)), vec2<i32>(0), size - vec2<i32>(1));
        let d = view_depth_at(q);
        if d <= 0.0 || abs(d - depth) > settings.depth_threshold * depth {
            continue;
        }
        let t = x / sigma;
        let w = exp(-0.5 * t * t);
        weight_sum += w;
        out.occlusion += w * occlusion_at(q, layer);
        if colored {
            out.light += w * light_at(q, layer);
        }
    }
    out.occlusion /= weight_sum;
    out.light /= weight_sum;
    return out;
}
