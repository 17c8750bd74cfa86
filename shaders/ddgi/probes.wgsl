// The probe grid of ddgi (Majercik et al. 2019): its uniform, the layout of its one storage
// buffer and the irradiance lookup every pass shares. Bind group 2.
//
// `ddgi` holds, in vec4s: each probe's state (its offset from its home, and 1 where active),
// then each probe's irradiance tile ((IRRADIANCE_TEXELS + 2)² texels: an octahedral map of
// the cosine-weighted mean radiance around each direction, with a one-texel border that
// repeats the map across its folds, so that bilinear taps never leave the tile), then each
// probe's distance tile (the same for the mean and mean square of the ray distance, x and y),
// then each probe's rays of this frame (radiance, and the hit distance, negative where the ray
// met a surface's back).

#import "ddgi/ddgi_grid.wgsl"

@group(2) @binding(0) var<uniform> grid: DdgiGrid;
@group(2) @binding(1) var<storage, read_write> ddgi: array<vec4<f32>>;
// The scene object of every traced triangle, then of every instance (from
// `grid.instance_objects`).
@group(2) @binding(2) var<storage, read> surface_objects: array<u32>;
@group(2) @binding(3) var indirect_out: texture_storage_2d<rgba16float, write>;
// Probes active, moved and inside geometry (`cs_relocate`), read back as counters
// (`zoo_plugin_ddgi::Count`).
@group(2) @binding(4) var<storage, read_write> ddgi_counts: array<atomic<u32>, 3>;

// Texels along an irradiance and a distance map's side, borders left out
// (`zoo_plugin_ddgi::IRRADIANCE_TEXELS`, `DISTANCE_TEXELS`).
const IRRADIANCE_TEXELS: u32 = 6u;
const DISTANCE_TEXELS: u32 = 14u;
// A ray's distance where it met nothing.
const DDGI_MISS: f32 = 1e30;

fn probe_count() -> u32 {
    return grid.counts.x * grid.counts.y * grid.counts.z;
}

fn probe_index(at: vec3<u32>) -> u32 {
    return at.x + grid.counts.x * (at.y + grid.counts.y * at.z);
}

fn probe_coords(index: u32) -> vec3<u32> {
    let x = index % grid.counts.x;
    let y = (index / grid.counts.x) % grid.counts.y;
    return vec3<u32>(x, y, index / (grid.counts.x * grid.counts.y));
}

// Index in `ddgi` of texel `texel` of probe `probe`'s irradiance tile, and of its distance tile.
fn irradiance_index(probe: u32, texel: u32) -> u32 {
    let side = IRRADIANCE_TEXELS + 2u;
    return probe_count() + probe * side * side + texel;
}

fn distance_index(probe: u32, texel: u32) -> u32 {
    let irradiance_side = IRRADIANCE_TEXELS + 2u;
    let side = DISTANCE_TEXELS + 2u;
    return probe_count() * (1u + irradiance_side * irradiance_side) + probe * side * side + texel;
}

// Index in `ddgi` of ray `ray` of probe `probe`.
fn ray_index(probe: u32, ray: u32) -> u32 {
    let irradiance_side = IRRADIANCE_TEXELS + 2u;
    let distance_side = DISTANCE_TEXELS + 2u;
    let tiles = 1u + irradiance_side * irradiance_side + distance_side * distance_side;
    return probe_count() * tiles + probe * grid.rays + ray;
}

// Where probe `probe` lies: its home on the grid moved by its offset.
fn probe_position(probe: u32) -> vec3<f32> {
    return grid.origin + vec3<f32>(probe_coords(probe)) * grid.spacing + ddgi[probe].xyz;
}

fn probe_active(probe: u32) -> bool {
    return ddgi[probe].w > 0.5;
}

fn sign_not_zero(v: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(-1.0), vec2<f32>(1.0), v >= vec2<f32>(0.0));
}

// The octahedral map: a unit direction to a point of [-1, 1]², and back.
fn oct_encode(n: vec3<f32>) -> vec2<f32> {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z < 0.0 {
        return (1.0 - abs(p.yx)) * sign_not_zero(p);
    }
    return p;
}

fn oct_decode(e: vec2<f32>) -> vec3<f32> {
    var v = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if v.z < 0.0 {
        v = vec3<f32>((1.0 - abs(v.yx)) * sign_not_zero(v.xy), v.z);
    }
    return normalize(v);
}

// Ray `ray` of `rays` of this frame: a spherical Fibonacci point turned by the frame's rotation.
fn ray_direction(ray: u32, rays: u32) -> vec3<f32> {
    let golden = 0.61803398875;
    let z = 1.0 - (2.0 * f32(ray) + 1.0) / f32(rays);
    let phi = 6.28318530718 * fract(f32(ray) * golden);
    let r = sqrt(max(0.0, 1.0 - z * z));
    let d = vec3<f32>(r * cos(phi), r * sin(phi), z);
    return vec3<f32>(dot(grid.rotation[0].xyz, d), dot(grid.rotation[1].xyz, d), dot(grid.rotation[2].xyz, d));
}

