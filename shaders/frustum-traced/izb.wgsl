// Frustum-traced shadows over an irregular z-buffer (Wyman, Hoetzlein and Lefohn, I3D 2015 and
// TVCG 2016). Per light:
//
// 1. `cs_samples`: each pixel's view sample, the hard shadow ray its surface sends to the
//    light (`ray-tracing/shadow_ray.wgsl`, as rt-shadows and the judge send it), and where the
//    ray meets the light's image plane: for the sun one plane across its direction, for point
//    and spot lights the six faces of a cube around the light (a ray to the light's centre is
//    one point of a face). The samples' extent on each plane is fitted as they are placed
//    (atomic minima and maxima, read by `view_bounds`), so the grid covers what the camera sees,
//    not the scene.
// 2. `cs_insert`: each sample joins the list of its grid texel (a head per texel, a link per
//    sample): the irregular z-buffer, whose texels hold the exact points the eye sees.
// 3. `cs_triangles`: every caster triangle is rasterised conservatively on each plane: the
//    rectangle of texels its projection (clipped to a cube face's pyramid) can touch, widened
//    by the projections' rounding, so every sample whose ray crosses the triangle is in a list
//    it visits. Each sample of those lists is tested exactly against the triangle in world
//    space (the ray tracer's own triangle test, alpha mask at the crossing's texture
//    coordinates included). Triangles over more than `SMALL_RECT` texels are queued for
//    `cs_big_triangles`, where a workgroup shares one triangle's texels; past the queue's
//    capacity they are walked where they are (slower, as exact).
//
// Instances are visited through their placement: corners to world space for the rectangle,
// rays to the mesh's space for the test (`ray-tracing/casters.wgsl`).

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "ray-tracing/casters.wgsl"
#import "ray-tracing/shadow_ray.wgsl"
#import "frustum-traced/ft_light.wgsl"

@group(2) @binding(0) var<uniform> ft_light: FtLight;

// A view sample: its ray's origin and reach, and its direction with its plane in `w` (1 + the
// view's number; 0 for pixels the light does not reach, which no triangle shadows).
struct ViewSample {
    origin: vec4<f32>,
    direction: vec4<f32>,
}

// (Binding 0: `caster_batches`, `ray-tracing/casters.wgsl`.)
@group(4) @binding(1) var<storage, read_write> view_samples: array<ViewSample>;
// The grid: each view's texels' list heads (1 + the first sample's pixel, 0 for none) at
// `head_index`, their lengths at `length_index`, each pixel's link to the next sample of its
// list at `link_index`, and the queue of large triangles at `queue_index`.
@group(4) @binding(2) var<storage, read_write> grid: array<atomic<u32>>;
// 1 where a caster stops the pixel's ray.
@group(4) @binding(3) var<storage, read_write> shadowed: array<atomic<u32>>;
// `COUNTERS` a light, then the current light's bounds (`BOUNDS` words a view) and the length
// of its queue of large triangles.
@group(4) @binding(4) var<storage, read_write> state: array<atomic<u32>>;

// Counters a light (`COUNTERS` in the plugin): samples inserted, lists walked, samples
// tested exactly, the longest list, large triangles queued, large triangles past the queue.
const COUNTERS: u32 = 6u;
const SAMPLES_INSERTED: u32 = 0u;
const LISTS_WALKED: u32 = 1u;
const EXACT_TESTS: u32 = 2u;
const LONGEST_LIST: u32 = 3u;
const QUEUED: u32 = 4u;
const OVERFLOWED: u32 = 5u;
// Views a light has at most: a cube's faces.
const MAX_VIEWS: u32 = 6u;
// Words of a view's bounds: the order keys of its lowest u and v, inverted, then of its
// highest u and v (`order_key`), all 0 before any sample.
const BOUNDS: u32 = 4u;
// Triangles whose rectangle holds more texels are queued for `cs_big_triangles`.
const SMALL_RECT: u32 = 16u;
// Entries of the queue of large triangles (`QUEUE_CAPACITY` in the plugin).
const QUEUE_CAPACITY: u32 = 65536u;
// Workgroups of `cs_triangles` and of `cs_big_triangles` (in the plugin).
const TRIANGLE_GROUPS: u32 = 2048u;
const BIG_GROUPS: u32 = 512u;
const GROUP: u32 = 64u;

