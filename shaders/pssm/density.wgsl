// Effective texel density for the debug views of the perspective-aliasing techniques.

#import "common/frame.wgsl"

// False colour for shadow-map texels per screen pixel (linear): red where one texel covers
// several pixels (blocky), green at one to one, blue where texels are finer than pixels.
fn density_colour(texels_per_pixel: f32) -> vec3<f32> {
    let t = clamp(log2(max(texels_per_pixel, 1e-6)) / 3.0, -1.0, 1.0);
    if t < 0.0 {
        return mix(vec3<f32>(0.1, 0.85, 0.2), vec3<f32>(0.95, 0.15, 0.1), -t);
    }
    return mix(vec3<f32>(0.1, 0.85, 0.2), vec3<f32>(0.15, 0.3, 1.0), t);
}

// Shadow-map texels per screen pixel (linear) where one map texel is `texel` world units
// wide at view depth `depth`.
fn texels_per_pixel(depth: f32, texel: f32) -> f32 {
    // World size of one screen pixel at this depth.
    let pixel = 2.0 * depth / (camera.proj[1][1] * camera.size.y);
    return pixel / max(texel, 1e-12);
}
