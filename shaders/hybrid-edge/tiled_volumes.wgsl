enable clip_distances;

// Hybrid shadows, tile restriction: shadow volumes drawn once per active tile (instance),
// clipped to the tile by four clip distances.

#import "common/frame.wgsl"

// The tile grid (`TileParams` in the plugin's Rust).
#import "hybrid-edge/tile_params.wgsl"

@group(2) @binding(0) var<storage, read> tile_list: array<u32>;
@group(2) @binding(1) var<uniform> params: TileParams;

struct TiledVertex {
    @builtin(position) clip: vec4<f32>,
    @builtin(clip_distances) distances: array<f32, 4>,
}

@vertex
fn vs_volume_tiled(
    @location(0) position: vec4<f32>,
    @builtin(instance_index) instance: u32,
) -> TiledVertex {
    let c = camera.view_proj * position;
    let tile = tile_list[instance];
    let corner = vec2<f32>(f32(tile & 0xffffu), f32(tile >> 16u)) * f32(params.tile_size);
    let lo = corner / camera.size;
    let hi = (corner + f32(params.tile_size)) / camera.size;
    // The tile's sides in normalised device coordinates (y up).
    let x0 = lo.x * 2.0 - 1.0;
    let x1 = hi.x * 2.0 - 1.0;
    let y_top = 1.0 - lo.y * 2.0;
    let y_bottom = 1.0 - hi.y * 2.0;
    var out: TiledVertex;
    out.clip = c;
    out.distances = array<f32, 4>(
        c.x - x0 * c.w,
        x1 * c.w - c.x,
        c.y - y_bottom * c.w,
        y_top * c.w - c.y,
    );
    return out;
}

@fragment
fn fs_volume() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0);
}
