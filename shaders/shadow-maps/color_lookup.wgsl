// Colour-map access for lookups (moments, fluxes), bound at group 3 by
// `ShadowMapSet::lookup_group` (colour sets): the maps, a linear clamping sampler and the
// layer cameras.

#import "shadow-maps/receiver.wgsl"

@group(3) @binding(0) var color_maps: texture_2d_array<f32>;
@group(3) @binding(1) var color_sampler: sampler;
@group(3) @binding(2) var<storage, read> layer_cameras: array<CameraSlot>;

// A colour map read at a world point.
struct ColorSample {
    // The bilinearly filtered texel.
    value: vec4<f32>,
    // The point's `light_depth` in that layer (what moment maps store).
    depth: f32,
    // Whether the point is inside the layer's frustum (lookups treat points outside as lit).
    inside: bool,
}

// The header's colour map at world point p.
fn sample_color_map(h: MapHeader, p: vec3<f32>) -> ColorSample {
    let layer = header_layer(h, p);
    let camera = layer_cameras[layer].camera;
    let clip = camera.view_proj * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    var s: ColorSample;
    s.inside = camera.tile.size > 0u && clip.w > 0.0 && all(abs(ndc.xy) <= vec2<f32>(1.0)) && ndc.z >= 0.0 && ndc.z <= 1.0;
    if !s.inside {
        return s;
    }
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let page_uv = tile_page_uv(camera.tile, uv, textureDimensions(color_maps));
    s.value = textureSampleLevel(color_maps, color_sampler, page_uv, camera.tile.page, 0.0);
    s.depth = light_depth(camera, p);
    return s;
}
