// The per-light uniform of rt-shadows' passes (group 2). Mirrors `RtLight` in
// plugins/rt-shadows/src/lib.rs.

struct RtLight {
    light: u32,
    // Rays per pixel toward the light's disk (1: its centre).
    rays: u32,
    // The light's visibility slot: array layer and channel.
    layer: u32,
    channel: u32,
    // Radius in pixels of the denoising filter; 0 leaves the light as traced.
    denoise_radius: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(2) @binding(0) var<uniform> rt_light: RtLight;
