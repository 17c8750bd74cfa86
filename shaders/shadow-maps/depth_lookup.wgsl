// Depth-map access for lookups, bound at group 3 by `ShadowMapSet::lookup_group` (depth sets):
// the maps with linear and nearest comparison samplers, the layer cameras, and the same maps
// as plain floats for reading stored depths. The maps appear three times because GLSL cannot
// fetch texels of depth textures and pairs each texture with one sampler. A pass may add
// variables of its own to group 3 from binding 6 on (a pipeline has four groups on WebGPU;
// `Joinable` in the kit's Rust).

#import "shadow-maps/layers.wgsl"

@group(3) @binding(0) var depth_maps: texture_depth_2d_array;
@group(3) @binding(1) var depth_compare_linear: sampler_comparison;
@group(3) @binding(2) var depth_compare_nearest: sampler_comparison;
@group(3) @binding(3) var<storage, read> layer_cameras: array<CameraSlot>;
@group(3) @binding(4) var depth_values: texture_2d_array<f32>;
@group(3) @binding(5) var depth_maps_nearest: texture_depth_2d_array;

// Where a world point lands in one layer: the layer's map coordinates in [0, 1], depth in
// [0, 1], the layer (its index among the cameras), its tile in the atlas, and whether it is
// inside the layer's frustum.
struct MapPoint {
    uv: vec2<f32>,
    depth: f32,
    layer: u32,
    tile: MapTile,
    inside: bool,
}

fn map_point(layer: u32, p: vec3<f32>) -> MapPoint {
    let camera = layer_cameras[layer].camera;
    let clip = camera.view_proj * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    var m: MapPoint;
    m.uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    m.depth = ndc.z;
    m.layer = layer;
    m.tile = camera.tile;
    m.inside = camera.tile.size > 0u && clip.w > 0.0 && abs(ndc.x) <= 1.0 && abs(ndc.y) <= 1.0 && ndc.z >= 0.0 && ndc.z <= 1.0;
    return m;
}

// One depth comparison (bilinear when `linear`): 1 = lit; points outside the layer are lit.
fn compare_map(m: MapPoint, linear: bool) -> f32 {
    if !m.inside {
        return 1.0;
    }
    let uv = tile_page_uv(m.tile, m.uv, textureDimensions(depth_maps));
    if linear {
        return textureSampleCompareLevel(depth_maps, depth_compare_linear, uv, m.tile.page, m.depth);
    }
    return textureSampleCompareLevel(depth_maps_nearest, depth_compare_nearest, uv, m.tile.page, m.depth);
}

// The depth stored in the texel under `m`, in [0, 1].
fn stored_map_depth(m: MapPoint) -> f32 {
    return textureLoad(depth_values, tile_texel(m.tile, m.uv), m.tile.page, 0).r;
}
