// Compares two rendered images of the same view (A/B): red where A is darker than B (A shadows
// more), blue where B is darker, both scaled by `gain`, over a dim copy of A for context.

#import "common/fullscreen.wgsl"

#import "host/difference_params.wgsl"

@group(0) @binding(0) var<uniform> params: DifferenceParams;
@group(0) @binding(1) var image_a: texture_2d<f32>;
@group(0) @binding(2) var image_b: texture_2d<f32>;

const LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

@fragment
fn fs_difference(in: FullscreenOut) -> @location(0) vec4<f32> {
    let size = textureDimensions(image_a);
    let pixel = vec2<i32>(min(vec2<u32>(in.uv * vec2<f32>(size)), size - vec2<u32>(1u)));
    let a = dot(textureLoad(image_a, pixel, 0).rgb, LUMA);
    let b = dot(textureLoad(image_b, pixel, 0).rgb, LUMA);
    let d = (b - a) * params.gain;
    let base = a * params.context;
    return vec4<f32>(base + max(d, 0.0), base, base + max(-d, 0.0), 1.0);
}
