// EVSM with four moments: both warps, the tighter bound wins.

#import "moments/evsm.wgsl"

fn moments(z: f32, spread: f32) -> vec4<f32> {
    let p = positive_warp(z);
    let n = negative_warp(z);
    let positive = warped_moments(p, POSITIVE_EXPONENT * p, spread);
    let negative = warped_moments(n, NEGATIVE_EXPONENT * n, spread);
    return vec4<f32>(positive, negative);
}

fn moment_visibility(m: vec4<f32>, z: f32, bias: f32) -> f32 {
    return min(positive_visibility(m.xy, z, bias), negative_visibility(m.zw, z, bias));
}
