// Exponential variance shadow maps (Lauritzen and McCool 2008): Chebyshev's bound applied to
// depths warped by exponentials, which separates casters at different depths and so bleeds
// far less light than VSM. The positive warp exp(c+ (z - 1)) is increasing in z; the negative
// one exp(c- (1 - z)) is decreasing, so its bound is taken on its negation. Both are 1 at the
// far plane. The smallest variance (the bias) is in light-depth units and scales with each
// warp's slope at the receiver.

#import "shadow-maps/chebyshev.wgsl"

fn positive_warp(z: f32) -> f32 {
    return exp(POSITIVE_EXPONENT * (z - 1.0));
}

fn negative_warp(z: f32) -> f32 {
    return exp(NEGATIVE_EXPONENT * (1.0 - z));
}

// A warp's first two moments, its slope spreading the second like the depth's own; the second
// stays below the map format's largest finite value (MOMENT_LIMIT, generated), so that steep
// texels never store infinity for the blur to spread.
fn warped_moments(w: f32, slope: f32, spread: f32) -> vec2<f32> {
    return vec2<f32>(w, min(w * w + slope * slope * spread, MOMENT_LIMIT));
}

// The bound for the positive warp (moments m, receiver depth z).
fn positive_visibility(m: vec2<f32>, z: f32, bias: f32) -> f32 {
    let w = positive_warp(z);
    let slope = POSITIVE_EXPONENT * w;
    return chebyshev_upper_bound(m.x, m.y, w, bias * slope * slope);
}

// The bound for the negative warp, on its negation (increasing in z).
fn negative_visibility(m: vec2<f32>, z: f32, bias: f32) -> f32 {
    let w = negative_warp(z);
    let slope = NEGATIVE_EXPONENT * w;
    return chebyshev_upper_bound(-m.x, m.y, -w, bias * slope * slope);
}
