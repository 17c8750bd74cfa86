// Any-hit shadow rays by hardware ray queries against the scene's acceleration structure
// (`zoo_ray_tracing`, tracer `RayQuery`): the same `rt_occluded` as `ray-tracing/trace.wgsl`,
// which a shader imports; the library swaps this module in where the device has ray queries.
// Bind group 3. Opaque casters are decided by the hardware; masked ones are a non-opaque
// geometry whose candidate hits pass the shared alpha test before they count.

enable wgpu_ray_query;

#import "common/alpha_test.wgsl"

// Mirrors `GpuMaskedTriangle`: a masked caster's corners' texture coordinates and alpha test,
// indexed by its primitive index in the masked geometry.
struct RtMaskedTriangle {
    uv: array<vec2<f32>, 3>,
    mask_layer: i32,
    alpha_cutoff: f32,
}

@group(3) @binding(0) var rt_scene: acceleration_structure;
@group(3) @binding(1) var<storage, read> rt_masked: array<RtMaskedTriangle>;
@group(3) @binding(2) var rt_textures: texture_2d_array<f32>;
@group(3) @binding(3) var rt_sampler: sampler;

// Whether any caster lies on the segment from `origin` along unit `dir` up to `tmax`.
fn rt_occluded(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> bool {
    var query: ray_query;
    let ray = RayDesc(RAY_FLAG_TERMINATE_ON_FIRST_HIT, 0xffu, 0.0, tmax, origin, dir);
    rayQueryInitialize(&query, rt_scene, ray);
    while rayQueryProceed(&query) {
        // Only the masked geometry is non-opaque, so every candidate is a masked triangle.
        let candidate = rayQueryGetCandidateIntersection(&query);
        let tri = rt_masked[candidate.primitive_index];
        let b = candidate.barycentrics;
        let at = tri.uv[0] * (1.0 - b.x - b.y) + tri.uv[1] * b.x + tri.uv[2] * b.y;
        if alpha_covers(rt_textures, rt_sampler, at, tri.mask_layer, tri.alpha_cutoff) {
            rayQueryConfirmIntersection(&query);
        }
    }
    return rayQueryGetCommittedIntersection(&query).kind != RAY_QUERY_INTERSECTION_NONE;
}
