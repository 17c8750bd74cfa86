// Chebyshev's one-sided inequality, the bound of variance-based moment methods (VSM, EVSM).

// The largest fraction of a filter region at or behind t that a region with this mean and
// mean square allows: 1 for t <= mean, else variance / (variance + (t - mean)²).
fn chebyshev_upper_bound(mean: f32, mean_square: f32, t: f32, min_variance: f32) -> f32 {
    if t <= mean {
        return 1.0;
    }
    let variance = max(mean_square - mean * mean, min_variance);
    let d = t - mean;
    return variance / (variance + d * d);
}
