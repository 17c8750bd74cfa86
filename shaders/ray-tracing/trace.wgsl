// Any-hit shadow rays against the scene's shadow casters in a bounding volume hierarchy
// (`zoo_ray_tracing`: the judge's own build, boxes grown by the triangle test's rounding).
// Bind group 3. Alpha-masked casters let rays through their holes; translucent ones, in a
// hierarchy of their own, filter them (`rt_transmittance`). Closest-hit rays: `rt_closest`.

#import "common/alpha_test.wgsl"
#import "ray-tracing/hit.wgsl"
#import "ray-tracing/translucent.wgsl"

// Mirrors `GpuNode`: children `first` and `first + 1`, or triangles `first..first + count`.
struct RtNode {
    min: vec3<f32>,
    first: u32,
    max: vec3<f32>,
    count: u32,
}

// Mirrors `GpuTriangle`: a corner, the edges from it, its translucent object (in the
// translucent hierarchy) and its alpha test.
struct RtTriangle {
    v0: vec3<f32>,
    translucent: u32,
    e1: vec3<f32>,
    mask_layer: i32,
    e2: vec3<f32>,
    alpha_cutoff: f32,
}

// Mirrors `GpuTexcoords`.
struct RtTexcoords {
    uv: array<vec2<f32>, 3>,
    _pad: vec2<f32>,
}

@group(3) @binding(0) var<storage, read> rt_nodes: array<RtNode>;
@group(3) @binding(1) var<storage, read> rt_triangles: array<RtTriangle>;
@group(3) @binding(2) var<storage, read> rt_texcoords: array<RtTexcoords>;
@group(3) @binding(3) var rt_textures: texture_2d_array<f32>;
@group(3) @binding(4) var rt_sampler: sampler;
@group(3) @binding(5) var<storage, read> rt_translucent: array<RtTranslucent>;

// Nodes a traversal can hold pending (`zoo_ray_tracing::STACK_SIZE`, which refuses deeper
// hierarchies).
const RT_STACK_SIZE: u32 = 64u;

// Whether the ray enters the node's box before `tmax` (slab test; `inv_dir` finite).
fn rt_enters(node: RtNode, origin: vec3<f32>, inv_dir: vec3<f32>, tmax: f32) -> bool {
    let t1 = (node.min - origin) * inv_dir;
    let t2 = (node.max - origin) * inv_dir;
    let near = max(max(min(t1.x, t2.x), min(t1.y, t2.y)), max(min(t1.z, t2.z), 0.0));
    let far = min(min(max(t1.x, t2.x), max(t1.y, t2.y)), max(t1.z, t2.z)) * (1.0 + 1e-6);
    return near <= far && near <= tmax;
}

// Where triangle `index` stops the ray within (0, tmax), as (t, b1, b2) (the hit's distance and
// barycentric coordinates), or zero where it does not: Möller–Trumbore, then its alpha test at
// the hit's barycentric texture coordinates.
fn rt_intersect(index: u32, origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> vec3<f32> {
    let tri = rt_triangles[index];
    let p = cross(dir, tri.e2);
    let det = dot(tri.e1, p);
    if det == 0.0 {
        return vec3<f32>(0.0);
    }
    let inv_det = 1.0 / det;
    let s = origin - tri.v0;
    let b1 = dot(s, p) * inv_det;
    let q = cross(s, tri.e1);
    let b2 = dot(dir, q) * inv_det;
    let t = dot(tri.e2, q) * inv_det;
    if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 || t <= 0.0 || t >= tmax {
        return vec3<f32>(0.0);
    }
    if tri.mask_layer >= 0 {
        let uv = rt_texcoords[index].uv;
        let at = uv[0] * (1.0 - b1 - b2) + uv[1] * b1 + uv[2] * b2;
        if !alpha_covers(rt_textures, rt_sampler, at, tri.mask_layer, tri.alpha_cutoff) {
            return vec3<f32>(0.0);
        }
    }
    return vec3<f32>(t, b1, b2);
}

// What a walk of the hierarchy answers.
const RT_ANY_HIT: u32 = 0u;
const RT_FILTER: u32 = 1u;
const RT_CLOSEST: u32 = 2u;

// Walks the hierarchy from node `root` along the segment from `origin` along unit `dir` up to
// `tmax`. `RT_ANY_HIT`: whether a triangle stops the ray. `RT_FILTER`: every triangle the ray
// crosses filters it (`crossing`). `RT_CLOSEST`: the nearest hit (`nearest`, whose `t` starts
// at `tmax`), the segment shortened to it as the walk goes on.
fn rt_walk(
    root: u32,
    origin: vec3<f32>,
    dir: vec3<f32>,
    mode: u32,
    crossing: ptr<function, RtFilter>,
    nearest: ptr<function, RtHit>,
) -> bool {
    // Reciprocals kept finite, as the judge's: no 0 x inf in the slab test.
    let huge = vec3<f32>(1e30);
    let inv_dir = clamp(select(1.0 / dir, huge, dir == vec3<f32>(0.0)), -huge, huge);
    var stack: array<u32, RT_STACK_SIZE>;
    var top = 1u;
    stack[0] = root;
    while top > 0u {
        top -= 1u;
        let node = rt_nodes[stack[top]];
        if !rt_enters(node, origin, inv_dir, (*nearest).t) {
            continue;
        }
        if node.count > 0u {
            for (var i = node.first; i < node.first + node.count; i++) {
                let hit = rt_intersect(i, origin, dir, (*nearest).t);
                if hit.x <= 0.0 {
                    continue;
                }
                if mode == RT_ANY_HIT {
                    return true;
                } else if mode == RT_FILTER {
                    let object = rt_triangles[i].translucent;
                    rt_filter_cross(crossing, object, rt_translucent[object].transmittance);
                } else {
                    *nearest = RtHit(true, hit.x, hit.yz);
                }
            }
        } else if top + 2u <= RT_STACK_SIZE {
            stack[top] = node.first;
            stack[top + 1u] = node.first + 1u;
            top += 2u;
        }
    }
    return (*nearest).found;
}

// Whether an opaque or masked caster lies on the segment from `origin` along unit `dir` up to
// `tmax` (translucent casters do not block): an any-hit shadow ray.
fn rt_occluded(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> bool {
    var crossing = rt_filter_new();
    var nearest = RtHit(false, tmax, vec2<f32>(0.0));
    return rt_walk(0u, origin, dir, RT_ANY_HIT, &crossing, &nearest);
}

// The nearest opaque or masked caster on the segment from `origin` along unit `dir` up to
// `tmax`: a closest-hit ray.
fn rt_closest(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> RtHit {
    var crossing = rt_filter_new();
    var nearest = RtHit(false, tmax, vec2<f32>(0.0));
    rt_walk(0u, origin, dir, RT_CLOSEST, &crossing, &nearest);
    return nearest;
}

// The colour fraction of light the translucent casters on the segment let through (1 without
// any); blocking casters are `rt_occluded`'s.
fn rt_transmittance(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> vec3<f32> {
    var crossing = rt_filter_new();
    var nearest = RtHit(false, tmax, vec2<f32>(0.0));
    let root = rt_translucent[0].hierarchy;
    if root != RT_NO_HIERARCHY {
        rt_walk(root, origin, dir, RT_FILTER, &crossing, &nearest);
    }
    return crossing.light;
}
