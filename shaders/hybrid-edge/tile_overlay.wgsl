// Debug: the active tiles of the tile restriction as squares, one instance per listed tile.

#import "common/frame.wgsl"

// The tile grid (`TileParams` in the plugin's Rust).
#import "hybrid-edge/tile_params.wgsl"

@group(2) @binding(0) var<storage, read> active_tiles: array<u32>;
@group(2) @binding(1) var<uniform> overlay_params: TileParams;

@vertex
fn vs_tile(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> @builtin(position) vec4<f32> {
    let tile = active_tiles[instance];
    let corner = vec2<f32>(f32(tile & 0xffffu), f32(tile >> 16u)) * f32(overlay_params.tile_size);
    // Two triangles over the tile, one pixel in from its sides so neighbours stay apart.
    let unit = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0),
        vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    );
    let pixel = corner + 1.0 + unit[vertex] * (f32(overlay_params.tile_size) - 2.0);
    let ndc = pixel / camera.size * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    return vec4<f32>(ndc, 0.0, 1.0);
}

@fragment
fn fs_tile() -> @location(0) vec4<f32> {
    return vec4<f32>(0.95, 0.45, 0.1, 1.0);
}
