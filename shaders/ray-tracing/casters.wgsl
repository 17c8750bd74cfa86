// The caster triangles one at a time, for the exact per-triangle methods (per-triangle
// volumes, frustum-traced shadows): the flat numbering of `zoo_ray_tracing::GpuBatch`es over
// the traced triangles, each triangle's placement (instances share their mesh's triangles,
// stored once), and the exact test of a shadow ray against one triangle, alpha mask included,
// with the traversal's own triangle test (`rt_intersect`), so the methods stop exactly the rays
// that rt-shadows and the judge see stopped.
//
// A stage importing it binds `caster_batches` at group 4, binding 0 (the plugin's buffer from
// `zoo_ray_tracing::RayTracing::batch_buffer`), keeping that binding free in its own group.

#import "ray-tracing/trace.wgsl"
#import "ray-tracing/batch.wgsl"

// The casters' runs of triangles, in flat order (`start` ascending).
@group(4) @binding(0) var<storage, read> caster_batches: array<GpuBatch>;

// `zoo_ray_tracing::NO_INSTANCE`.
const CASTER_NO_INSTANCE: u32 = 0xffffffffu;

// A caster triangle: its index among the traced triangles and the placement of its instance
// (rows of world to mesh space; the identity for triangles stored in world space).
struct CasterTriangle {
    index: u32,
    instanced: bool,
    to_local: array<vec4<f32>, 3>,
}

// The batch that holds flat triangle number `flat` (the last whose start is not past it).
fn caster_batch_of(flat: u32) -> GpuBatch {
    var low = 0u;
    var high = arrayLength(&caster_batches);
    while high - low > 1u {
        let middle = (low + high) / 2u;
        if caster_batches[middle].start <= flat {
            low = middle;
        } else {
            high = middle;
        }
    }
    return caster_batches[low];
}

// Caster triangle number `flat` of the flat numbering.
fn caster_triangle(flat: u32) -> CasterTriangle {
    let batch = caster_batch_of(flat);
    var caster: CasterTriangle;
    caster.index = batch.first + flat - batch.start;
    caster.instanced = batch.instance != CASTER_NO_INSTANCE;
    caster.to_local = array<vec4<f32>, 3>(
        vec4<f32>(1.0, 0.0, 0.0, 0.0),
        vec4<f32>(0.0, 1.0, 0.0, 0.0),
        vec4<f32>(0.0, 0.0, 1.0, 0.0),
    );
    if caster.instanced {
        caster.to_local = rt_instances[batch.instance].to_local;
    }
    return caster;
}

// World point `p` in the caster's mesh space.
fn caster_local_point(caster: CasterTriangle, p: vec3<f32>) -> vec3<f32> {
    let m = caster.to_local;
    let o = vec4<f32>(p, 1.0);
    return vec3<f32>(dot(m[0], o), dot(m[1], o), dot(m[2], o));
}

// World direction `d` in the caster's mesh space.
fn caster_local_direction(caster: CasterTriangle, d: vec3<f32>) -> vec3<f32> {
    let m = caster.to_local;
    return vec3<f32>(dot(m[0].xyz, d), dot(m[1].xyz, d), dot(m[2].xyz, d));
}

// The caster's corners in world space (an instance's placement inverted).
fn caster_world_corners(caster: CasterTriangle) -> array<vec3<f32>, 3> {
    let tri = rt_triangles[caster.index];
    var corners = array<vec3<f32>, 3>(tri.v0, tri.v0 + tri.e1, tri.v0 + tri.e2);
    if caster.instanced {
        // The rows of the world-to-mesh matrix inverted: columns of cofactors over the
        // determinant, and the shift undone.
        let m = caster.to_local;
        let r0 = m[0].xyz;
        let r1 = m[1].xyz;
        let r2 = m[2].xyz;
        let shift = vec3<f32>(m[0].w, m[1].w, m[2].w);
        let c0 = cross(r1, r2);
        let c1 = cross(r2, r0);
        let c2 = cross(r0, r1);
        let det = dot(r0, c0);
        for (var k = 0u; k < 3u; k++) {
            let local = corners[k] - shift;
            corners[k] = (c0 * local.x + c1 * local.y + c2 * local.z) / det;
        }
    }
    return corners;
}

// Whether the caster stops the shadow ray from world `origin` along unit `direction` within
// `reach`: the traversal's triangle test in the mesh's space (a placement maps the ray's
// points at the same parameter), its alpha mask included.
fn caster_blocks(caster: CasterTriangle, origin: vec3<f32>, direction: vec3<f32>, reach: f32) -> bool {
    var o = origin;
    var d = direction;
    if caster.instanced {
        o = caster_local_point(caster, origin);
        d = caster_local_direction(caster, direction);
    }
    return rt_intersect(caster.index, o, d, reach).x > 0.0;
}
