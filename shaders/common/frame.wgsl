// Per-frame data shared by the host and every technique: bind group 0.

const LIGHT_DIRECTIONAL: u32 = 0u;
const LIGHT_POINT: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;

// `zoo_host::render::frame::CameraUniform`, `GpuLight` and `GpuObject`, by their WGSL names.
#import "common/camera.wgsl"
#import "common/light.wgsl"
#import "common/object.wgsl"
alias Camera = CameraUniform;
alias Light = GpuLight;
alias Object = GpuObject;

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> objects: array<Object>;

// Stored vertex `position` of `object` in world space.
fn object_world(object: u32, position: vec3<f32>) -> vec3<f32> {
    return (objects[object].placement * vec4<f32>(position, 1.0)).xyz;
}

// The drawn index of `object`'s stored triangle `triangle`: one number per triangle drawn,
// instances counted.
fn drawn_triangle_id(object: u32, triangle: u32) -> u32 {
    return objects[object].drawn.x + triangle - objects[object].drawn.y;
}

// The object and stored triangle of drawn triangle `id` (`drawn_triangle_id`'s inverse).
fn drawn_triangle(id: u32) -> vec2<u32> {
    // The last object whose first drawn triangle is at most `id` (an object without triangles
    // starts where the next one does, so that one holds it).
    var lo = 0u;
    var hi = arrayLength(&objects);
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if objects[mid].drawn.x <= id {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return vec2<u32>(lo, objects[lo].drawn.y + id - objects[lo].drawn.x);
}
