// Per-triangle shadow volumes over a hierarchy of view samples (Sintorn, Olsson and Assarsson
// 2011; with the sample hierarchy of Sintorn, Kämpe, Olsson and Assarsson 2014). Per light:
//
// 1. `cs_samples`: each pixel's view sample, the hard shadow ray its surface sends to the
//    light (`ray-tracing/shadow_ray.wgsl`, as rt-shadows and the judge send it), and the
//    boxes of the rays' origins over each 8x8 tile of pixels, two clusters a tile split at
//    the middle of its depth range (level 0 of the hierarchy: a tile across a silhouette holds
//    a near and a far cluster, each tight, not one box spanning the gap);
// 2. `cs_reduce1`, `cs_reduce2`: boxes over 8x8 nodes of the level below (64 and 512 pixels);
// 3. `cs_triangles`: every caster triangle's shadow volume (the three planes through
//    the light and its edges, and its own plane) against the hierarchy top down, one
//    workgroup a triangle (its invocations take a node's 64 children at once): a node whose
//    box lies outside one of the planes is skipped, a node wholly inside all four is shadowed
//    whole (for an opaque triangle), and at the leaves each sample's ray is tested exactly
//    against the triangle, alpha mask included (`rt_intersect`, the traversal's own test), a
//    hit marking the pixel shadowed.
//
// Screen tiles are the hierarchy's clusters: a pixel's Morton order is its tile's, and the
// tiles' boxes are tight where the depth is continuous. Instances are visited through their
// placement: the volume's planes are built in the mesh's space and carried to world space, and
// the rays go into the mesh's space as the traversal sends them.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "ray-tracing/casters.wgsl"
#import "ray-tracing/shadow_ray.wgsl"
#import "per-triangle-volumes/ptv_light.wgsl"

@group(2) @binding(0) var<uniform> ptv_light: PtvLight;

// A view sample: its ray's origin and reach, and its direction with its cluster in `w`: 1
// or 2 for its tile's near or far cluster, 0 for pixels the light does not reach, which no
// triangle shadows.
struct ViewSample {
    origin: vec4<f32>,
    direction: vec4<f32>,
}

// (Binding 0: `caster_batches`, `ray-tracing/casters.wgsl`.)
@group(4) @binding(1) var<storage, read_write> view_samples: array<ViewSample>;
// Each node's box (minimum, then maximum), level after level (`level_offset`); level 0 has
// two nodes a tile, its clusters.
@group(4) @binding(2) var<storage, read_write> node_bounds: array<vec4<f32>>;
// 1 where a caster stops the pixel's ray.
@group(4) @binding(3) var<storage, read_write> shadowed: array<atomic<u32>>;
// Per light (`COUNTERS` a light): the triangles that went down the hierarchy, the nodes
// classified, and the samples tested exactly.
@group(4) @binding(4) var<storage, read_write> counts: array<atomic<u32>>;

// Counters a light in `counts` (`COUNTERS` in the plugin).
const COUNTERS: u32 = 3u;
// This invocation's counts, added to `counts` once at its end.
var<private> nodes_classified: u32;
var<private> exact_tests: u32;

// Children per side of a node (and pixels per side of a level-0 node).
const BRANCHING: u32 = 8u;
// Pixels per side of a level-1 and a level-2 node.
const MIDDLE_SPAN: u32 = BRANCHING * BRANCHING;
const TOP_SPAN: u32 = MIDDLE_SPAN * BRANCHING;
// An empty box: its minimum above its maximum.
const EMPTY: f32 = 3.0e38;

fn frame_size() -> vec2<u32> {
    return vec2<u32>(ptv_light.width, ptv_light.height);
}

// Nodes per side of level `level` (0: 8x8-pixel tiles).
fn level_size(level: u32) -> vec2<u32> {
    var span = BRANCHING;
    for (var l = 0u; l < level; l++) {
        span *= BRANCHING;
    }
    return (frame_size() + span - 1u) / span;
}

// Clusters a tile holds (level-0 nodes a tile).
const CLUSTERS: u32 = 2u;

// The first node of level `level` in `node_bounds` (two entries a node).
fn level_offset(level: u32) -> u32 {
    var offset = 0u;
    for (var l = 0u; l < level; l++) {
        let size = level_size(l);
        offset += size.x * size.y * select(1u, CLUSTERS, l == 0u);
    }
    return offset;
}