// This invocation's counts, added to `state` once at its end.
var<private> lists_walked: u32;
var<private> exact_tests: u32;

fn frame_size() -> vec2<u32> {
    return vec2<u32>(ft_light.width, ft_light.height);
}

fn texels() -> u32 {
    return ft_light.grid * ft_light.grid;
}

fn head_index(view: u32, texel: u32) -> u32 {
    return view * texels() + texel;
}

fn length_index(view: u32, texel: u32) -> u32 {
    return (MAX_VIEWS + view) * texels() + texel;
}

fn link_index(pixel: u32) -> u32 {
    return 2u * MAX_VIEWS * texels() + pixel;
}

fn queue_index(entry: u32) -> u32 {
    return link_index(ft_light.width * ft_light.height) + entry;
}

fn counter_index(counter: u32) -> u32 {
    return COUNTERS * ft_light.light + counter;
}

fn bounds_index(view: u32) -> u32 {
    return COUNTERS * ft_light.lights + BOUNDS * view;
}

fn queue_length_index() -> u32 {
    return bounds_index(MAX_VIEWS);
}

// A key whose unsigned order is `x`'s order (for atomic minimum and maximum of floats).
fn order_key(x: f32) -> u32 {
    let bits = bitcast<u32>(x);
    return select(bits | 0x80000000u, ~bits, (bits & 0x80000000u) != 0u);
}

fn from_order_key(key: u32) -> f32 {
    return bitcast<f32>(select(~key, key & 0x7fffffffu, (key & 0x80000000u) != 0u));
}

// The sun's image plane: two unit axes across its direction.
fn sun_axes(light: Light) -> array<vec3<f32>, 2> {
    let w = normalize(-light.direction);
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(w.y) < 0.9);
    let right = normalize(cross(helper, w));
    return array<vec3<f32>, 2>(right, cross(w, right));
}

// Point `d` (from a point or spot light) in the frame of cube face `face`: across the face
// (x, y) and along its axis (z, positive in front of the face).
fn face_frame(face: u32, d: vec3<f32>) -> vec3<f32> {
    let axis = face / 2u;
    let sign = select(-1.0, 1.0, face % 2u == 0u);
    return vec3<f32>(d[(axis + 1u) % 3u], d[(axis + 2u) % 3u], sign * d[axis]);
}

// The cube face whose pyramid holds direction `d`: its largest axis (the first of equals).
fn face_of(d: vec3<f32>) -> u32 {
    let a = abs(d);
    var axis = 0u;
    if a.y > a.x && a.y >= a.z {
        axis = 1u;
    } else if a.z > a.x && a.z > a.y {
        axis = 2u;
    }
    return 2u * axis + u32(d[axis] < 0.0);
}

// Where world point `p` lies on the light's image plane `view`, and for point and spot lights
// which face that is.
fn plane_position(light: Light, p: vec3<f32>) -> vec3<f32> {
    if light.kind == LIGHT_DIRECTIONAL {
        let axes = sun_axes(light);
        return vec3<f32>(dot(p, axes[0]), dot(p, axes[1]), 0.0);
    }
    let d = p - light.position;
    let face = face_of(d);
    let f = face_frame(face, d);
    return vec3<f32>(f.xy / f.z, f32(face));
}

// A view's fitted extent on its plane (lowest u, v, highest u, v), and whether any sample lies
// on it.
struct Extent {
    low: vec2<f32>,
    high: vec2<f32>,
    used: bool,
}

fn view_bounds(view: u32) -> Extent {
    let first = bounds_index(view);
    var words: vec4<u32>;
    for (var k = 0u; k < BOUNDS; k++) {
        words[k] = atomicLoad(&state[first + k]);
    }
    return extent_of(words);
}

// The extent that a view's `BOUNDS` words of `state` hold.
fn extent_of(words: vec4<u32>) -> Extent {
    let low = ~words.xy;
    let high = words.zw;
    return Extent(
        vec2<f32>(from_order_key(low.x), from_order_key(low.y)),
        vec2<f32>(from_order_key(high.x), from_order_key(high.y)),
        high.x != 0u,
    );
}

