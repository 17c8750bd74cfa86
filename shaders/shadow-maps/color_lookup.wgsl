// Colour-map access for lookups (moments, fluxes), bound at group 3 by
// `ShadowMapSet::lookup_group` (colour sets): the maps and the layer cameras. The maps hold
// 32-bit floats as their bits (`MOMENTS_RG_FORMAT`: not every device renders into or filters
// float textures), so lookups filter them here: the same texels and weights on every backend.

#import "shadow-maps/receiver.wgsl"

@group(3) @binding(0) var color_maps: texture_2d_array<u32>;
@group(3) @binding(1) var<storage, read> layer_cameras: array<CameraSlot>;

// A colour map read at a world point.
struct ColorSample {
    // The bilinearly filtered texel.
    value: vec4<f32>,
    // The point's `light_depth` in that layer (what moment maps store).
    depth: f32,
    // Whether the point is inside the layer's frustum (lookups treat points outside as lit).
    inside: bool,
}

// Bilinear filtering of `page` at `uv` (0 to 1 over the page), texels past the page's edge
// clamped to it, as a linear clamping sampler would.
fn filter_color_map(uv: vec2<f32>, page: u32) -> vec4<f32> {
    let texel = uv * vec2<f32>(textureDimensions(color_maps)) - 0.5;
    let corner = floor(texel);
    let f = texel - corner;
    let top = mix(color_texel(corner, vec2<i32>(0, 0), page), color_texel(corner, vec2<i32>(1, 0), page), f.x);
    let bottom = mix(color_texel(corner, vec2<i32>(0, 1), page), color_texel(corner, vec2<i32>(1, 1), page), f.x);
    return mix(top, bottom, f.y);
}

// The texel at `corner + offset` of `page` (clamped to the page) as floats.
fn color_texel(corner: vec2<f32>, offset: vec2<i32>, page: u32) -> vec4<f32> {
    let last = vec2<i32>(textureDimensions(color_maps)) - 1;
    let texel = clamp(vec2<i32>(corner) + offset, vec2<i32>(0), last);
    return bitcast<vec4<f32>>(textureLoad(color_maps, texel, page, 0));
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
    s.value = filter_color_map(page_uv, camera.tile.page);
    s.depth = light_depth(camera, p);
    return s;
}
