// The scene's materials: bind group 1 of the passes that draw the scene's geometry (the
// G-buffer, the shadow-map depth passes, planar's flattened casters, lpv's reflective maps).
// Records: `zoo_host::render::materials::GpuObjectMaterial`.

#import "common/alpha_test.wgsl"
#import "common/object_material.wgsl"

@group(1) @binding(0) var<storage, read> object_materials: array<GpuObjectMaterial>;
@group(1) @binding(1) var material_textures: texture_2d_array<f32>;
@group(1) @binding(2) var material_sampler: sampler;

// Whether the surface of `object` at `uv` is there (not a hole of its alpha mask).
fn covered(object: u32, uv: vec2<f32>) -> bool {
    let m = object_materials[object];
    return alpha_covers(material_textures, material_sampler, uv, m.mask_layer, m.alpha_cutoff);
}

// The albedo texture's colour of `object` at `uv`, filtered at the level the fragment's
// derivatives pick (white without a texture). Fragment stage, uniform control flow.
fn albedo_texel(object: u32, uv: vec2<f32>) -> vec3<f32> {
    let layer = object_materials[object].albedo_layer;
    let texel = textureSample(material_textures, material_sampler, uv, max(layer, 0)).rgb;
    return select(vec3<f32>(1.0), texel, layer >= 0);
}
