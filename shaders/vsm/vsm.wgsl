// Variance shadow maps (Donnelly and Lauritzen 2006), a moment method of the shadow-map
// library (`shadow-maps/moments_store.wgsl`, `shadow-maps/moments_lookup.wgsl`): the first
// two moments of the light depth, and Chebyshev's bound on the lit fraction of the filter
// region. Where two casters at different depths share the region the bound is loose and light
// bleeds through.

#import "shadow-maps/chebyshev.wgsl"

fn moments(z: f32, spread: f32) -> vec4<f32> {
    return vec4<f32>(z, z * z + spread, 1.0, 1.0);
}

// The bias is the smallest variance, in squared light-depth units.
fn moment_visibility(m: vec4<f32>, z: f32, bias: f32) -> f32 {
    return chebyshev_upper_bound(m.x, m.y, z, bias);
}
