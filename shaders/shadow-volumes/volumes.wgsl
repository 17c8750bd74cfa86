// Shadow-volume generation for one light (the shadow-volume library, `zoo-shadow-volumes`).
//
// `triangles`: every shadow-casting triangle gets a weight: +1 when it faces the light, -1 when
// it faces away and belongs to an open (or non-manifold) mesh, whose triangles all block light
// and are oriented toward it, 0 otherwise. Weighted triangles emit a near cap (the triangle
// oriented toward the light) and a far cap (extruded, reversed) unless `params.caps` is 0.
// Vertices are extruded to infinity (w = 0), or by `params.extrusion` where it is not 0.
// `edges`: each edge emits |m| side quads, m = sum over its faces of weight x traversal sign,
// so sides shared by two emitting triangles cancel and boundary or non-manifold edges close
// the volume exactly as per-triangle volumes would.
// Both run once per part of the scene (`Part`): the triangles stored in world space, then each
// instance's shared triangles under its placement, or a stretch of one's triangles or edges.
// A light's parts may come in pieces, each generated into the same buffer and drawn before
// the next: `tally` adds each piece's vertices to the light's total.

#import "common/vertices.wgsl"
#import "common/frame.wgsl"

const FLAG_CASTS: u32 = 1u;
const FLAG_CLOSED: u32 = 2u;
// The triangle is an instance's (shared): the world-space part leaves it out.
const FLAG_PLACED: u32 = 4u;
// `EdgeRecord::info` (host scene crate): the face count below bit 24, the edge kind above.
const EDGE_FACE_COUNT_MASK: u32 = 0x00ffffffu;
const MODE_PER_TRIANGLE: u32 = 1u;
// Invocations per workgroup of both entry points (`WORKGROUP_SIZE` in the library).
const WORKGROUP_SIZE: u32 = 64u;

// The per-light `Params` and per-part `Part` (one dispatch's triangles and edges, and what
// takes their stored vertices to world space) of `zoo_shadow_volumes`.
#import "shadow-volumes/params.wgsl"
#import "shadow-volumes/part.wgsl"

struct DrawArgs {
    vertex_count: atomic<u32>,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
    // The light's counts over its pieces so far.
    silhouette_edges: atomic<u32>,
    total_vertices: u32,
}

@group(1) @binding(0) var<storage, read> vertices: array<f32>;
@group(1) @binding(1) var<storage, read> indices: array<u32>;
@group(1) @binding(2) var<storage, read> edges: array<vec4<u32>>;
@group(1) @binding(3) var<storage, read> edge_faces: array<u32>;
@group(1) @binding(4) var<storage, read> triangle_flags: array<u32>;
@group(1) @binding(5) var<storage, read_write> weights: array<i32>;
@group(1) @binding(6) var<storage, read_write> volume: array<vec4<f32>>;
@group(1) @binding(7) var<storage, read_write> draw: DrawArgs;
@group(2) @binding(0) var<uniform> params: Params;
@group(3) @binding(0) var<uniform> part: Part;

fn position(index: u32) -> vec3<f32> {
    let base = index * VERTEX_FLOATS;
    let stored = vec3<f32>(vertices[base], vertices[base + 1u], vertices[base + 2u]);
    return (part.to_world * vec4<f32>(stored, 1.0)).xyz;
}

fn directional() -> bool {
    return lights[params.light].kind == LIGHT_DIRECTIONAL;
}

// Whether the volume ends in one point (a directional light extruded to infinity): its sides
// are single triangles and it has no far cap (`VolumeShape::collapses` in the library).
fn collapses() -> bool {
    return directional() && params.extrusion <= 0.0;
}

// `p` moved away from the light: to infinity, or by `params.extrusion` where it is finite.
fn extrude(p: vec3<f32>) -> vec4<f32> {
    let light = lights[params.light];
    var away = p - light.position;
    if light.kind == LIGHT_DIRECTIONAL {
        away = light.direction;
    }
    if params.extrusion > 0.0 {
        return vec4<f32>(p + normalize(away) * params.extrusion, 1.0);
    }
    return vec4<f32>(away, 0.0);
}

