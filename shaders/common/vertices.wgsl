// The scene's vertex buffer read as storage (`array<f32>`): each vertex is
// `zoo_host::render::Vertex` (position, normal, texture coordinates), whose size a test checks
// against this.
const VERTEX_FLOATS: u32 = 8u;

// An object's placement (`zoo_host::render::Placement`: instance-rate vertex attributes at
// locations 3 to 6, one column each): takes its stored vertices to world space (the identity
// for objects stored in world space, an instance's transform for instances).
struct Placement {
    @location(3) x: vec4<f32>,
    @location(4) y: vec4<f32>,
    @location(5) z: vec4<f32>,
    @location(6) w: vec4<f32>,
}

fn placed_position(p: Placement, position: vec3<f32>) -> vec3<f32> {
    return (mat4x4<f32>(p.x, p.y, p.z, p.w) * vec4<f32>(position, 1.0)).xyz;
}

// The normal under the placement: its cofactor matrix (the inverse transpose times the
// determinant, which is positive since instances cannot mirror).
fn placed_normal(p: Placement, normal: vec3<f32>) -> vec3<f32> {
    let cofactor = mat3x3<f32>(cross(p.y.xyz, p.z.xyz), cross(p.z.xyz, p.x.xyz), cross(p.x.xyz, p.y.xyz));
    return normalize(cofactor * normal);
}
