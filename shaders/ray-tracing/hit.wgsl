// A closest-hit ray's answer, the same from both traversals (`rt_closest` in
// `ray-tracing/trace.wgsl` and `ray-tracing/query.wgsl`).

// The nearest opaque or masked caster on a segment: whether there is one, the distance to it
// along the ray (the segment's end where there is none) and the hit's barycentric coordinates
// (the weights of the triangle's second and third corners).
struct RtHit {
    found: bool,
    t: f32,
    barycentrics: vec2<f32>,
}