// Texels per unit of the plane across `extent` (the grid spans it; a point gets a width of its
// own).
fn texel_scale(extent: Extent) -> vec2<f32> {
    let span = max(extent.high - extent.low, 1e-6 * (abs(extent.low) + abs(extent.high)) + 1e-30);
    return f32(ft_light.grid) / span;
}

// The texel (column, row) of plane position `uv` on a view of `extent`, clamped to the grid.
fn texel_of(uv: vec2<f32>, extent: Extent) -> vec2<u32> {
    let t = floor((uv - extent.low) * texel_scale(extent));
    return vec2<u32>(clamp(t, vec2<f32>(0.0), vec2<f32>(f32(ft_light.grid - 1u))));
}

@compute @workgroup_size(8, 8)
fn cs_samples(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = frame_size();
    if any(id.xy >= size) {
        return;
    }
    let pixel = id.y * size.x + id.x;
    atomicStore(&shadowed[pixel], 0u);
    var sample = ViewSample(vec4<f32>(0.0), vec4<f32>(0.0));
    let s = load_surface(vec2<i32>(id.xy));
    let light = lights[ft_light.light];
    let ray = hard_shadow_ray(s, light);
    // (A surface at a point light's centre has no direction to it: no sample.)
    if s.valid && light_falloff(light, s.position) > 0.0 && ray.reach > 0.0 {
        let at = plane_position(light, ray.origin);
        let view = u32(at.z);
        sample = ViewSample(vec4<f32>(ray.origin, ray.reach), vec4<f32>(ray.direction, f32(1u + view)));
        let first = bounds_index(view);
        atomicMax(&state[first], ~order_key(at.x));
        atomicMax(&state[first + 1u], ~order_key(at.y));
        atomicMax(&state[first + 2u], order_key(at.x));
        atomicMax(&state[first + 3u], order_key(at.y));
    }
    view_samples[pixel] = sample;
}

@compute @workgroup_size(8, 8)
fn cs_insert(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = frame_size();
    if any(id.xy >= size) {
        return;
    }
    let pixel = id.y * size.x + id.x;
    let sample = view_samples[pixel];
    if sample.direction.w == 0.0 {
        return;
    }
    let light = lights[ft_light.light];
    let view = u32(sample.direction.w) - 1u;
    let uv = plane_position(light, sample.origin.xyz).xy;
    let t = texel_of(uv, view_bounds(view));
    let texel = t.y * ft_light.grid + t.x;
    let next = atomicExchange(&grid[head_index(view, texel)], 1u + pixel);
    atomicStore(&grid[link_index(pixel)], next);
    let length = atomicAdd(&grid[length_index(view, texel)], 1u) + 1u;
    atomicAdd(&state[counter_index(SAMPLES_INSERTED)], 1u);
    atomicMax(&state[counter_index(LONGEST_LIST)], length);
}

// The texels a triangle's projection on a view can touch: the lowest and highest (column,
// row), empty where the first exceeds the second.
struct Rect {
    low: vec2<i32>,
    high: vec2<i32>,
}

const NO_RECT: Rect = Rect(vec2<i32>(1), vec2<i32>(0));

fn rect_texels(rect: Rect) -> u32 {
    let size = max(rect.high - rect.low + 1, vec2<i32>(0));
    return u32(size.x) * u32(size.y);
}

// The texels under plane rectangle [`low`, `high`] on a view of `extent`, widened by the
// projections' rounding.
fn texel_rect(low: vec2<f32>, high: vec2<f32>, extent: Extent) -> Rect {
    let margin = 1e-5 * (abs(low) + abs(high) + (extent.high - extent.low)) + 1e-30;
    let scale = texel_scale(extent);
    let a = floor((low - margin - extent.low) * scale);
    let b = floor((high + margin - extent.low) * scale);
    let last = f32(ft_light.grid - 1u);
    if any(b < vec2<f32>(0.0)) || any(a > vec2<f32>(last)) {
        return NO_RECT;
    }
    return Rect(vec2<i32>(max(a, vec2<f32>(0.0))), vec2<i32>(min(b, vec2<f32>(last))));
}

// A polygon of up to 7 corners (a triangle clipped by four planes, each adding at most one).
struct Polygon {
    corners: array<vec3<f32>, 7>,
    count: u32,
}