var<workgroup> group_min: array<vec3<f32>, 64>;
var<workgroup> group_max: array<vec3<f32>, 64>;
var<workgroup> group_depth: array<vec2<f32>, 64>;
var<workgroup> group_split: f32;

// Writes the box over the workgroup's 64 boxes (`lo`, `hi` of this invocation) as node
// `node`.
fn store_group_box(local: u32, lo: vec3<f32>, hi: vec3<f32>, node: u32) {
    // (The workgroup's arrays may still be read for the node before.)
    workgroupBarrier();
    group_min[local] = lo;
    group_max[local] = hi;
    workgroupBarrier();
    if local == 0u {
        var low = lo;
        var high = hi;
        for (var k = 1u; k < 64u; k++) {
            low = min(low, group_min[k]);
            high = max(high, group_max[k]);
        }
        node_bounds[2u * node] = vec4<f32>(low, 0.0);
        node_bounds[2u * node + 1u] = vec4<f32>(high, 0.0);
    }
}

@compute @workgroup_size(8, 8)
fn cs_samples(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(workgroup_id) tile: vec3<u32>,
) {
    let size = frame_size();
    let inside = all(id.xy < size);
    let pixel = id.y * size.x + id.x;
    var sample = ViewSample(vec4<f32>(0.0), vec4<f32>(0.0));
    var depth = vec2<f32>(EMPTY, -EMPTY);
    if all(id == vec3<u32>(0u)) {
        for (var k = 0u; k < COUNTERS; k++) {
            atomicStore(&counts[COUNTERS * ptv_light.light + k], 0u);
        }
    }
    if inside {
        atomicStore(&shadowed[pixel], 0u);
        let s = load_surface(vec2<i32>(id.xy));
        let light = lights[ptv_light.light];
        if s.valid && light_falloff(light, s.position) > 0.0 {
            let ray = hard_shadow_ray(s, light);
            sample = ViewSample(vec4<f32>(ray.origin, ray.reach), vec4<f32>(ray.direction, 1.0));
            depth = vec2<f32>(distance(ray.origin, camera.position));
        }
    }
    // The tile's depth range, split in the middle.
    group_depth[local] = depth;
    workgroupBarrier();
    if local == 0u {
        var range = depth;
        for (var k = 1u; k < 64u; k++) {
            range = vec2<f32>(min(range.x, group_depth[k].x), max(range.y, group_depth[k].y));
        }
        group_split = (range.x + range.y) * 0.5;
    }
    let split = workgroupUniformLoad(&group_split);
    let far = u32(depth.x > split);
    if sample.direction.w != 0.0 {
        sample.direction.w = f32(1u + far);
    }
    if inside {
        view_samples[pixel] = sample;
    }
    let node = CLUSTERS * (tile.y * level_size(0u).x + tile.x);
    for (var cluster = 0u; cluster < CLUSTERS; cluster++) {
        let member = sample.direction.w == f32(1u + cluster);
        let lo = select(vec3<f32>(EMPTY), sample.origin.xyz, member);
        let hi = select(vec3<f32>(-EMPTY), sample.origin.xyz, member);
        store_group_box(local, lo, hi, node + cluster);
    }
}

// One node of level `level` from its 8x8 children of the level below.
fn reduce(level: u32, local: vec3<u32>, index: u32, node: vec3<u32>) {
    let below = level_size(level - 1u);
    let child = node.xy * BRANCHING + local.xy;
    var lo = vec3<f32>(EMPTY);
    var hi = vec3<f32>(-EMPTY);
    if all(child < below) {
        // A tile's clusters, or one node of the levels above.
        let count = select(1u, CLUSTERS, level == 1u);
        let first = level_offset(level - 1u) + (child.y * below.x + child.x) * count;
        for (var k = first; k < first + count; k++) {
            lo = min(lo, node_bounds[2u * k].xyz);
            hi = max(hi, node_bounds[2u * k + 1u].xyz);
        }
    }
    store_group_box(index, lo, hi, level_offset(level) + node.y * level_size(level).x + node.x);
}

@compute @workgroup_size(8, 8)
fn cs_reduce1(
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
    @builtin(workgroup_id) node: vec3<u32>,
) {
    reduce(1u, local, index, node);
}

@compute @workgroup_size(8, 8)
fn cs_reduce2(
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
    @builtin(workgroup_id) node: vec3<u32>,
) {
    reduce(2u, local, index, node);
}

