// Hybrid shadows, pass 2: classify every pixel from its shadow-map neighbourhood
// ((2r + 1)² nearest depth comparisons one texel apart): all lit is lit, all shadowed is
// shadowed, mixed is the edge band. So is a pixel the samples call lit whose own light ray may
// cross a caster thinner than a texel, which the samples miss: the coverage maps
// (`hybrid-edge/coverage.wgsl`) hold the nearest depth of any caster touching each texel. Lit
// and shadowed pixels get their visibility here.
// Edge pixels are resolved exactly, depending on the restriction:
// - depth band (`fs_band`): edge pixels are left lit and get their own depth in the band's
//   depth image (every other pixel holds 1), so the shadow volumes drawn next are rejected
//   outside the band by the depth test; `everywhere` puts every pixel in the band, and
//   `tiles` also draws the volumes only in the screen tiles that hold edge pixels
//   (`hybrid-edge/tiles.wgsl`), and `stencil` marks the band in the stencil, where the
//   volumes are then counted (`hybrid-edge/mark.wgsl`);
// - triangle ids (`fs_band_ids`): the light ray of an edge pixel is tested against the
//   triangles the shadow map saw nearest the light in the pixel's neighbourhood (seed 003's
//   future-work idea): no volumes at all.

#import "common/vertices.wgsl"
#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/fullscreen.wgsl"
#import "shadow-maps/receiver.wgsl"
#import "shadow-maps/depth_lookup.wgsl"

// One light's header, band radius, restriction and coverage switch (`EdgeLight` in the
// plugin's Rust).
#import "hybrid-edge/edge_light.wgsl"

// Restrictions, one per variant of the Rust `Restriction` parameter.
const RESTRICTION_DEPTHBAND: u32 = 0u;
const RESTRICTION_EVERYWHERE: u32 = 1u;
const RESTRICTION_TRIANGLEIDS: u32 = 2u;
const RESTRICTION_TILES: u32 = 3u;
// The band as for the depth band; the volume passes mark it in the stencil and test that.
const RESTRICTION_STENCIL: u32 = 4u;

@group(2) @binding(0) var<uniform> edge: EdgeLight;
// In the lookup group, after its bindings: the coverage maps (laid out like the depth maps):
// the id of the triangle nearest the light among those touching each texel (NO_TRIANGLE where
// none); the scene's vertices (`VERTEX_FLOATS` floats each) and indices.
@group(3) @binding(6) var coverage_ids: texture_2d_array<u32>;
@group(3) @binding(7) var<storage, read> scene_vertices: array<f32>;
@group(3) @binding(8) var<storage, read> scene_indices: array<u32>;

const CLASS_LIT: vec4<f32> = vec4<f32>(0.95, 0.9, 0.6, 1.0);
const CLASS_SHADOWED: vec4<f32> = vec4<f32>(0.15, 0.2, 0.45, 1.0);
const CLASS_EDGE: vec4<f32> = vec4<f32>(1.0, 0.2, 0.2, 1.0);

// Number of lit taps in the (2r + 1)² neighbourhood of p.
fn lit_taps(light: Light, p: vec3<f32>, texel: f32) -> u32 {
    var w = light.direction;
    if light.kind != LIGHT_DIRECTIONAL {
        w = normalize(p - light.position);
    }
    let frame = tangent_frame(w);
    let r = i32(edge.radius);
    var lit = 0u;
    for (var j = -r; j <= r; j++) {
        for (var i = -r; i <= r; i++) {
            let q = p + (frame[0] * f32(i) + frame[1] * f32(j)) * texel;
            let layer = header_layer(edge.map, q);
            lit += u32(compare_map(map_point(layer, q), false) > 0.5);
        }
    }
    return lit;
}

struct BandOut {
    @location(0) visibility: vec4<f32>,
    @location(1) classification: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// What the neighbourhood says about one pixel.
struct Classified {
    // LIT, SHADOWED or EDGE.
    kind: u32,
    surface: Surface,
    light: Light,
    // The lookup point (moved off the surface) and the world size of a texel there.
    lookup: vec3<f32>,
    texel: f32,
}

const LIT: u32 = 1u;
const SHADOWED: u32 = 2u;
const EDGE: u32 = 3u;

const NO_TRIANGLE: u32 = 0xffffffffu;

// The corners of drawn triangle `id` (the maps hold drawn indices: `drawn_triangle_id`), in
// world space.
fn drawn_corners(id: u32) -> array<vec3<f32>, 3> {
    let triangle = drawn_triangle(id);
    var corners: array<vec3<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        let base = scene_indices[3u * triangle.y + k] * VERTEX_FLOATS;
        let stored = vec3<f32>(scene_vertices[base], scene_vertices[base + 1u], scene_vertices[base + 2u]);
        corners[k] = object_world(triangle.x, stored);
    }
    return corners;
}

