// One separable pass of the anisotropic Gaussian (seed 001 §7), all layers at once, on the
// blur grid (the screen, or half of it). Every layer blurs with its own sigma from the
// penumbra pass (taken at the centre), along a rotated direction; taps whose view depth
// differs from the centre's by more than a fraction of it are skipped and the weights
// renormalised, so light does not leak across depth edges. The importer supplies the data it
// blurs, per grid pixel:
//
//   fn occlusion_at(q: vec2<i32>, layer: u32) -> f32     1 = shadowed
//   fn light_at(q: vec2<i32>, layer: u32) -> vec3<f32>   colour that arrives (translucent
//                                                        scenes only)
//
// and writes the results. Expects `common/frame.wgsl`, `common/gbuffer.wgsl` and
// `ssss/data.wgsl` imported first.

@group(2) @binding(1) var penumbra: texture_2d_array<f32>;

struct Blurred {
    occlusion: f32,
    light: vec3<f32>,
}

fn view_depth_at(pixel: vec2<i32>) -> f32 {
    return bitcast<f32>(textureLoad(gbuffer_view_depth, pixel, 0).r);
}

// The screen pixel a grid pixel stands for (the top-left of its block).
fn screen_pixel(q: vec2<i32>) -> vec2<i32> {
    return min(q * grid_step(), vec2<i32>(camera.size) - vec2<i32>(1));
}

// Blur sigmas of grid pixel `q`'s four layers of group `g`, in grid pixels: the largest over
// the screen pixels it stands for.
fn grid_sigma(q: vec2<i32>, g: u32) -> vec4<f32> {
    let step = grid_step();
    var sigma = vec4<f32>(0.0);
    for (var k = 0; k < step * step; k++) {
        let p = min(q * step + vec2<i32>(k % 2, k / 2), vec2<i32>(camera.size) - vec2<i32>(1));
        sigma = max(sigma, textureLoad(penumbra, p, g, 0));
    }
    return sigma / f32(step);
}

// Layer `layer` at grid pixel `q`, blurred along `direction` with `sigma` grid pixels.
fn blur_layer(q: vec2<i32>, layer: u32, sigma: f32, direction: vec2<f32>, depth: f32) -> Blurred {
    let settings = data.settings;
    let colored = settings.translucent == 1u;
    var out: Blurred;
    if sigma <= 0.0 {
        out.occlusion = occlusion_at(q, layer);
        if colored {
            out.light = light_at(q, layer);
        }
        return out;
    }
    let h = i32(settings.half_taps);
    // Taps cover +-2.5 sigma whatever their number.
    let spacing = 2.5 * sigma / f32(h);
    let size = grid_size();
    var weight_sum = 0.0;
    for (var i = -h; i <= h; i++) {
        let x = f32(i) * spacing;
        let t = clamp(q + vec2<i32>(round(direction * x)), vec2<i32>(0), size - vec2<i32>(1));
        let d = view_depth_at(screen_pixel(t));
        if d <= 0.0 || abs(d - depth) > settings.params.depth_threshold * depth {
            continue;
        }
        let u = x / sigma;
        let w = exp(-0.5 * u * u);
        weight_sum += w;
        out.occlusion += w * occlusion_at(t, layer);
        if colored {
            out.light += w * light_at(t, layer);
        }
    }
    out.occlusion /= weight_sum;
    out.light /= weight_sum;
    return out;
}

// Blurs every layer at grid pixel `q` along `direction` into the group and colour outputs.
fn blur_all(q: vec2<i32>, direction: vec2<f32>) {
    let settings = data.settings;
    let depth = view_depth_at(screen_pixel(q));
    let groups = (settings.layer_count + 3u) / 4u;
    for (var g = 0u; g < groups; g++) {
        let sigma = grid_sigma(q, g);
        var occlusion = vec4<f32>(0.0);
        for (var c = 0u; c < 4u; c++) {
            let layer = g * 4u + c;
            if layer >= settings.layer_count || depth <= 0.0 {
                break;
            }
            let b = blur_layer(q, layer, sigma[c], direction, depth);
            occlusion[c] = b.occlusion;
            if settings.translucent == 1u {
                textureStore(light_out, q, layer, vec4<f32>(b.light, 1.0));
            }
        }
        textureStore(occlusion_out, q, g, occlusion);
    }
}