// A triangle's shadow volume as four world-space planes (normal, offset): a point x is inside
// where dot(normal, x) + offset >= 0 for all four. A plane with a zero normal culls nothing.
struct Volume {
    planes: array<vec4<f32>, 4>,
    // With the light on the triangle's plane (which then decides no side), that plane: a
    // ray can meet the triangle only from within its rounding of it. Zero otherwise.
    slab: vec4<f32>,
}

// The plane through `p` with local normal `n`, carried to world space through `to_local`
// (rows of the world-to-mesh placement).
fn world_plane(n: vec3<f32>, p: vec3<f32>, to_local: array<vec4<f32>, 3>) -> vec4<f32> {
    let normal = to_local[0].xyz * n.x + to_local[1].xyz * n.y + to_local[2].xyz * n.z;
    let shift = vec3<f32>(to_local[0].w, to_local[1].w, to_local[2].w);
    return vec4<f32>(normal, dot(n, shift - p));
}

// `n` turned to the side of `toward` from `p` (zero where `toward` lies on its plane).
fn facing(n: vec3<f32>, p: vec3<f32>, toward: vec3<f32>) -> vec3<f32> {
    let side = dot(n, toward - p);
    return select(select(-n, n, side > 0.0), vec3<f32>(0.0), side == 0.0);
}

// The volume of triangle (a, b, c), in mesh space, lit from local `light`: a position (w 1)
// or a direction toward the light (w 0).
fn volume_of(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, light: vec4<f32>, to_local: array<vec4<f32>, 3>) -> Volume {
    var corners = array<vec3<f32>, 3>(a, b, c);
    var volume: Volume;
    for (var k = 0u; k < 3u; k++) {
        let p = corners[k];
        let q = corners[(k + 1u) % 3u];
        let r = corners[(k + 2u) % 3u];
        let toward_light = select(light.xyz, light.xyz - p, light.w == 1.0);
        volume.planes[k] = world_plane(facing(cross(q - p, toward_light), p, r), p, to_local);
    }
    // Beyond the triangle from the light.
    let n = cross(b - a, c - a);
    let light_side = select(a + light.xyz, light.xyz, light.w == 1.0);
    let beyond = -facing(n, a, light_side);
    volume.planes[3] = world_plane(beyond, a, to_local);
    volume.slab = select(vec4<f32>(0.0), world_plane(n, a, to_local), all(beyond == vec3<f32>(0.0)));
    return volume;
}

// Where a node's box lies against a volume.
const OUTSIDE: u32 = 0u;
const STRADDLING: u32 = 1u;
const INSIDE: u32 = 2u;

// Where node `node`'s box lies against `volume`, conservatively (the box grown by the planes'
// rounding): outside one of its planes, inside all four, or straddling (also where the
// hierarchy is off). Empty nodes are outside.
fn classify(volume: Volume, node: u32) -> u32 {
    nodes_classified += 1u;
    let low = node_bounds[2u * node].xyz;
    let high = node_bounds[2u * node + 1u].xyz;
    if any(low > high) {
        return OUTSIDE;
    }
    if ptv_light.hierarchy == 0u {
        return STRADDLING;
    }
    let centre = (low + high) * 0.5;
    let extent = (high - low) * 0.5;
    let slab = volume.slab;
    if any(slab.xyz != vec3<f32>(0.0)) {
        let rounding = 1e-4 * (dot(abs(slab.xyz), abs(centre) + extent) + abs(slab.w));
        if abs(dot(slab.xyz, centre) + slab.w) > dot(abs(slab.xyz), extent) + rounding {
            return OUTSIDE;
        }
    }
    var inside = true;
    for (var k = 0u; k < 4u; k++) {
        let plane = volume.planes[k];
        let reach = dot(abs(plane.xyz), extent);
        let value = dot(plane.xyz, centre) + plane.w;
        let rounding = 1e-4 * (dot(abs(plane.xyz), abs(centre) + extent) + abs(plane.w));
        if value + reach < -rounding {
            return OUTSIDE;
        }
        // A plane with no normal (the light on it) decides nothing: never wholly inside.
        inside = inside && value - reach > rounding && any(plane.xyz != vec3<f32>(0.0));
    }
    return select(STRADDLING, INSIDE, inside);
}

// Whether a sample whose direction's `w` is `tag` belongs to `cluster` (0 or 1, or
// `ANY_CLUSTER`): the light reaches it, and it is of that cluster.
fn member_of(tag: f32, cluster: u32) -> bool {
    return tag != 0.0 && (cluster == ANY_CLUSTER || tag == f32(1u + cluster));
}

// Every cluster of a region (`shadow_region`).
const ANY_CLUSTER: u32 = 0xffffffffu;