// How far towards the light a surface moves before it meets the coverage map's triangle, in
// texels: depth precision, and the planes of a curved receiver's neighbouring triangles.
const COVERAGE_CLEARANCE: f32 = 0.02;

// Surfaces the light grazes (the cosine of their shading normal to it) join the band: one
// texel spans a long stretch of them, so the samples and the coverage test, a texel apart,
// cannot settle their shadow; near a coarse curve's terminator a triangle may even face away
// from the light while its shading normal does not (sin 11.25°: a 16-sided cylinder). Under
// a light lower than this over a flat receiver, the whole receiver joins the band: exact, and
// as dear as the volumes everywhere.
const GRAZING: f32 = 0.2;

// The step from p to the neighbour of `pixel` along `step` or against it, whichever lies
// nearer p (pixels beside a silhouette take the surface they belong to), oriented along `step`.
fn nearer_step(pixel: vec2<i32>, p: vec3<f32>, step: vec2<i32>) -> vec3<f32> {
    let ahead = load_surface(pixel + step);
    let behind = load_surface(pixel - step);
    let forward = ahead.position - p;
    let backward = p - behind.position;
    if !behind.valid || (ahead.valid && dot(forward, forward) < dot(backward, backward)) {
        return forward;
    }
    return backward;
}

// The normal of the triangle under `pixel` (shading normals bend away from it near a
// terminator, where a triangle faces away from the light while its shading normal does not),
// from the positions of its neighbours, on the shading normal's side.
fn face_normal(pixel: vec2<i32>, s: Surface) -> vec3<f32> {
    let across = cross(nearer_step(pixel, s.position, vec2<i32>(1, 0)), nearer_step(pixel, s.position, vec2<i32>(0, 1)));
    if dot(across, across) == 0.0 {
        return s.normal;
    }
    let n = normalize(across);
    return select(n, -n, dot(n, s.normal) < 0.0);
}

// The depth of triangle `id`'s plane where map point `m` lies, within the triangle's own depth
// range (0 where the triangle reaches behind a perspective layer's eye: it may block).
fn plane_depth(id: u32, m: MapPoint) -> f32 {
    let camera = layer_cameras[m.layer].camera;
    let world = drawn_corners(id);
    var corners: array<vec3<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        let clip = camera.view_proj * vec4<f32>(world[k], 1.0);
        if clip.w <= 1e-6 {
            return 0.0;
        }
        corners[k] = clip.xyz / clip.w;
    }
    let ndc = vec2<f32>(m.uv.x * 2.0 - 1.0, 1.0 - m.uv.y * 2.0);
    let e1 = corners[1] - corners[0];
    let e2 = corners[2] - corners[0];
    let area = e1.x * e2.y - e1.y * e2.x;
    let low = min(corners[0].z, min(corners[1].z, corners[2].z));
    let high = max(corners[0].z, max(corners[1].z, corners[2].z));
    if abs(area) < 1e-14 {
        return high;
    }
    let slope = vec2<f32>(e1.z * e2.y - e2.z * e1.y, e2.z * e1.x - e1.z * e2.x) / area;
    return clamp(corners[0].z + dot(slope, ndc - corners[0].xy), low, high);
}

// Whether a caster may cross the light ray of the pixel's surface: its triangle faces away
// from the light, the light grazes it, or the plane of the coverage map's triangle under the ray lies nearer the
// light than the surface there.
fn coverage_blocked(c: Classified, pixel: vec2<i32>) -> bool {
    let p = c.surface.position;
    var to_light = -c.light.direction;
    var clearance = COVERAGE_CLEARANCE * c.texel;
    if c.light.kind != LIGHT_DIRECTIONAL {
        to_light = c.light.position - p;
        clearance = min(clearance, 0.5 * length(to_light));
        to_light = normalize(to_light);
    }
    if dot(face_normal(pixel, c.surface), to_light) <= 0.0 || dot(c.surface.normal, to_light) < GRAZING {
        return true;
    }
    let layer = header_layer(edge.map, p);
    let m = map_point(layer, p);
    if !m.inside {
        return false;
    }
    let id = textureLoad(coverage_ids, tile_texel(m.tile, m.uv), m.tile.page, 0).r;
    if id == NO_TRIANGLE {
        return false;
    }
    let moved = map_point(layer, p + to_light * clearance);
    return plane_depth(id, m) < moved.depth;
}

