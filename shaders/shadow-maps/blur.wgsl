// Separable Gaussian blur of one colour map tile (moments, for example): a horizontal pass
// from the tile's page into the same texels of a scratch page, then a vertical pass back, each
// drawn in the tile's viewport. Taps are loaded, not sampled, so unfilterable formats work
// too; texels past the tile's edge repeat the edge. Sources are bound as arrays with the page
// in the parameters (GL cannot sample a 2D view of one array layer).

#import "common/fullscreen.wgsl"
#import "shadow-maps/layers.wgsl"

struct BlurParams {
    // The tile read (its page of `source`).
    tile: MapTile,
    // Taps on each side of the centre; the kernel has 2 * radius + 1.
    radius: u32,
    // Standard deviation in texels.
    sigma: f32,
    // 1 for the vertical pass, 0 for the horizontal one.
    vertical: u32,
    _pad: u32,
}

@group(0) @binding(0) var source: texture_2d_array<f32>;
@group(1) @binding(0) var<uniform> params: BlurParams;

@fragment
fn fs_blur(in: FullscreenOut) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.position.xy);
    let step = select(vec2<i32>(1, 0), vec2<i32>(0, 1), params.vertical == 1u);
    let r = i32(params.radius);
    var sum = vec4<f32>(0.0);
    var weights = 0.0;
    for (var k = -r; k <= r; k++) {
        let w = exp(-0.5 * f32(k * k) / (params.sigma * params.sigma));
        let texel = clamp_to_tile(params.tile, pixel + step * k);
        sum += w * textureLoad(source, texel, params.tile.page, 0);
        weights += w;
    }
    return sum / weights;
}