// Marks the samples of `cluster` in the `span` x `span` pixels from `first` shadowed, the
// workgroup's invocations sharing the pixels: a node wholly inside an opaque triangle's
// volume, whose every ray crosses the triangle.
fn shadow_region(first: vec2<u32>, span: u32, cluster: u32, lane: u32) {
    // (The part of the region within the frame.)
    let extent = min(first + span, frame_size()) - first;
    for (var k = lane; k < extent.x * extent.y; k += GROUP) {
        shadow_sample(first + vec2<u32>(k % extent.x, k / extent.x), cluster);
    }
}

// Marks the sample of pixel `p` shadowed if it is of `cluster`.
fn shadow_sample(p: vec2<u32>, cluster: u32) {
    let size = frame_size();
    let pixel = p.y * size.x + p.x;
    if all(p < size) && member_of(view_samples[pixel].direction.w, cluster) {
        atomicStore(&shadowed[pixel], 1u);
    }
}

// Whether point `p` may lie in `volume` (within the planes' rounding): the cheap test that
// spares most samples of a straddling tile the exact one.
fn may_hold(volume: Volume, p: vec3<f32>) -> bool {
    let slab = volume.slab;
    if abs(dot(slab.xyz, p) + slab.w) > 1e-4 * (dot(abs(slab.xyz), abs(p)) + abs(slab.w)) {
        return false;
    }
    for (var k = 0u; k < 4u; k++) {
        let plane = volume.planes[k];
        let rounding = 1e-4 * (dot(abs(plane.xyz), abs(p)) + abs(plane.w));
        if dot(plane.xyz, p) + plane.w < -rounding {
            return false;
        }
    }
    return true;
}

// The caster triangle a workgroup tests (its index and placement), its volume and whether it
// is opaque.
struct Caster {
    triangle: CasterTriangle,
    volume: Volume,
    // Whether the triangle comes within the light's range (a point or spot light's samples
    // all lie within it, so a triangle beyond it stops no ray).
    in_range: bool,
    opaque: bool,
}

// Tests the sample of pixel `p` of `cluster` that may lie in the caster's volume exactly
// against the caster.
fn test_sample(p: vec2<u32>, cluster: u32, caster: Caster) {
    let size = frame_size();
    if any(p >= size) {
        return;
    }
    let pixel = p.y * size.x + p.x;
    let sample = view_samples[pixel];
    if !member_of(sample.direction.w, cluster) || atomicLoad(&shadowed[pixel]) != 0u {
        return;
    }
    if ptv_light.hierarchy != 0u && !may_hold(caster.volume, sample.origin.xyz) {
        return;
    }
    exact_tests += 1u;
    if caster_blocks(caster.triangle, sample.origin.xyz, sample.direction.xyz, sample.origin.w) {
        atomicStore(&shadowed[pixel], 1u);
    }
}

// Workgroups of `cs_triangles` (`TRIANGLE_GROUPS` in the plugin): each takes 64 triangles in
// turn, every `TRIANGLE_GROUPS`-th 64; enough workgroups to fill a GPU, and few enough that
// starting them costs little on a CPU's.
const TRIANGLE_GROUPS: u32 = 2048u;
// Invocations of a `cs_triangles` workgroup: one a child of a node, one a pixel of a tile.
const GROUP: u32 = 64u;
// A queue entry's flag: the node lies wholly inside the volume (else it straddles it).
const WHOLLY_INSIDE: u32 = 0x80000000u;

// The caster, loaded once for the workgroup.
var<workgroup> caster_shared: Caster;
// A class decided by one invocation for all.
var<workgroup> class_shared: u32;
// The middle nodes of the current top node that the volume reaches, and their count.
var<workgroup> middle_queue: array<u32, GROUP>;
var<workgroup> middle_count: atomic<u32>;
// The level-0 clusters of the current middle node that the volume reaches, and their count.
var<workgroup> cluster_queue: array<u32, 128>;
var<workgroup> cluster_count: atomic<u32>;
// The triangles of the workgroup's current 64 that reach the hierarchy, and their count.
var<workgroup> triangle_queue: array<u32, GROUP>;
var<workgroup> triangle_count: atomic<u32>;
// A queue's length, read by one invocation for all.
var<workgroup> count_shared: u32;