// Pixels without a surface or outside the light's range and cone are discarded (lit, out of
// the band).
fn classify(pixel: vec2<f32>) -> Classified {
    let receiver = map_receiver(edge.map, pixel);
    var c: Classified;
    c.surface = receiver.surface;
    c.light = lights[edge.map.light];
    c.lookup = receiver.lookup;
    c.texel = receiver.texel;
    let light = c.light;
    let n = (2u * edge.radius + 1u) * (2u * edge.radius + 1u);
    let lit = lit_taps(light, c.lookup, c.texel);
    if edge.restriction == RESTRICTION_EVERYWHERE || (lit > 0u && lit < n) {
        c.kind = EDGE;
    } else if lit == 0u {
        c.kind = SHADOWED;
    } else if edge.coverage == 1u && coverage_blocked(c, vec2<i32>(pixel)) {
        c.kind = EDGE;
    } else {
        c.kind = LIT;
    }
    return c;
}

fn class_colour(kind: u32) -> vec4<f32> {
    switch kind {
        case LIT: { return CLASS_LIT; }
        case SHADOWED: { return CLASS_SHADOWED; }
        default: { return CLASS_EDGE; }
    }
}

@fragment
fn fs_band(in: FullscreenOut) -> BandOut {
    let c = classify(in.position.xy);
    var out: BandOut;
    out.visibility = vec4<f32>(select(1.0, 0.0, c.kind == SHADOWED));
    out.classification = class_colour(c.kind);
    out.depth = 1.0;
    if c.kind == EDGE {
        let clip = camera.view_proj * vec4<f32>(c.surface.position, 1.0);
        out.depth = clip.z / clip.w;
    }
    return out;
}

// Triangle ids of the shadow map's front-most triangles (NO_TRIANGLE where none), for the
// exact test.
@group(3) @binding(9) var triangle_ids: texture_2d_array<u32>;

// Whether triangle `id` crosses the ray origin + t·direction for t in (0, t_max)
// (Möller–Trumbore).
fn ray_hits(id: u32, origin: vec3<f32>, direction: vec3<f32>, t_max: f32) -> bool {
    let corners = drawn_corners(id);
    let a = corners[0];
    let b = corners[1];
    let c = corners[2];
    let e1 = b - a;
    let e2 = c - a;
    let h = cross(direction, e2);
    let det = dot(e1, h);
    if abs(det) < 1e-12 {
        return false;
    }
    let f = 1.0 / det;
    let s = origin - a;
    let u = f * dot(s, h);
    let q = cross(s, e1);
    let v = f * dot(direction, q);
    let t = f * dot(e2, q);
    return u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 && t < t_max;
}

// Whether the light ray from the surface is blocked by a triangle the map saw in the
// (2r + 3)² texels around the surface's texel.
fn occluded(c: Classified) -> bool {
    let light = c.light;
    let layer = header_layer(edge.map, c.lookup);
    let m = map_point(layer, c.lookup);
    let centre = tile_texel(m.tile, m.uv);
    // Leave the surface by a hair, relative to the scene's scale at this point.
    let scale = max(distance(c.surface.position, camera.position), 1.0);
    let origin = c.surface.position + c.surface.normal * (1e-4 * scale);
    var direction = -light.direction;
    var t_max = 3.4e38;
    if light.kind != LIGHT_DIRECTIONAL {
        let to_light = light.position - origin;
        t_max = length(to_light);
        direction = to_light / t_max;
    }
    let r = i32(edge.radius) + 1;
    for (var j = -r; j <= r; j++) {
        for (var i = -r; i <= r; i++) {
            let texel = clamp_to_tile(m.tile, centre + vec2<i32>(i, j));
            let id = textureLoad(triangle_ids, texel, m.tile.page, 0).r;
            if id != NO_TRIANGLE && ray_hits(id, origin, direction, t_max) {
                return true;
            }
        }
    }
    return false;
}

@fragment
fn fs_band_ids(in: FullscreenOut) -> BandOut {
    let c = classify(in.position.xy);
    var out: BandOut;
    out.classification = class_colour(c.kind);
    out.depth = 1.0;
    var shadowed = c.kind == SHADOWED;
    if c.kind == EDGE {
        shadowed = occluded(c);
    }
    out.visibility = vec4<f32>(select(1.0, 0.0, shadowed));
    return out;
}

// Pass 4, edge pixels inside a volume (non-zero count) shadowed, and the count view are the
// shadow-volume library's (`shadow-volumes/stencil_read.wgsl`).
