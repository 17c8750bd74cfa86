// Caster triangles pulled from the scene's storage buffers, for passes that render every
// caster from one shadow-map layer and need a triangle whole (its drawn index, all three
// corners). Draws cover a caster's stored index range with the object as the instance, so
// instances place their shared triangles.

#import "common/vertices.wgsl"
#import "common/frame.wgsl"
#import "shadow-maps/layers.wgsl"

@group(1) @binding(0) var<uniform> layer_camera: LayerCamera;
// The scene's vertices (`VERTEX_FLOATS` floats each) and triangle indices.
@group(2) @binding(0) var<storage, read> scene_vertices: array<f32>;
@group(2) @binding(1) var<storage, read> scene_indices: array<u32>;

// A clip position outside the clip volume, for triangles that draw nothing.
const OUTSIDE_CLIP: vec4<f32> = vec4<f32>(2.0, 2.0, 2.0, 1.0);

fn scene_position(index: u32) -> vec3<f32> {
    let base = index * VERTEX_FLOATS;
    return vec3<f32>(scene_vertices[base], scene_vertices[base + 1u], scene_vertices[base + 2u]);
}

// Corner `corner` of `object`'s stored triangle `triangle`, in world space.
fn triangle_corner(object: u32, triangle: u32, corner: u32) -> vec3<f32> {
    return object_world(object, scene_position(scene_indices[3u * triangle + corner]));
}
