// The alpha test every pass shares, whatever group its textures are bound in: the mask read at
// full resolution (level 0), bilinearly, with repeating coordinates (the sampler's), the rule
// the judge's `Textures::alpha` follows, so that a technique's holes are the reference's.

// Whether a surface with mask `layer` (-1: none) and `cutoff` is there at `uv`.
fn alpha_covers(
    textures: texture_2d_array<f32>,
    repeating: sampler,
    uv: vec2<f32>,
    layer: i32,
    cutoff: f32,
) -> bool {
    let alpha = textureSampleLevel(textures, repeating, uv, max(layer, 0), 0.0).a;
    return layer < 0 || alpha >= cutoff;
}
