// Layered screen-space soft shadows: the data every pass reads (group 2, binding 0) and the
// layout of the layered targets. A layer is a visibility slot: layer `l` is channel `l % 4`
// of array layer `l / 4` in the float targets, and bit `l % 32` of array layer `l / 32` in
// the bit targets (occluded bits; the tinted bits follow in as many layers again).

// Largest layer count of one batch (64, the plugin's `max_layers` cap): the private arrays
// of the penumbra pass hold this many groups of four and words of 32.
const MAX_GROUPS: u32 = 16u;
const MAX_WORDS: u32 = 2u;

#import "ssss/params.wgsl"

struct Settings {
    // The plugin's parameters the shaders read (generated from their declaration, with the
    // `ESTIMATE_*` constants of its `estimate` choice).
    params: SsssParams,
    // Layers in use.
    layer_count: u32,
    // Blur taps on each side of the centre (kernel = 2 * half_taps + 1).
    half_taps: u32,
    // 1 when the scene has translucent casters.
    translucent: u32,
    // Pixels per world unit at unit view depth: proj[1][1] * height / 2.
    pixel_scale: f32,
    // What the debug pass shows (`DEBUG_*` in `ssss/debug.wgsl`).
    debug_mode: u32,
    // The batch's first layer among all (a multiple of four): the passes run once per batch
    // of at most 64 layers, each over its own layers 0..layer_count.
    layer_base: u32,
    // To 64 bytes, where the light array starts (its 16-byte alignment).
    _pad1: u32,
    _pad2: u32,
}

// One scene light's maps and layer in the batch (indexed like the scene's lights).
struct SsssLight {
    first_layer: u32,
    // 0 when the light is culled, not shadowed or in another batch; 1 or 6 (cube faces).
    layer_count: u32,
    // Its screen-space layer in the batch (visibility slot layer_base + layer).
    layer: u32,
    perspective: u32,
    near: f32,
    far: f32,
    // World size of a texel: per unit of distance along the face axis (perspective) or
    // absolute (orthographic).
    texel_scale: f32,
    // Radius (point, spot) or tangent of the angular radius (directional).
    size: f32,
    // Screen rectangle its influence can reach: x, y, width, height in pixels.
    scissor: vec4<u32>,
    // Bit k set when its layer first_layer + k was rendered this frame (culled layers hold
    // stale depths and are never read).
    kept_faces: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

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