// `polygon` clipped to where dot(plane, corner) >= 0.
fn clip(polygon: Polygon, plane: vec3<f32>) -> Polygon {
    var out: Polygon;
    out.count = 0u;
    for (var k = 0u; k < polygon.count; k++) {
        let a = polygon.corners[k];
        let b = polygon.corners[(k + 1u) % polygon.count];
        let da = dot(plane, a);
        let db = dot(plane, b);
        if da >= 0.0 {
            out.corners[out.count] = a;
            out.count += 1u;
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.corners[out.count] = a + (b - a) * (da / (da - db));
            out.count += 1u;
        }
    }
    return out;
}

// The texels of view `view` (of `extent`) that the triangle with world `corners` can cover.
fn triangle_rect(light: Light, view: u32, extent: Extent, corners: array<vec3<f32>, 3>) -> Rect {
    if !extent.used {
        return NO_RECT;
    }
    var low = vec2<f32>(3.0e38);
    var high = vec2<f32>(-3.0e38);
    if light.kind == LIGHT_DIRECTIONAL {
        for (var k = 0u; k < 3u; k++) {
            let uv = plane_position(light, corners[k]).xy;
            low = min(low, uv);
            high = max(high, uv);
        }
        return texel_rect(low, high, extent);
    }
    // The triangle against the face's pyramid (widened by the rounding): skipped where its
    // corners all lie outside one side, projected as it is where they all lie inside, clipped
    // to the pyramid where it crosses a side.
    let wide = 1.0 + 1e-5;
    let sides = array<vec3<f32>, 4>(
        vec3<f32>(-1.0, 0.0, wide),
        vec3<f32>(1.0, 0.0, wide),
        vec3<f32>(0.0, -1.0, wide),
        vec3<f32>(0.0, 1.0, wide),
    );
    let a = face_frame(view, corners[0] - light.position);
    let b = face_frame(view, corners[1] - light.position);
    let c = face_frame(view, corners[2] - light.position);
    var inside = min(a.z, min(b.z, c.z)) > 0.0;
    for (var k = 0u; k < 4u; k++) {
        let side = vec3<f32>(dot(sides[k], a), dot(sides[k], b), dot(sides[k], c));
        if all(side < vec3<f32>(0.0)) {
            return NO_RECT;
        }
        inside = inside && all(side >= vec3<f32>(0.0));
    }
    if inside {
        low = min(a.xy / a.z, min(b.xy / b.z, c.xy / c.z));
        high = max(a.xy / a.z, max(b.xy / b.z, c.xy / c.z));
        return texel_rect(low, high, extent);
    }
    var polygon: Polygon;
    polygon.count = 3u;
    polygon.corners[0] = a;
    polygon.corners[1] = b;
    polygon.corners[2] = c;
    for (var k = 0u; k < 4u; k++) {
        polygon = clip(polygon, sides[k]);
    }
    if polygon.count == 0u {
        return NO_RECT;
    }
    for (var k = 0u; k < polygon.count; k++) {
        let c = polygon.corners[k];
        if c.z > 0.0 {
            let uv = clamp(c.xy / c.z, vec2<f32>(-wide), vec2<f32>(wide));
            low = min(low, uv);
            high = max(high, uv);
        } else {
            // The triangle passes through the light: every direction of the face is near.
            low = vec2<f32>(-wide);
            high = vec2<f32>(wide);
        }
    }
    return texel_rect(low, high, extent);
}

// Tests every sample in the list of `texel` of `view` not yet shadowed against `caster`.
fn walk_list(view: u32, texel: u32, caster: CasterTriangle) {
    lists_walked += 1u;
    var node = atomicLoad(&grid[head_index(view, texel)]);
    while node != 0u {
        let pixel = node - 1u;
        node = atomicLoad(&grid[link_index(pixel)]);
        if atomicLoad(&shadowed[pixel]) != 0u {
            continue;
        }
        let sample = view_samples[pixel];
        exact_tests += 1u;
        if caster_blocks(caster, sample.origin.xyz, sample.direction.xyz, sample.origin.w) {
            atomicStore(&shadowed[pixel], 1u);
        }
    }
}

// Walks the texels of `rect` from the `first`-th, every `step`-th.
fn walk_rect(view: u32, rect: Rect, caster: CasterTriangle, first: u32, step: u32) {
    let width = u32(rect.high.x - rect.low.x + 1);
    for (var k = first; k < rect_texels(rect); k += step) {
        let t = vec2<u32>(rect.low) + vec2<u32>(k % width, k / width);
        walk_list(view, t.y * ft_light.grid + t.x, caster);
    }
}

