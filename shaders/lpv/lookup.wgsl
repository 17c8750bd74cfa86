// The lookup (seed 002 §5.4): the accumulated light at every pixel's surface, trilinear in
// each grid. The cells hold the intensity of light flowing through them; taken as radiance over
// the cell's cross-section (I / s^2), the irradiance on a surface with normal n is the SH
// product with the clamped cosine lobe around -n (light flowing towards the surface). The
// indirect target gets irradiance over pi. Lookups move `damping` cells along the normal, so a
// surface does not read the light it injected itself; with `lookup_blocking` each cell's light
// counts by the occluders' transmittance between it and the lookup point (`corner_reach`).
//
// Grids combine from the coarsest in. A grid of cell s after N steps holds light that travelled
// up to N s. With `coarse_far_light`, the next finer grid (cell s/2, N steps) carries the light
// within N s/2 in finer detail, so at a point it covers it replaces the coarser grid's first
// N/2 steps and the coarser grid adds only the rest: E = E_fine + E_coarse - E_coarse,near.
// Without it, a finer grid replaces the coarser one outright. Either way a finer grid fades in
// over `blend_cells` from its border.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "lpv/volume.wgsl"
#import "lpv/blocking.wgsl"

@group(2) @binding(0) var<storage, read> lpv: LpvData;
@group(2) @binding(1) var<storage, read> accumulated: array<vec4<f32>>;
@group(2) @binding(2) var indirect_out: texture_storage_2d<rgba16float, write>;
@group(2) @binding(3) var<storage, read> near: array<vec4<f32>>;
@group(2) @binding(4) var<storage, read> moments: array<vec4<f32>>;
@group(2) @binding(5) var<storage, read> occluder_sums: array<i32>;

// Band 1 over band 0 of the two-band projection of a uniform hemisphere about its axis:
// y1 pi / (y0 2 pi) = sqrt(3)/2, where the clamped-cosine lookup facing the axis is zero.
const HEMISPHERE_BAND_RATIO: f32 = 0.8660254;

// One colour's values in a grid at a point.
struct Channel {
    // The accumulated light's SH.
    light: vec4<f32>,
    // The light's SH after half the steps.
    near: vec4<f32>,
    // The emitters' moments (flux x normal, flux).
    moment: vec4<f32>,
}

struct Sample {
    channels: array<Channel, 3>,
}

// How much of the light of each of the eight cells around a lookup point reaches it, by
// corner bits (x 1, y 2, z 4) from `base`: with `lookup_blocking` and occlusion, the best
// product of transmittances over the face crossings from `home`, the corner whose cell holds
// the lookup point, to it; otherwise 1. Unreached cells count as dark, not renormalised away:
// measured, renormalising brightens receivers beside emitters more than it restores light
// to receivers beside walls.
fn corner_reach(k: u32, base: vec3<i32>, home: u32) -> array<f32, 8> {
    var reach = array<f32, 8>(1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0);
    if lpv.settings.params.lookup_blocking == 0u || lpv.settings.params.occlusion == OCCLUSION_OFF {
        return reach;
    }
    // Corners one, two and three steps from home, each from its best neighbour a step nearer.
    for (var steps = 1u; steps <= 3u; steps++) {
        for (var corner = 0u; corner < 8u; corner++) {
            let away = corner ^ home;
            if countOneBits(away) != steps {
                continue;
            }
            var best = 0.0;
            for (var axis = 0u; axis < 3u; axis++) {
                let bit = 1u << axis;
                if (away & bit) == 0u {
                    continue;
                }
                // The corner's light flows from its cell into the nearer one.
                let nearer = corner ^ bit;
                let into = base + corner_offset(nearer);
                let t = transmittance(k, into, into - base - corner_offset(corner));
                best = max(best, reach[nearer] * t);
            }
            reach[corner] = best;
        }
    }
    return reach;
}

// The offset of corner `corner` (bits x 1, y 2, z 4) from the base cell.
fn corner_offset(corner: u32) -> vec3<i32> {
    return vec3<i32>(i32(corner & 1u), i32((corner >> 1u) & 1u), i32((corner >> 2u) & 1u));
}

// Trilinear values of grid k at lookup point p, each cell read once (cells outside the grid
// count as dark) and weighted by how much of its light reaches p (`corner_reach`).
// `with_near` also reads the light after half the steps.
fn sample_grid(k: u32, p: vec3<f32>, with_near: bool) -> Sample {
    let g = lpv.cascades[k];
    let u = (p - g.min) / g.cell - vec3<f32>(0.5);
    let base = vec3<i32>(floor(u));
    let f = u - floor(u);
    let home = u32(f.x >= 0.5) | (u32(f.y >= 0.5) << 1u) | (u32(f.z >= 0.5) << 2u);
    let reach = corner_reach(k, base, home);
    let oriented = lpv.settings.params.emitter_orientation != 0u;
    var out: Sample;
    for (var corner = 0u; corner < 8u; corner++) {
        let o = corner_offset(corner);
        let c = base + o;
        let w = mix(1.0 - f.x, f.x, f32(o.x)) * mix(1.0 - f.y, f.y, f32(o.y))
            * mix(1.0 - f.z, f.z, f32(o.z)) * reach[corner];
        if !inside_grid(c) || w == 0.0 {
            continue;
        }
        let i = cell_index(k, c) * 3u;
        for (var ch = 0u; ch < 3u; ch++) {
            out.channels[ch].light += w * accumulated[i + ch];
            if with_near {
                out.channels[ch].near += w * near[i + ch];
            }
            if oriented {
                out.channels[ch].moment += w * moments[i + ch];
            }
        }
    }
    return out;
}

