// Hybrid shadows, tile restriction: a compute pass lists the screen tiles that hold edge pixels
// (band depth below 1) and writes the instance count of the volume draw; the volume is then
// drawn once per listed tile, clipped to the tile by clip distances, so nothing is rasterised
// outside the edge tiles.

// Invocations along each side of a tile's scan (`SCAN_SIDE` in `tiles.rs`).
const SCAN_SIDE: u32 = 8u;

// The tile grid (`TileParams` in the plugin's Rust).
#import "hybrid-edge/tile_params.wgsl"

@group(0) @binding(0) var band_depth: texture_depth_2d;
// Active tiles, packed as x | y << 16.
@group(0) @binding(1) var<storage, read_write> tile_list: array<u32>;
// The volume draw's arguments: vertex count, instance count, first vertex, first instance.
@group(0) @binding(2) var<storage, read_write> draw_args: array<atomic<u32>, 4>;
@group(0) @binding(3) var<uniform> params: TileParams;

var<workgroup> has_edge: atomic<u32>;

@compute @workgroup_size(SCAN_SIDE, SCAN_SIDE)
fn cs_tiles(
    @builtin(workgroup_id) tile: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
) {
    if index == 0u {
        atomicStore(&has_edge, 0u);
    }
    workgroupBarrier();
    let size = textureDimensions(band_depth);
    let span = params.tile_size / SCAN_SIDE;
    for (var y = 0u; y < span; y++) {
        for (var x = 0u; x < span; x++) {
            let pixel = tile.xy * params.tile_size + local.xy * span + vec2<u32>(x, y);
            if all(pixel < size) && textureLoad(band_depth, pixel, 0) < 1.0 {
                atomicStore(&has_edge, 1u);
            }
        }
    }
    workgroupBarrier();
    if index == 0u && atomicLoad(&has_edge) == 1u {
        let slot = atomicAdd(&draw_args[1], 1u);
        tile_list[slot] = tile.x | (tile.y << 16u);
    }
}