fn add_counts() {
    if lists_walked > 0u {
        atomicAdd(&state[counter_index(LISTS_WALKED)], lists_walked);
    }
    if exact_tests > 0u {
        atomicAdd(&state[counter_index(EXACT_TESTS)], exact_tests);
    }
}

// Views of the light: one plane for the sun, six faces otherwise.
fn light_views(light: Light) -> u32 {
    return select(MAX_VIEWS, 1u, light.kind == LIGHT_DIRECTIONAL);
}

// Each invocation takes caster triangles in turn: on each view, a small rectangle of texels
// is walked here and a large one queued.
@compute @workgroup_size(GROUP)
fn cs_triangles(@builtin(global_invocation_id) id: vec3<u32>) {
    let light = lights[ft_light.light];
    let views = light_views(light);
    for (var flat = id.x; flat < ft_light.triangles; flat += TRIANGLE_GROUPS * GROUP) {
        let caster = caster_triangle(flat);
        let corners = caster_world_corners(caster);
        for (var view = 0u; view < views; view++) {
            let rect = triangle_rect(light, view, view_bounds(view), corners);
            let count = rect_texels(rect);
            if count == 0u {
                continue;
            }
            if count > SMALL_RECT {
                let entry = atomicAdd(&state[queue_length_index()], 1u);
                if entry < QUEUE_CAPACITY {
                    atomicStore(&grid[queue_index(entry)], flat * MAX_VIEWS + view);
                    continue;
                }
                atomicAdd(&state[counter_index(OVERFLOWED)], 1u);
            }
            walk_rect(view, rect, caster, 0u, 1u);
        }
    }
    add_counts();
}

// Each workgroup takes queued large triangles in turn, its invocations sharing the texels.
@compute @workgroup_size(GROUP)
fn cs_big_triangles(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let light = lights[ft_light.light];
    let queued = min(atomicLoad(&state[queue_length_index()]), QUEUE_CAPACITY);
    if group.x == 0u && lane == 0u {
        atomicAdd(&state[counter_index(QUEUED)], queued);
    }
    for (var entry = group.x; entry < queued; entry += BIG_GROUPS) {
        let packed = atomicLoad(&grid[queue_index(entry)]);
        let view = packed % MAX_VIEWS;
        let caster = caster_triangle(packed / MAX_VIEWS);
        let rect = triangle_rect(light, view, view_bounds(view), caster_world_corners(caster));
        walk_rect(view, rect, caster, lane, GROUP);
    }
    add_counts();
}

// The debug views of the light whose passes ran last (the plugin runs them for `debug_light`):
// each pixel's list length, and each texel's (the views stacked from the top).
@group(4) @binding(5) var list_length: texture_storage_2d<r32uint, write>;
@group(4) @binding(6) var samples_per_texel: texture_storage_2d<r32uint, write>;

@compute @workgroup_size(8, 8)
fn cs_list_length(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = frame_size();
    if any(id.xy >= size) {
        return;
    }
    let sample = view_samples[id.y * size.x + id.x];
    var length = 0u;
    if sample.direction.w != 0.0 {
        let view = u32(sample.direction.w) - 1u;
        let uv = plane_position(lights[ft_light.light], sample.origin.xyz).xy;
        let t = texel_of(uv, view_bounds(view));
        length = atomicLoad(&grid[length_index(view, t.y * ft_light.grid + t.x)]);
    }
    textureStore(list_length, id.xy, vec4<u32>(length));
}

@compute @workgroup_size(8, 8)
fn cs_samples_per_texel(@builtin(global_invocation_id) id: vec3<u32>) {
    let g = ft_light.grid;
    if id.x >= g || id.y >= MAX_VIEWS * g {
        return;
    }
    let view = id.y / g;
    var length = 0u;
    // (The lists of views the light lacks are not cleared for it.)
    if view < light_views(lights[ft_light.light]) {
        length = atomicLoad(&grid[length_index(view, (id.y % g) * g + id.x)]);
    }
    textureStore(samples_per_texel, id.xy, vec4<u32>(length));
}