// Whether triangle (a, b, c) in mesh space may come within `range` (in world space) of the
// light at `light` (in mesh space): its bounding sphere against the range, stretched by the
// most that world-to-mesh placement `m` can stretch a length (its Frobenius norm bounds that).
fn within_range(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, light: vec3<f32>, range: f32, m: array<vec4<f32>, 3>) -> bool {
    let centre = (a + b + c) / 3.0;
    let radius = sqrt(max(distance_sq(a, centre), max(distance_sq(b, centre), distance_sq(c, centre))));
    let stretch = sqrt(dot(m[0].xyz, m[0].xyz) + dot(m[1].xyz, m[1].xyz) + dot(m[2].xyz, m[2].xyz));
    // (With the planes' rounding to spare.)
    return distance(centre, light) - radius <= range * stretch * 1.001;
}

fn distance_sq(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return dot(a - b, a - b);
}

// Caster triangle number `flat` of the flat list, with its volume from the frame's light.
fn load_caster(flat: u32) -> Caster {
    var caster: Caster;
    caster.triangle = caster_triangle(flat);
    let m = caster.triangle.to_local;
    let light = lights[ptv_light.light];
    var local_light: vec4<f32>;
    if light.kind == LIGHT_DIRECTIONAL {
        let w = -light.direction;
        local_light = vec4<f32>(dot(m[0].xyz, w), dot(m[1].xyz, w), dot(m[2].xyz, w), 0.0);
    } else {
        let o = vec4<f32>(light.position, 1.0);
        local_light = vec4<f32>(dot(m[0], o), dot(m[1], o), dot(m[2], o), 1.0);
    }
    let tri = rt_triangles[caster.triangle.index];
    caster.volume = volume_of(tri.v0, tri.v0 + tri.e1, tri.v0 + tri.e2, local_light, m);
    caster.in_range = light.kind == LIGHT_DIRECTIONAL || within_range(tri.v0, tri.v0 + tri.e1, tri.v0 + tri.e2, local_light.xyz, light.range, m);
    // Wholly inside the volume of an opaque triangle, every ray crosses it; a masked one's
    // rays are each tested at their crossing's texture coordinates.
    caster.opaque = tri.mask_layer < 0;
    return caster;
}

// Whether `volume` reaches any of the `count` nodes from `first` (is not outside all).
fn reaches_a_node(volume: Volume, first: u32, count: u32) -> bool {
    for (var node = first; node < first + count; node++) {
        if classify(volume, node) != OUTSIDE {
            return true;
        }
    }
    return false;
}

// Whether any of the `count` nodes from `first` holds a sample (is not empty).
fn any_sample(first: u32, count: u32) -> bool {
    for (var node = first; node < first + count; node++) {
        if all(node_bounds[2u * node].xyz <= node_bounds[2u * node + 1u].xyz) {
            return true;
        }
    }
    return false;
}

