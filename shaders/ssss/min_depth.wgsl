// Min-filtered depth maps (seed 001 §9, after Gumbau et al. 2010): each texel keeps the nearest
// depth stored in a MIN_BLOCK x MIN_BLOCK block of its map layer. The penumbra pass reads a
// few of them around a receiver instead of searching the full map for blockers.

// Full-resolution texels per min-map texel along each side.
const MIN_BLOCK: i32 = 8;

@group(0) @binding(0) var depth_maps: texture_2d_array<f32>;
@group(0) @binding(1) var min_maps: texture_storage_2d_array<r32float, write>;
// The atlas pages rendered into this frame (others are skipped). Atlas tiles are whole
// blocks, so no block straddles two lights' maps.
@group(0) @binding(2) var<storage, read> kept_layers: array<u32>;

@compute @workgroup_size(8, 8, 1)
fn cs_min_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(min_maps);
    if id.x >= size.x || id.y >= size.y || id.z >= arrayLength(&kept_layers) {
        return;
    }
    let layer = kept_layers[id.z];
    let full = vec2<i32>(textureDimensions(depth_maps));
    let origin = vec2<i32>(id.xy) * MIN_BLOCK;
    var nearest = 1.0;
    for (var y = 0; y < MIN_BLOCK; y++) {
        for (var x = 0; x < MIN_BLOCK; x++) {
            let texel = min(origin + vec2<i32>(x, y), full - vec2<i32>(1));
            nearest = min(nearest, textureLoad(depth_maps, texel, layer, 0).r);
        }
    }
    textureStore(min_maps, vec2<i32>(id.xy), layer, vec4<f32>(nearest));
}