// How much of grid k to use at p: 1 inside, fading to 0 over its last `blend_cells` cells.
fn grid_weight(k: u32, p: vec3<f32>) -> f32 {
    let g = lpv.cascades[k];
    let n = f32(lpv.settings.params.grid_size);
    let u = (p - g.min) / g.cell;
    let border = min(u, vec3<f32>(n) - u);
    let nearest = min(border.x, min(border.y, border.z));
    return clamp((nearest - 0.5) / max(lpv.settings.params.blend_cells, 1e-3), 0.0, 1.0);
}

// Where grid k is read for a surface at p with normal n: `damping` cells along the normal.
fn lookup_point(k: u32, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return p + n * (lpv.settings.params.damping * lpv.cascades[k].cell);
}

// The clamped-cosine lookup of one channel's SH `s` on a surface with normal n: the SH
// product with the lobe around -n, C0 c0 - C1 (g . n), where g is the direction light flows
// towards (the field is y0 c0 + y1 g . w). With `emitter_orientation`, g along the mean
// normal of the emitters nearby (moment.xyz / moment.w, shorter than 1 where their normals
// differ) is raised to what emitters facing that way give, HEMISPHERE_BAND_RATIO c0 times its
// length: propagation spreads light sideways and adds band 0 faster than band 1, so a lit
// plane would otherwise light itself (see `sh.rs`).
fn receive(s: vec4<f32>, moment: vec4<f32>, n: vec3<f32>) -> f32 {
    var g = vec3<f32>(-s.w, -s.y, s.z);
    if lpv.settings.params.emitter_orientation != 0u && moment.w > 0.0 {
        let mean = moment.xyz / moment.w;
        let m = min(length(mean), 1.0);
        if m > 1e-4 {
            let axis = normalize(mean);
            let restored = HEMISPHERE_BAND_RATIO * s.x * m;
            g += max(restored - dot(g, axis), 0.0) * axis;
        }
    }
    return SH_COS0 * s.x - SH_COS1 * dot(g, n);
}

// One grid's irradiance over pi on a surface with normal n (not clamped: grids combine
// before the clamp): from all its light, and from its light after half the steps.
struct Irradiance {
    all: vec3<f32>,
    near: vec3<f32>,
}

fn irradiance(k: u32, p: vec3<f32>, n: vec3<f32>, with_near: bool) -> Irradiance {
    let s = sample_grid(k, lookup_point(k, p, n), with_near);
    var out: Irradiance;
    for (var ch = 0u; ch < 3u; ch++) {
        let c = s.channels[ch];
        out.all[ch] = receive(c.light, c.moment, n);
        out.near[ch] = receive(c.near, c.moment, n);
    }
    let area = lpv.cascades[k].cell * lpv.cascades[k].cell * 3.14159265;
    out.all /= area;
    out.near /= area;
    return out;
}

@compute @workgroup_size(8, 8, 1)
fn cs_lookup(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.size);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let s = load_surface(pixel);
    var light = vec3<f32>(0.0);
    if s.valid {
        let count = lpv.settings.cascade_count;
        let far = lpv.settings.params.coarse_far_light != 0u;
        // From the coarsest grid in; `coarser` is the grid read last and `coarser_weight` the
        // weight its light has in `light` (its light within half the steps, at that weight,
        // is what the next finer grid replaces).
        let coarsest = count - 1u;
        var coarser = irradiance(coarsest, s.position, s.normal, far && count > 1u);
        var coarser_weight = grid_weight(coarsest, lookup_point(coarsest, s.position, s.normal));
        light = coarser_weight * coarser.all;
        for (var j = 1u; j < count; j++) {
            let k = coarsest - j;
            let w = grid_weight(k, lookup_point(k, s.position, s.normal));
            let fine = irradiance(k, s.position, s.normal, far && k > 0u);
            if far {
                light += w * (fine.all - coarser_weight * coarser.near);
            } else {
                light = mix(light, fine.all, w);
            }
            coarser = fine;
            coarser_weight = w;
        }
    }
    light = max(light, vec3<f32>(0.0));
    textureStore(indirect_out, pixel, vec4<f32>(light * lpv.settings.params.intensity, 1.0));
}