// Each workgroup takes caster triangles 64 at a time: each invocation drops its triangle if it
// is out of the light's range or its volume misses every top node, and the rest go down the
// hierarchy one at a time: the top nodes one after another, the 64 middle children of a top
// node the volume reaches one an invocation, then the 8x8 tiles (two clusters each) of each
// middle node it reaches one an invocation, then the pixels of each cluster it reaches, shared
// out over the invocations. Nodes wholly inside an opaque triangle's volume are shadowed whole;
// the samples of the clusters it straddles are tested exactly.
@compute @workgroup_size(64)
fn cs_triangles(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let top = level_size(2u);
    let middle = level_size(1u);
    let bottom = level_size(0u);
    let top_offset = level_offset(2u);
    let middle_offset = level_offset(1u);
    // A light that reaches no sample: nothing to shadow.
    if lane == 0u {
        class_shared = u32(any_sample(top_offset, top.x * top.y));
    }
    if workgroupUniformLoad(&class_shared) == 0u {
        return;
    }
    for (var first = group.x * GROUP; first < ptv_light.triangles; first += TRIANGLE_GROUPS * GROUP) {
        // The workgroup's next 64 triangles, one an invocation: those in the light's range
        // whose volume reaches a top node are queued.
        if lane == 0u {
            atomicStore(&triangle_count, 0u);
        }
        workgroupBarrier();
        if first + lane < ptv_light.triangles {
            let candidate = load_caster(first + lane);
            if candidate.in_range && reaches_a_node(candidate.volume, top_offset, top.x * top.y) {
                triangle_queue[atomicAdd(&triangle_count, 1u)] = first + lane;
            }
        }
        workgroupBarrier();
        if lane == 0u {
            count_shared = atomicLoad(&triangle_count);
        }
        let queued = workgroupUniformLoad(&count_shared);
        if lane == 0u {
            atomicAdd(&counts[COUNTERS * ptv_light.light], queued);
        }
        for (var q = 0u; q < queued; q++) {
            if lane == 0u {
                caster_shared = load_caster(triangle_queue[q]);
            }
            let caster = workgroupUniformLoad(&caster_shared);
            for (var t = 0u; t < top.x * top.y; t++) {
                let tile = vec2<u32>(t % top.x, t / top.x);
                if lane == 0u {
                    class_shared = classify(caster.volume, top_offset + t);
                }
                let top_class = workgroupUniformLoad(&class_shared);
                if top_class == OUTSIDE {
                    continue;
                }
                if top_class == INSIDE && caster.opaque {
                    shadow_region(tile * TOP_SPAN, TOP_SPAN, ANY_CLUSTER, lane);
                    continue;
                }
                // The top node's middle children, one an invocation.
                if lane == 0u {
                    atomicStore(&middle_count, 0u);
                }
                workgroupBarrier();
                let m = tile * BRANCHING + vec2<u32>(lane % BRANCHING, lane / BRANCHING);
                if all(m < middle) {
                    let node = m.y * middle.x + m.x;
                    let node_class = classify(caster.volume, middle_offset + node);
                    if node_class != OUTSIDE {
                        let inside = select(0u, WHOLLY_INSIDE, node_class == INSIDE && caster.opaque);
                        middle_queue[atomicAdd(&middle_count, 1u)] = node | inside;
                    }
                }
                workgroupBarrier();
                if lane == 0u {
                    count_shared = atomicLoad(&middle_count);
                }
                let middles = workgroupUniformLoad(&count_shared);
                for (var i = 0u; i < middles; i++) {
                    let entry = workgroupUniformLoad(&middle_queue[i]);
                    let node = entry & ~WHOLLY_INSIDE;
                    let mid = vec2<u32>(node % middle.x, node / middle.x);
                    if (entry & WHOLLY_INSIDE) != 0u {
                        shadow_region(mid * MIDDLE_SPAN, MIDDLE_SPAN, ANY_CLUSTER, lane);
                        continue;
                    }
                    // The middle node's tiles, one an invocation, both clusters of each.
                    if lane == 0u {
                        atomicStore(&cluster_count, 0u);
                    }
                    workgroupBarrier();
                    let b = mid * BRANCHING + vec2<u32>(lane % BRANCHING, lane / BRANCHING);
                    if all(b < bottom) {
                        for (var c = 0u; c < CLUSTERS; c++) {
                            let cluster = CLUSTERS * (b.y * bottom.x + b.x) + c;
                            let node_class = classify(caster.volume, cluster);
                            if node_class != OUTSIDE {
                                let inside = select(0u, WHOLLY_INSIDE, node_class == INSIDE && caster.opaque);
                                cluster_queue[atomicAdd(&cluster_count, 1u)] = cluster | inside;
                            }
                        }
                    }
                    workgroupBarrier();
                    if lane == 0u {
                        count_shared = atomicLoad(&cluster_count);
                    }
                    let clusters = workgroupUniformLoad(&count_shared);
                    // The queued clusters' pixels, shared out over the invocations.
                    for (var k = lane; k < clusters * GROUP; k += GROUP) {
                        let entry = cluster_queue[k / GROUP];
                        let cluster = entry & ~WHOLLY_INSIDE;
                        let tile_index = cluster / CLUSTERS;
                        let corner = vec2<u32>(tile_index % bottom.x, tile_index / bottom.x) * BRANCHING;
                        let p = corner + vec2<u32>(k % BRANCHING, (k % GROUP) / BRANCHING);
                        if (entry & WHOLLY_INSIDE) != 0u {
                            shadow_sample(p, cluster % CLUSTERS);
                        } else {
                            test_sample(p, cluster % CLUSTERS, caster);
                        }
                    }
                    // (The queue is refilled for the next middle node.)
                    workgroupBarrier();
                }
                workgroupBarrier();
            }
            // (`caster_shared` is loaded again for the next triangle.)
            workgroupBarrier();
        }
        // (The queue is refilled for the next triangles.)
        workgroupBarrier();
    }
    if nodes_classified > 0u {
        atomicAdd(&counts[COUNTERS * ptv_light.light + 1u], nodes_classified);
    }
    if exact_tests > 0u {
        atomicAdd(&counts[COUNTERS * ptv_light.light + 2u], exact_tests);
    }
}
