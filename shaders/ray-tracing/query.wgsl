// Shadow rays by hardware ray queries against the scene's acceleration structure
// (`zoo_ray_tracing`, tracer `RayQuery`): the same `rt_occluded` (any hit), `rt_closest`
// (closest hit) and `rt_transmittance` (translucent filtering) as `ray-tracing/trace.wgsl`,
// which a shader imports; the library swaps this module in where the device has ray queries.
// Bind group 3. The casters drawn once are two instances: the blocking casters (mask
// `RT_BLOCKING`: opaque ones decided by the hardware, masked ones a non-opaque geometry whose
// candidate hits pass the shared alpha test before they count) and the translucent ones (mask
// `RT_TRANSLUCENT`, a non-opaque geometry per object). A mesh instances share (unless masked)
// is one bottom level, an instance of it for each of theirs. A translucent object's record is
// its instance's custom data plus its geometry index.

enable wgpu_ray_query;

#import "common/alpha_test.wgsl"
#import "ray-tracing/hit.wgsl"
#import "ray-tracing/translucent.wgsl"

// `GpuMaskedTriangle`: a masked caster's corners' texture coordinates and alpha test,
// indexed by its primitive index in the masked geometry (masked instances are placed into
// it, so no candidate's instance data is read).
#import "ray-tracing/masked_triangle.wgsl"

@group(3) @binding(0) var rt_scene: acceleration_structure;
@group(3) @binding(1) var<storage, read> rt_masked: array<GpuMaskedTriangle>;
@group(3) @binding(2) var rt_textures: texture_2d_array<f32>;
@group(3) @binding(3) var rt_sampler: sampler;
@group(3) @binding(4) var<storage, read> rt_translucent: array<GpuTranslucent>;

// Instance masks (`zoo_ray_tracing`'s `BLOCKING_MASK` and `TRANSLUCENT_MASK`).
const RT_BLOCKING: u32 = 1u;
const RT_TRANSLUCENT: u32 = 2u;

// A query against the blocking casters with ray `flags`, run to its end: masked candidates
// that pass the alpha test are committed (opaque ones the hardware commits alone).
fn rt_query_blocking(origin: vec3<f32>, dir: vec3<f32>, tmax: f32, flags: u32) -> RayIntersection {
    var query: ray_query;
    rayQueryInitialize(&query, rt_scene, RayDesc(flags, RT_BLOCKING, 0.0, tmax, origin, dir));
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
    return rayQueryGetCommittedIntersection(&query);
}

// Whether an opaque or masked caster lies on the segment from `origin` along unit `dir` up to
// `tmax` (translucent casters do not block): an any-hit shadow ray.
fn rt_occluded(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> bool {
    let hit = rt_query_blocking(origin, dir, tmax, RAY_FLAG_TERMINATE_ON_FIRST_HIT);
    return hit.kind != RAY_QUERY_INTERSECTION_NONE;
}

// The nearest opaque or masked caster on the segment from `origin` along unit `dir` up to
// `tmax`: a closest-hit ray.
fn rt_closest(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> RtHit {
    let hit = rt_query_blocking(origin, dir, tmax, RAY_FLAG_NONE);
    if hit.kind == RAY_QUERY_INTERSECTION_NONE {
        return RtHit(false, tmax, vec2<f32>(0.0));
    }
    return RtHit(true, hit.t, hit.barycentrics);
}

// The colour fraction of light the translucent casters on the segment let through (1 without
// any); blocking casters are `rt_occluded`'s.
fn rt_transmittance(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> vec3<f32> {
    var crossing = rt_filter_new();
    // (Without translucent casters no instance has the mask, and the query finds nothing.)
    var query: ray_query;
    rayQueryInitialize(&query, rt_scene, RayDesc(RAY_FLAG_NONE, RT_TRANSLUCENT, 0.0, tmax, origin, dir));
    // Every candidate filters the ray once per object; none is committed, so all are seen.
    while rayQueryProceed(&query) {
        let candidate = rayQueryGetCandidateIntersection(&query);
        let object = candidate.instance_custom_data + candidate.geometry_index;
        rt_filter_cross(&crossing, object, rt_translucent[object].transmittance);
    }
    return crossing.light;
}
