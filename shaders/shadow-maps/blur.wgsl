// Separable Gaussian blur of one colour map tile (moments, for example): a horizontal pass
// from the tile's page into the same texels of a scratch page, then a vertical pass back, each
// drawn in the tile's viewport. The maps hold 32-bit floats as their bits
// (`MOMENTS_RG_FORMAT`), so taps are loaded and converted; texels past the tile's edge repeat
// the edge. Sources are bound as arrays with the page
// in the parameters (GL cannot sample a 2D view of one array layer).

#import "common/fullscreen.wgsl"
#import "shadow-maps/layers.wgsl"

// The step's tile, kernel radius and sigma, and direction (`BlurParams` in the library's
// Rust).
#import "shadow-maps/blur_params.wgsl"

@group(0) @binding(0) var source: texture_2d_array<u32>;

// The texel of the tile at `pixel` (clamped to the tile), as floats.
fn tap(pixel: vec2<i32>) -> vec4<f32> {
    return bitcast<vec4<f32>>(textureLoad(source, clamp_to_tile(params.tile, pixel), params.tile.page, 0));
}
@group(1) @binding(0) var<uniform> params: BlurParams;

// The kernel's weights exp(-k² / 2σ²) come incrementally (each is the previous one times a
// ratio that itself shrinks by exp(-1 / σ²)), two exponentials a texel instead of one a tap,
// and each weight serves both taps at its distance.
@fragment
fn fs_blur(in: FullscreenOut) -> @location(0) vec4<u32> {
    let pixel = vec2<i32>(in.position.xy);
    let step = select(vec2<i32>(1, 0), vec2<i32>(0, 1), params.vertical == 1u);
    let inverse_variance = 1.0 / (params.sigma * params.sigma);
    var sum = tap(pixel);
    var weights = 1.0;
    var w = 1.0;
    var ratio = exp(-0.5 * inverse_variance);
    let ratio_step = exp(-inverse_variance);
    for (var k = 1; k <= i32(params.radius); k++) {
        w *= ratio;
        ratio *= ratio_step;
        sum += w * (tap(pixel + step * k) + tap(pixel - step * k));
        weights += 2.0 * w;
    }
    return bitcast<vec4<u32>>(sum / weights);
}
