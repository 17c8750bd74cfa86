// Edge-aware spatial filter of rt-shadows' soft visibility: each pixel the weighted mean of the
// accumulated visibility around it (the history, group 3), weighted by a Gaussian of the
// pixel distance, by how near each neighbour lies to the pixel's tangent plane (relative to its
// view distance), by how closely their normals agree and by how close their traced values are
// (a cross-bilateral filter), so that the noise of penumbrae is smoothed while shadows do not
// bleed across depth or orientation edges, nor umbrae into lit ground. Pixels traced like all
// their neighbours are left as they are.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/fullscreen.wgsl"
#import "rt-shadows/light.wgsl"

@group(3) @binding(0) var history: texture_2d_array<f32>;

// A neighbour counts fully within this fraction of the view distance off the tangent plane.
const PLANE_TOLERANCE: f32 = 0.01;
// Exponent of the normals' agreement.
const NORMAL_POWER: f32 = 16.0;
// Difference of traced values at which a neighbour's weight falls to 1/e: a few rays' noise
// is smoothed, a hard edge (0 against 1) is kept.
const VALUE_SIGMA: f32 = 0.35;

// Whether the pixel and its eight neighbours were traced alike: inside an umbra or in full
// light, which filtering could only blur.
fn settled(pixel: vec2<i32>, centre: f32, size: vec2<i32>) -> bool {
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let at = clamp(pixel + vec2<i32>(dx, dy), vec2<i32>(0), size - 1);
            if traced_at(at) != centre {
                return false;
            }
        }
    }
    return true;
}

fn traced_at(pixel: vec2<i32>) -> f32 {
    return textureLoad(history, pixel, rt_light.layer, 0)[rt_light.channel];
}

@fragment
fn fs_denoise(in: FullscreenOut) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.position.xy);
    let s = load_surface(pixel);
    let radius = i32(rt_light.denoise_radius);
    if rt_light.soft == 0u || !s.valid {
        discard;
    }
    let size = vec2<i32>(camera.size);
    let tolerance = PLANE_TOLERANCE * distance(s.position, camera.position);
    let sigma = max(f32(radius) * 0.5, 0.5);
    let centre = traced_at(pixel);
    if radius == 0 || settled(pixel, centre, size) {
        return vec4<f32>(centre);
    }
    var sum = 0.0;
    var weights = 0.0;
    for (var dy = -radius; dy <= radius; dy++) {
        for (var dx = -radius; dx <= radius; dx++) {
            let at = pixel + vec2<i32>(dx, dy);
            if any(at < vec2<i32>(0)) || any(at >= size) {
                continue;
            }
            let n = load_surface(at);
            if !n.valid {
                continue;
            }
            let plane = dot(s.normal, n.position - s.position) / tolerance;
            let spatial = f32(dx * dx + dy * dy) / (2.0 * sigma * sigma);
            let value = traced_at(at);
            let range = (value - centre) / VALUE_SIGMA;
            let w = exp(-spatial - plane * plane - range * range)
                * pow(max(dot(s.normal, n.normal), 0.0), NORMAL_POWER);
            sum += w * value;
            weights += w;
        }
    }
    // Every channel: the pass's blend constant keeps only this light's.
    return vec4<f32>(sum / max(weights, 1e-6));
}
