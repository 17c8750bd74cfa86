// Frustum-traced shadows, raster path (`rasteriser: Raster`): step 3 of `izb.wgsl` on the
// raster pipeline. Each caster triangle is drawn once a view (the instance index) into a
// `grid` x `grid` target, conservatively: by the rasteriser's own conservative mode where the
// device has it, otherwise grown by half a texel in the vertex stage (`common/conservative.wgsl`).
// Each fragment walks its texel's list and tests every listed sample's ray exactly against the
// triangle, as the compute path does; fragments outside the triangle's conservative rectangle
// (`triangle_rect`, the compute path's) are discarded, so both paths visit the same texels
// at most. A triangle that reaches behind a cube face's apex has no projection there; it is
// drawn as its rectangle (two triangles), which holds every texel its clipped part touches.

#import "common/conservative.wgsl"
#import "frustum-traced/izb.wgsl"

// Each view's `BOUNDS` words of `state`, copied after the samples are placed (the vertex stage
// reads them; it cannot read `state`, which the fragments write).
@group(4) @binding(7) var<storage, read> raster_bounds: array<vec4<u32>>;

struct RasterVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) triangle: u32,
    @location(1) @interpolate(flat) view: u32,
    // The conservative rectangle: lowest column and row, then highest.
    @location(2) @interpolate(flat) rect: vec4<i32>,
}

// A clip position every vertex of a skipped triangle shares (no area: nothing is drawn).
const SKIPPED: vec4<f32> = vec4<f32>(-2.0, -2.0, 0.0, 1.0);

// Projected triangles of less area than this (twice, in texels squared), or thinner than
// `SLIVER` times their longest side, are drawn as their rectangle: their grown corners would
// run far out (an angle of a hundredth of a radian sends one about 100 texels).
const MIN_AREA: f32 = 1e-4;
const SLIVER: f32 = 0.01;

// Where world point `p` falls on view `view` of `light`, in texels of its grid (columns right,
// rows down); `w` is 0 where it has no projection (at or behind a cube face's apex).
fn texel_position(light: Light, view: u32, extent: Extent, p: vec3<f32>) -> vec3<f32> {
    var uv = plane_position(light, p).xy;
    if light.kind != LIGHT_DIRECTIONAL {
        let f = face_frame(view, p - light.position);
        if f.z <= 1e-6 * length(f) {
            return vec3<f32>(0.0);
        }
        uv = f.xy / f.z;
    }
    return vec3<f32>((uv - extent.low) * texel_scale(extent), 1.0);
}

@vertex
fn vs_caster(@builtin(vertex_index) vertex: u32, @builtin(instance_index) view: u32) -> RasterVertex {
    var out: RasterVertex;
    out.clip = SKIPPED;
    let flat = vertex / 6u;
    let k = vertex % 6u;
    out.triangle = flat;
    out.view = view;
    let light = lights[ft_light.light];
    let extent = extent_of(raster_bounds[view]);
    let corners = caster_world_corners(caster_triangle(flat));
    let rect = triangle_rect(light, view, extent, corners);
    if rect_texels(rect) == 0u {
        return out;
    }
    out.rect = vec4<i32>(rect.low, rect.high);
    var projected: array<vec2<f32>, 3>;
    var whole = true;
    for (var c = 0u; c < 3u; c++) {
        let t = texel_position(light, view, extent, corners[c]);
        projected[c] = t.xy;
        whole = whole && t.z > 0.0;
    }
    let e = array<vec2<f32>, 3>(
        projected[1] - projected[0],
        projected[2] - projected[1],
        projected[0] - projected[2],
    );
    let longest = max(dot(e[0], e[0]), max(dot(e[1], e[1]), dot(e[2], e[2])));
    let area = cross2(e[0], -e[2]);
    var position: vec2<f32>;
    if whole && abs(area) >= max(MIN_AREA, SLIVER * longest) {
        if k >= 3u {
            return out;
        }
        position = grown_corner(projected, k, vec2<f32>(ft_light.grow));
    } else {
        // The rectangle's texels, corner to corner, as two triangles.
        let low = vec2<f32>(rect.low);
        let high = vec2<f32>(rect.high + 1);
        let quad = array<vec2<f32>, 6>(
            low,
            vec2<f32>(high.x, low.y),
            high,
            low,
            high,
            vec2<f32>(low.x, high.y),
        );
        position = quad[k];
    }
    let g = f32(ft_light.grid);
    out.clip = vec4<f32>(2.0 * position.x / g - 1.0, 1.0 - 2.0 * position.y / g, 0.0, 1.0);
    return out;
}

@fragment
fn fs_walk(in: RasterVertex) -> @location(0) vec4<f32> {
    let texel = vec2<i32>(floor(in.clip.xy));
    if any(texel < in.rect.xy) || any(texel > in.rect.zw) {
        discard;
    }
    let t = vec2<u32>(texel);
    walk_list(in.view, t.y * ft_light.grid + t.x, caster_triangle(in.triangle));
    add_counts();
    return vec4<f32>(0.0);
}
