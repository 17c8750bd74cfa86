// Layered screen-space soft shadows: the data every pass reads (group 2, binding 0) and the
// layout of the layered targets. A layer is a visibility slot: layer `l` is channel `l % 4`
// of array layer `l / 4` in the float targets, and bit `l % 32` of array layer `l / 32` in
// the bit targets (occluded bits; the tinted bits follow in as many layers again).

// Largest layer count of one batch (64, the plugin's `max_layers` cap): the private arrays
// of the penumbra pass hold this many groups of four and words of 32.
const MAX_GROUPS: u32 = 16u;
const MAX_WORDS: u32 = 2u;

// The settings every pass reads (the plugin's parameters, then what each frame derives) and
// one scene light's maps and layer in the batch (indexed like the scene's lights):
// `Settings` and `SsssLight` in the plugin's Rust.
#import "ssss/settings.wgsl"
#import "ssss/ssss_light.wgsl"

struct SsssData {
    settings: Settings,
    lights: array<SsssLight>,
}

@group(2) @binding(0) var<storage, read> data: SsssData;

// Screen pixels per blur-grid pixel along each side.
fn grid_step() -> i32 {
    return select(1, 2, data.settings.params.half_resolution == 1u);
}

// The blur grid: the screen, or half of it (rounded up).
fn grid_size() -> vec2<i32> {
    let step = grid_step();
    return (vec2<i32>(camera.size) + vec2<i32>(step - 1)) / step;
}

fn group_of(layer: u32) -> u32 {
    return layer / 4u;
}

fn word_of(layer: u32) -> u32 {
    return layer / 32u;
}

fn bit_of(layer: u32) -> u32 {
    return 1u << (layer % 32u);
}

// 32-bit words per bit set (occluded or tinted).
fn word_count() -> u32 {
    return (data.settings.layer_count + 31u) / 32u;
}

// Screen directions of the two separable passes: rotated by 26.6 degrees so that vertical
// walls do not band (seed 001, from the authors' sample).
const BLUR_DIRECTIONS: array<vec2<f32>, 2> = array<vec2<f32>, 2>(
    vec2<f32>(0.894427, 0.447214),
    vec2<f32>(-0.447214, 0.894427),
);