// The interior texel (0..texels in x and y) whose value bordered-tile texel `at` holds: itself
// inside, its mirror across the fold on the border (the octahedral map's edges fold onto
// themselves; its corners all meet at -z).
fn border_source(at: vec2<u32>, texels: u32) -> vec2<u32> {
    let last = texels + 1u;
    let x_edge = at.x == 0u || at.x == last;
    let y_edge = at.y == 0u || at.y == last;
    var source = at;
    if x_edge && y_edge {
        source = vec2<u32>(select(1u, texels, at.x == 0u), select(1u, texels, at.y == 0u));
    } else if y_edge {
        source = vec2<u32>(last - at.x, select(texels, 1u, at.y == 0u));
    } else if x_edge {
        source = vec2<u32>(select(texels, 1u, at.x == 0u), last - at.y);
    }
    return source - 1u;
}

// The direction at the centre of interior texel `texel` of a map `texels` wide.
fn texel_direction(texel: vec2<u32>, texels: u32) -> vec3<f32> {
    return oct_decode((vec2<f32>(texel) + 0.5) / f32(texels) * 2.0 - 1.0);
}

// Bilinear taps of a bordered tile `texels` wide (plus borders) toward `dir`: the four
// texels (row-major in the tile) and their weights.
struct Taps {
    texels: vec4<u32>,
    weights: vec4<f32>,
}

fn tile_taps(dir: vec3<f32>, texels: u32) -> Taps {
    let side = texels + 2u;
    // Interior texel k spans [k + 1, k + 2) of the bordered tile.
    let at = (oct_encode(dir) * 0.5 + 0.5) * f32(texels) + 1.0 - 0.5;
    let first = clamp(floor(at), vec2<f32>(0.0), vec2<f32>(f32(texels)));
    let f = clamp(at - first, vec2<f32>(0.0), vec2<f32>(1.0));
    let i = vec2<u32>(first);
    let row = i.y * side + i.x;
    return Taps(
        vec4<u32>(row, row + 1u, row + side, row + side + 1u),
        vec4<f32>((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y),
    );
}

fn sample_irradiance(probe: u32, dir: vec3<f32>) -> vec3<f32> {
    let taps = tile_taps(dir, IRRADIANCE_TEXELS);
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        sum += ddgi[irradiance_index(probe, taps.texels[k])].rgb * taps.weights[k];
    }
    return sum;
}

// The mean and mean square of the distance to what lies toward `dir` from probe `probe`.
fn sample_distance(probe: u32, dir: vec3<f32>) -> vec2<f32> {
    let taps = tile_taps(dir, DISTANCE_TEXELS);
    var sum = vec2<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        sum += ddgi[distance_index(probe, taps.texels[k])].xy * taps.weights[k];
    }
    return sum;
}

// Irradiance over pi (the cosine-weighted mean radiance) at `p` with unit normal `n`, seen
// along unit `view` (from the eye or the ray toward `p`): the eight probes around the point
// moved off the surface (the self-shadow bias), each weighted by its trilinear weight, by how
// much it lies in front of the surface (a wrapped cosine) and by the chance that it sees the
// point (Chebyshev's bound from its distance map); inactive probes left out.
fn ddgi_irradiance(p: vec3<f32>, n: vec3<f32>, view: vec3<f32>) -> vec3<f32> {
    let spacing = min(min(grid.spacing.x, grid.spacing.y), grid.spacing.z);
    let q = p + (n * 0.2 - view * 0.8) * (0.75 * spacing * grid.self_shadow_bias);
    let last = vec3<f32>(grid.counts - 1u);
    let cell = (q - grid.origin) / grid.spacing;
    let base = clamp(floor(cell), vec3<f32>(0.0), max(last - 1.0, vec3<f32>(0.0)));
    let alpha = clamp(cell - base, vec3<f32>(0.0), vec3<f32>(1.0));
    var sum = vec3<f32>(0.0);
    var total = 0.0;
    for (var corner = 0u; corner < 8u; corner++) {
        let step = vec3<u32>(corner & 1u, (corner >> 1u) & 1u, (corner >> 2u) & 1u);
        let probe = probe_index(vec3<u32>(base) + step);
        if !probe_active(probe) {
            continue;
        }
        let position = probe_position(probe);
        let trilinear = mix(1.0 - alpha, alpha, vec3<f32>(step));
        var weight = 1.0;
        let to_probe = normalize(position - p);
        let wrap = (dot(to_probe, n) + 1.0) * 0.5;
        weight *= wrap * wrap + 0.2;
        let from_probe = q - position;
        let r = length(from_probe);
        let moments = sample_distance(probe, from_probe / max(r, 1e-9));
        if r > moments.x {
            let variance = abs(moments.y - moments.x * moments.x);
            let d = r - moments.x;
            let chebyshev = variance / (variance + d * d);
            weight *= chebyshev * chebyshev * chebyshev;
        }
        weight = max(weight, 1e-6);
        // Weights below a threshold fall faster (no light from probes that barely see it).
        let crush = 0.2;
        if weight < crush {
            weight *= weight * weight / (crush * crush);
        }
        weight *= trilinear.x * trilinear.y * trilinear.z;
        sum += sample_irradiance(probe, n) * weight;
        total += weight;
    }
    return select(vec3<f32>(0.0), sum / total, total > 0.0);
}
