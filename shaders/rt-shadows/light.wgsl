// The per-light uniform of rt-shadows' passes (group 2). Mirrors `RtLight` in
// plugins/rt-shadows/src/lib.rs.

struct RtLight {
    light: u32,
    // Rays per pixel toward the light's disk (1: its centre).
    rays: u32,
    // The light's visibility slot: array layer and channel.
    layer: u32,
    channel: u32,
    // Radius in pixels of the denoising filter (0: the history as it is).
    denoise_radius: u32,
    // 1: a soft light, traced into the history (`fs_accumulate`) and resolved into its slot by
    // the filter; 0: traced straight into its slot (`fs_main`).
    soft: u32,
    // Frames since the view last changed: where the sample sequence continues.
    frame: u32,
}

@group(2) @binding(0) var<uniform> rt_light: RtLight;
