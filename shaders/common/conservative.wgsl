// Overestimating conservative rasterisation in the vertex stage: a triangle grown by half a
// pixel on every side covers every pixel its original touches. Its edges move out by the half
// pixel's extent along their normals and the corners go where the moved edges meet; beyond a
// sharp corner the growth overshoots, which a box grown by as much can clip (hybrid-edge's
// coverage maps, frustum-traced's raster path).

// 2D cross product (twice a triangle's signed area from two of its edges).
fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// The line through a and b moved out by `half` (half a pixel per axis), as (normal, offset):
// points x with dot(normal, x) <= offset are on the triangle's side. `orientation` is the
// sign of the triangle's area.
fn grown_edge(a: vec2<f32>, b: vec2<f32>, orientation: f32, half: vec2<f32>) -> vec3<f32> {
    let d = b - a;
    let normal = vec2<f32>(d.y, -d.x) * orientation;
    return vec3<f32>(normal, dot(normal, a) + dot(abs(normal), half));
}

// Where two edge lines (normal, offset) meet.
fn meet(e: vec3<f32>, f: vec3<f32>) -> vec2<f32> {
    let det = cross2(e.xy, f.xy);
    return vec2<f32>(e.z * f.y - f.z * e.y, e.x * f.z - f.x * e.z) / det;
}

// Corner `corner` of the triangle `p` (of nonzero area) grown by `half` per axis.
fn grown_corner(p: array<vec2<f32>, 3>, corner: u32, half: vec2<f32>) -> vec2<f32> {
    let orientation = sign(cross2(p[1] - p[0], p[2] - p[0]));
    let before = (corner + 2u) % 3u;
    let after = (corner + 1u) % 3u;
    let incoming = grown_edge(p[before], p[corner], orientation, half);
    let outgoing = grown_edge(p[corner], p[after], orientation, half);
    return meet(incoming, outgoing);
}
