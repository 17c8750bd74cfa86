// Hybrid shadows, coverage maps: every caster triangle rendered conservatively from one
// shadow-map layer, into every texel it touches, writing its id (of a closed opaque caster,
// only the triangles facing the light). The depth map samples texel
// centres and misses casters thinner than a texel; the band pass tests a pixel's own light
// ray against the plane of the triangle stored in its texel here (`coverage_blocked` in
// `hybrid-edge/band.wgsl`).
//
// Each triangle grows by half a texel on every side in the vertex shader
// (`common/conservative.wgsl`); the triangle's box grown by half a texel discards what the
// growth adds beyond sharp corners. The depth test keeps, per texel, the
// triangle whose plane is nearest the light at the texel's centre, within the triangle's own
// depth range (so a receiver's own triangle, not a steep one behind it, holds its texel).

#import "common/conservative.wgsl"
#import "hybrid-edge/casters.wgsl"
// Each scene object's box and, for a closed opaque caster, its orientation (`ClosedCaster` in
// the plugin's Rust).
#import "hybrid-edge/closed_caster.wgsl"

@group(2) @binding(2) var<storage, read> closed_casters: array<ClosedCaster>;

// Whether a triangle (world corners `p`) of `object` may be left out: its object is closed and
// opaque, the light lies outside its box, and the triangle faces away from the light (a ray
// that crosses a closed caster enters it through a triangle facing the light, nearer the
// light; `plugins/hybrid-edge/src/closed.rs`).
fn faces_away_inside_closed(object: u32, p: array<vec3<f32>, 3>) -> bool {
    let caster = closed_casters[object];
    let orientation = caster.low.w;
    if orientation == 0.0 {
        return false;
    }
    var to_light: vec3<f32>;
    if layer_camera.eye.w > 0.0 {
        let eye = layer_camera.eye.xyz;
        if all(eye >= caster.low.xyz) && all(eye <= caster.high.xyz) {
            return false;
        }
        to_light = eye - p[0];
    } else {
        // An orthographic layer: away from the direction its depth grows along.
        to_light = -(layer_camera.inv_view_proj * vec4<f32>(0.0, 0.0, 1.0, 0.0)).xyz;
    }
    return dot(cross(p[1] - p[0], p[2] - p[0]), to_light) * orientation < 0.0;
}

struct CoverageVertex {
    @builtin(position) clip: vec4<f32>,
    // The position in the layer's normalised device coordinates.
    @location(0) ndc: vec2<f32>,
    // The triangle's box grown by half a texel: min x, min y, max x, max y.
    @location(1) @interpolate(flat) bounds: vec4<f32>,
    // The triangle's nearest and farthest depth.
    @location(2) @interpolate(flat) depths: vec2<f32>,
    @location(3) @interpolate(flat) triangle: u32,
}

struct CoverageOut {
    @location(0) triangle: u32,
    @builtin(frag_depth) depth: f32,
}

@vertex
fn vs_coverage(@builtin(vertex_index) vertex: u32, @builtin(instance_index) object: u32) -> CoverageVertex {
    var out: CoverageVertex;
    out.clip = OUTSIDE_CLIP;
    let triangle = vertex / 3u;
    out.triangle = drawn_triangle_id(object, triangle);
    let corner = vertex % 3u;
    var world: array<vec3<f32>, 3>;
    var clip: array<vec4<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        world[k] = triangle_corner(object, triangle, k);
        clip[k] = layer_camera.view_proj * vec4<f32>(world[k], 1.0);
    }
    if faces_away_inside_closed(object, world) {
        return out;
    }
    // A triangle that reaches behind a perspective layer's eye is drawn as it is (clipped by
    // the rasteriser, not grown).
    if min(clip[0].w, min(clip[1].w, clip[2].w)) <= 1e-6 {
        out.clip = clip[corner];
        out.bounds = vec4<f32>(-2.0, -2.0, 2.0, 2.0);
        out.depths = vec2<f32>(0.0, 1.0);
        return out;
    }
    var ndc: array<vec3<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        ndc[k] = clip[k].xyz / clip[k].w;
    }
    let e1 = ndc[1].xy - ndc[0].xy;
    let e2 = ndc[2].xy - ndc[0].xy;
    let area = cross2(e1, e2);
    // Seen edge on, a triangle covers nothing.
    if abs(area) < 1e-14 {
        return out;
    }
    let half = vec2<f32>(1.0 / f32(layer_camera.tile.size));
    let flat = array<vec2<f32>, 3>(ndc[0].xy, ndc[1].xy, ndc[2].xy);
    let position = grown_corner(flat, corner, half);
    // The triangle's plane: depth = ndc[0].z + dot(slope, xy - ndc[0].xy).
    let dz1 = ndc[1].z - ndc[0].z;
    let dz2 = ndc[2].z - ndc[0].z;
    let slope = vec2<f32>(dz1 * e2.y - dz2 * e1.y, dz2 * e1.x - dz1 * e2.x) / area;
    out.clip = vec4<f32>(position, ndc[0].z + dot(slope, position - ndc[0].xy), 1.0);
    out.ndc = position;
    let low = min(ndc[0], min(ndc[1], ndc[2]));
    let high = max(ndc[0], max(ndc[1], ndc[2]));
    out.bounds = vec4<f32>(low.xy - half, high.xy + half);
    out.depths = vec2<f32>(low.z, high.z);
    return out;
}

@fragment
fn fs_coverage(in: CoverageVertex) -> CoverageOut {
    if any(in.ndc < in.bounds.xy) || any(in.ndc > in.bounds.zw) {
        discard;
    }
    var out: CoverageOut;
    out.triangle = in.triangle;
    out.depth = clamp(clamp(in.clip.z, in.depths.x, in.depths.y), 0.0, 1.0);
    return out;
}
