// Exponential shadow maps (Annen et al. 2008): a texel stores exp(c (z - 1)) (c =
// POSITIVE_EXPONENT, generated from the parameter); filtered, it is the mean of the
// occluders' exp(c z_o) / e^c, and visibility is that mean times exp(c (1 - z)): about 1 where
// the occluders are at the receiver, falling exponentially the farther they lie in front.

fn moments(z: f32, spread: f32) -> vec4<f32> {
    return vec4<f32>(exp(POSITIVE_EXPONENT * (z - 1.0)), 1.0, 1.0, 1.0);
}

fn moment_visibility(m: vec4<f32>, z: f32, bias: f32) -> f32 {
    return clamp(m.x * exp(POSITIVE_EXPONENT * (1.0 - z)), 0.0, 1.0);
}
