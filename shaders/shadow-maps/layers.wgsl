// Shadow-map layers as lookups see them: each layer's camera and tile in the atlas, the
// depth that moment maps store, the cube face a direction falls in, and a tangent frame across
// a light ray. No bindings: the importer binds the cameras.

// Where one layer's map lies in the atlas (`MapTile`) and one layer's camera (`LayerCamera`:
// the depth pass's uniform; an array element of 256-byte slots for lookups), both of the
// library's Rust.
#import "shadow-maps/map_tile.wgsl"
#import "shadow-maps/layer_camera.wgsl"

// Page coordinates in [0, 1] of tile coordinates `uv`, kept half a texel inside the tile so
// bilinear taps never read a neighbouring tile (edges repeat, like a clamping sampler).
fn tile_page_uv(tile: MapTile, uv: vec2<f32>, page_size: vec2<u32>) -> vec2<f32> {
    let size = f32(tile.size);
    let texel = clamp(uv * size, vec2<f32>(0.5), vec2<f32>(size - 0.5));
    return (vec2<f32>(tile.origin) + texel) / vec2<f32>(page_size);
}

// The page texel under tile coordinates `uv` (clamped to the tile).
fn tile_texel(tile: MapTile, uv: vec2<f32>) -> vec2<i32> {
    let size = i32(tile.size);
    let texel = clamp(vec2<i32>(floor(uv * f32(size))), vec2<i32>(0), vec2<i32>(size - 1));
    return vec2<i32>(tile.origin) + texel;
}

// `texel` clamped to the tile's texels (neighbourhoods stay inside the tile).
fn clamp_to_tile(tile: MapTile, texel: vec2<i32>) -> vec2<i32> {
    let origin = vec2<i32>(tile.origin);
    return clamp(texel, origin, origin + vec2<i32>(i32(tile.size) - 1));
}

// The light-space depth of `world` that moment maps store: distance to the light over far
// (perspective layers, the same on every cube face) or the depth coordinate (orthographic and
// warped layers). 0 at the light, 1 at the far plane.
fn light_depth(camera: LayerCamera, world: vec3<f32>) -> f32 {
    if camera.eye.w > 0.0 {
        return length(world - camera.eye.xyz) * camera.eye.w;
    }
    let clip = camera.view_proj * vec4<f32>(world, 1.0);
    return clip.z / clip.w;
}

// The cube face (+x, -x, +y, -y, +z, -z) direction `d` from a point light falls in.
fn cube_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}

// The layer of a light's maps that world point `p` projects into: its only layer, or the
// cube face seen from `light_position` when the light has six.
fn light_layer(first_layer: u32, layer_count: u32, light_position: vec3<f32>, p: vec3<f32>) -> u32 {
    if layer_count == 6u {
        return first_layer + cube_face(p - light_position);
    }
    return first_layer;
}

// One layer's camera in a 256-byte slot of the depth pass's uniform buffer, as lookups read
// the cameras (`CAMERA_STRIDE` in the library). The padding is a member: naga's GLSL output
// drops `@size`, and GL then read the cameras at the wrong stride (the GL parity test in
// `tests/zoo/gl_backend.rs` caught it).
struct CameraSlot {
    camera: LayerCamera,
    _pad: array<vec4<f32>, 6>,
}

// World size of one map texel at p, across the light's rays: `texel_scale` itself for
// orthographic layers; for perspective layers `texel_scale` times p's distance along the
// layer's axis (the spot axis `axis`, or on cube faces the face axis: the largest component).
// The distance along the axis, not along the ray, is the texel's largest footprint there.
fn map_texel_world(perspective: bool, layer_count: u32, texel_scale: f32, light_position: vec3<f32>, axis: vec3<f32>, p: vec3<f32>) -> f32 {
    if !perspective {
        return texel_scale;
    }
    let d = p - light_position;
    if layer_count == 6u {
        let a = abs(d);
        return texel_scale * max(a.x, max(a.y, a.z));
    }
    return texel_scale * dot(d, axis);
}

// Two unit vectors perpendicular to the ray direction `w` and to each other.
fn tangent_frame(w: vec3<f32>) -> mat2x3<f32> {
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(w.x) > 0.9);
    let u = normalize(cross(w, helper));
    return mat2x3<f32>(u, cross(w, u));
}
