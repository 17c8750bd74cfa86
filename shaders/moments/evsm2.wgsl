// EVSM with two moments: the positive warp only.

#import "moments/evsm.wgsl"

fn moments(z: f32, spread: f32) -> vec4<f32> {
    let w = positive_warp(z);
    return vec4<f32>(warped_moments(w, POSITIVE_EXPONENT * w, spread), 1.0, 1.0);
}

fn moment_visibility(m: vec4<f32>, z: f32, bias: f32) -> f32 {
    return positive_visibility(m.xy, z, bias);
}