// The first of `count` vertices in the volume, or 0xffffffff where the piece is full (its
// pieces are planned so that it never is): the count drawn then stays within the buffer.
fn allocate(count: u32) -> u32 {
    let base = atomicAdd(&draw.vertex_count, count);
    if base + count > params.capacity {
        atomicSub(&draw.vertex_count, count);
        return 0xffffffffu;
    }
    return base;
}

fn emit_triangle(base: u32, a: vec4<f32>, b: vec4<f32>, c: vec4<f32>) {
    volume[base] = a;
    volume[base + 1u] = b;
    volume[base + 2u] = c;
}

// Outward side of the volume along the directed edge u -> v of a triangle facing the light.
fn emit_side(u: vec3<f32>, v: vec3<f32>) {
    if collapses() {
        // Both far vertices are the same point at infinity: one triangle.
        let base = allocate(3u);
        if base != 0xffffffffu {
            emit_triangle(base, vec4<f32>(v, 1.0), vec4<f32>(u, 1.0), extrude(u));
        }
        return;
    }
    let base = allocate(6u);
    if base != 0xffffffffu {
        emit_triangle(base, vec4<f32>(v, 1.0), vec4<f32>(u, 1.0), extrude(u));
        emit_triangle(base + 3u, vec4<f32>(v, 1.0), extrude(u), extrude(v));
    }
}

// Near cap of the triangle a b c (oriented toward the light) and, unless the volume collapses,
// the far cap, reversed.
fn emit_caps(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) {
    var count = 3u;
    if !collapses() {
        count = 6u;
    }
    let base = allocate(count);
    if base != 0xffffffffu {
        emit_triangle(base, vec4<f32>(a, 1.0), vec4<f32>(b, 1.0), vec4<f32>(c, 1.0));
        if !collapses() {
            emit_triangle(base + 3u, extrude(a), extrude(c), extrude(b));
        }
    }
}

// Invocation index over a 2D dispatch (more than 65535 workgroups).
fn invocation(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.y * groups.x * WORKGROUP_SIZE + id.x;
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn triangles(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = invocation(id, groups);
    if i >= part.triangle_count {
        return;
    }
    let t = part.first_triangle + i;
    let flags = triangle_flags[t];
    if part.instance == 0u && (flags & FLAG_PLACED) != 0u {
        weights[t] = 0;
        return;
    }
    var a = position(indices[3u * t]);
    var b = position(indices[3u * t + 1u]);
    var c = position(indices[3u * t + 2u]);
    let light = lights[params.light];
    var toward_light = -light.direction;
    if light.kind != LIGHT_DIRECTIONAL {
        toward_light = light.position - (a + b + c) / 3.0;
    }
    let facing = dot(cross(b - a, c - a), toward_light) > 0.0;
    var weight = 0;
    if (flags & FLAG_CASTS) != 0u {
        if facing {
            weight = 1;
        } else if (flags & FLAG_CLOSED) == 0u {
            weight = -1;
        }
    }
    weights[t] = weight;
    if weight == 0 {
        return;
    }
    if weight < 0 {
        let swap = b;
        b = c;
        c = swap;
    }
    if params.caps != 0u {
        emit_caps(a, b, c);
    }
    if params.mode == MODE_PER_TRIANGLE {
        emit_side(a, b);
        emit_side(b, c);
        emit_side(c, a);
    }
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn edges_main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = invocation(id, groups);
    if i >= part.edge_count || params.mode == MODE_PER_TRIANGLE {
        return;
    }
    let e = part.first_edge + i;
    let edge = edges[e];
    let count = edge.w & EDGE_FACE_COUNT_MASK;
    var m = 0;
    for (var k = 0u; k < count; k++) {
        let incidence = edge_faces[edge.z + k];
        let weight = weights[incidence >> 1u];
        if (incidence & 1u) == 1u {
            m -= weight;
        } else {
            m += weight;
        }
    }
    if m == 0 {
        return;
    }
    atomicAdd(&draw.silhouette_edges, 1u);
    let p0 = position(edge.x);
    let p1 = position(edge.y);
    for (var k = 0; k < abs(m); k++) {
        if m > 0 {
            emit_side(p0, p1);
        } else {
            emit_side(p1, p0);
        }
    }
}

// Adds the piece just generated to the light's vertex total (one invocation).
@compute @workgroup_size(1)
fn tally() {
    draw.total_vertices += atomicLoad(&draw.vertex_count);
}
