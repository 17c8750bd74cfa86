// Stencil counting of shadow volumes and the resolve into visibility.

#import "common/frame.wgsl"
#import "common/fullscreen.wgsl"
#import "shadow-volumes/draw.wgsl"

// Debug pass outputs: stencil counts (integer) and translucent volumes (additive colour).
struct DebugOut {
    @location(0) count: u32,
    @location(1) color: vec4<f32>,
}

// Debug overlay: volumes accumulated translucently, front faces orange, back faces blue.
@fragment
fn fs_volume_debug(@builtin(front_facing) front: bool) -> DebugOut {
    var out: DebugOut;
    out.count = 0u;
    out.color = select(vec4<f32>(0.0, 0.04, 0.10, 1.0), vec4<f32>(0.10, 0.04, 0.0, 1.0), front);
    return out;
}

// Drawn where the stencil count is non-zero: the light is blocked.
@fragment
fn fs_shadowed() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0);
}

struct CountLevel {
    value: u32,
}

@group(1) @binding(0) var<uniform> count_level: CountLevel;

// Debug: writes the stencil count (selected by the stencil test) as an integer.
@fragment
fn fs_count() -> DebugOut {
    var out: DebugOut;
    out.count = count_level.value;
    out.color = vec4<f32>(0.0);
    return out;
}
