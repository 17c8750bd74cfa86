// Moment shadow maps, Hamburger 4MSM (Peters and Klein 2015): a texel stores z, z², z³, z⁴.
// From the filtered moments b (pulled towards (0.5, 0.5, 0.5, 0.5) by the moment bias, which
// keeps the Hankel matrix invertible), the lookup finds the distribution with three depths
// z_r, z_2, z_3 whose moments are b and which puts as little weight in front of the receiver
// as any distribution can, and returns the weight at or behind the receiver:
//   1. solve [[1, b1, b2], [b1, b2, b3], [b2, b3, b4]] c = (1, z_r, z_r²) (Cholesky);
//   2. z_2 <= z_3 are the roots of c3 z² + c2 z + c1 = 0;
//   3. shadow = 0 if z_r <= z_2,
//      (z_r z_3 - b1 (z_r + z_3) + b2) / ((z_3 - z_2) (z_r - z_2)) if z_r <= z_3,
//      1 - (z_2 z_3 - b1 (z_2 + z_3) + b2) / ((z_r - z_2) (z_r - z_3)) otherwise.

fn moments(z: f32, spread: f32) -> vec4<f32> {
    let z2 = z * z;
    return vec4<f32>(z, z2, z2 * z, z2 * z2);
}

fn moment_visibility(m: vec4<f32>, z: f32, bias: f32) -> f32 {
    let b = mix(m, vec4<f32>(0.5), bias);
    // Cholesky factorisation B = L D Lᵀ of the Hankel matrix, L unit lower triangular.
    let d2 = b.y - b.x * b.x;
    let l32 = (b.z - b.x * b.y) / d2;
    let d3 = (b.w - b.y * b.y) - l32 * l32 * d2;
    // Forward substitution L y = (1, z, z²), then D, then back substitution Lᵀ c = y.
    let y2 = z - b.x;
    let y3 = z * z - b.y - l32 * y2;
    let c3 = y3 / d3;
    let c2 = y2 / d2 - l32 * c3;
    let c1 = 1.0 - b.x * c2 - b.y * c3;
    // Roots of c3 t² + c2 t + c1.
    let p = c2 / c3;
    let q = c1 / c3;
    let r = sqrt(max(0.25 * p * p - q, 0.0));
    let z2 = -0.5 * p - r;
    let z3 = -0.5 * p + r;
    var shadow = 0.0;
    if z > z3 {
        shadow = 1.0 - (z2 * z3 - b.x * (z2 + z3) + b.y) / ((z - z2) * (z - z3));
    } else if z > z2 {
        shadow = (z * z3 - b.x * (z + z3) + b.y) / ((z3 - z2) * (z - z2));
    }
    return 1.0 - clamp(shadow, 0.0, 1.0);
}
