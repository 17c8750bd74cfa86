// Blends the frame's rays into each probe's maps (ddgi): every texel of a bordered tile takes
// the direction of the interior texel it holds (`border_source`) and the rays' mean around it,
// cosine-weighted for irradiance and sharply weighted (cos^50) for the distance's moments; the
// result moves the stored value by `grid.weight` (1 on the first frame, then 1/n, never below
// 1 - hysteresis). Before that, during the first frames, probes move out of walls and away
// from surfaces they nearly touch, and probes inside geometry are switched off (`cs_relocate`).

#import "ddgi/probes.wgsl"

// A probe is inside geometry when more of its rays than this meet backs of surfaces.
const INSIDE_SHARE: f32 = 0.25;
// A probe nearer a surface than this share of the spacing moves away from it.
const NEAREST_SURFACE: f32 = 0.2;
// Probes stay within this share of the spacing of their homes.
const MOST_OFFSET: f32 = 0.45;
// Rays this far or further from a distance texel's direction (cosine) count for nothing.
const DISTANCE_COSINE_CUTOFF: f32 = 0.75;

// A chunk of a probe's rays that a workgroup reads once for all its texels: direction and
// distance, and light.
const CHUNK: u32 = 256u;
var<workgroup> chunk_rays: array<vec4<f32>, CHUNK>;
var<workgroup> chunk_light: array<vec3<f32>, CHUNK>;

// Loads rays `first..first + CHUNK` of `probe` (those there are) into the chunk, each
// invocation `CHUNK / invocations` of them; every invocation calls it (workgroup barriers).
fn load_chunk(probe: u32, first: u32, local: u32, invocations: u32) {
    workgroupBarrier();
    for (var k = local; k < CHUNK; k += invocations) {
        let ray = first + k;
        if ray < grid.rays {
            let hit = ddgi[ray_index(probe, ray)];
            chunk_rays[k] = vec4<f32>(ray_direction(ray, grid.rays), hit.w);
            chunk_light[k] = hit.rgb;
        }
    }
    workgroupBarrier();
}

// One workgroup a probe's irradiance tile, an invocation a texel.
@compute @workgroup_size(8, 8, 1)
fn cs_irradiance(
    @builtin(workgroup_id) tile: vec3<u32>,
    @builtin(local_invocation_id) at: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    // (The test is the same for the whole workgroup, so it leaves together; whether the
    // probe is active is read from storage, which barriers cannot depend on: tested last.)
    let probe = tile.z;
    if probe >= probe_count() {
        return;
    }
    let side = IRRADIANCE_TEXELS + 2u;
    let dir = texel_direction(border_source(at.xy, IRRADIANCE_TEXELS), IRRADIANCE_TEXELS);
    var sum = vec3<f32>(0.0);
    var total = 0.0;
    for (var first = 0u; first < grid.rays; first += CHUNK) {
        load_chunk(probe, first, local, side * side);
        for (var k = 0u; k < min(CHUNK, grid.rays - first); k++) {
            let weight = dot(dir, chunk_rays[k].xyz);
            if weight <= 0.0 {
                continue;
            }
            sum += chunk_light[k] * weight;
            total += weight;
        }
    }
    if !probe_active(probe) {
        return;
    }
    let index = irradiance_index(probe, at.y * side + at.x);
    let mean = select(vec3<f32>(0.0), sum / total, total > 0.0);
    ddgi[index] = vec4<f32>(mix(ddgi[index].rgb, mean, grid.weight), 1.0);
}

// One workgroup a probe's distance tile, an invocation a texel.
@compute @workgroup_size(16, 16, 1)
fn cs_distance(
    @builtin(workgroup_id) tile: vec3<u32>,
    @builtin(local_invocation_id) at: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let probe = tile.z;
    if probe >= probe_count() {
        return;
    }
    let side = DISTANCE_TEXELS + 2u;
    let dir = texel_direction(border_source(at.xy, DISTANCE_TEXELS), DISTANCE_TEXELS);
    var sum = vec2<f32>(0.0);
    var total = 0.0;
    for (var first = 0u; first < grid.rays; first += CHUNK) {
        load_chunk(probe, first, local, side * side);
        for (var k = 0u; k < min(CHUNK, grid.rays - first); k++) {
            let c = dot(dir, chunk_rays[k].xyz);
            // cos^50 is below 6e-7 past this: most rays, skipped without a power.
            if c <= DISTANCE_COSINE_CUTOFF {
                continue;
            }
            let weight = pow(c, 50.0);
            let d = min(abs(chunk_rays[k].w), grid.max_distance);
            sum += vec2<f32>(d, d * d) * weight;
            total += weight;
        }
    }
    let index = distance_index(probe, at.y * side + at.x);
    if total > 0.0 && probe_active(probe) {
        let mean = sum / total;
        ddgi[index] = vec4<f32>(mix(ddgi[index].xy, mean, grid.weight), 0.0, 0.0);
    }
}

// Moves each probe out of the geometry it is inside (through the nearest back it sees) or away
// from the nearest surface it nearly touches (with `grid.relocate`); or, on the last relocation
// frame (`grid.classify`), switches it off if its rays, traced where it ended, still find it
// inside.
@compute @workgroup_size(64, 1, 1)
fn cs_relocate(@builtin(global_invocation_id) id: vec3<u32>) {
    let probe = id.x;
    if probe >= probe_count() {
        return;
    }
    var backs = 0u;
    var nearest_back = vec4<f32>(0.0, 0.0, 0.0, DDGI_MISS);
    var nearest_front = vec4<f32>(0.0, 0.0, 0.0, DDGI_MISS);
    for (var ray = 0u; ray < grid.rays; ray++) {
        let d = ddgi[ray_index(probe, ray)].w;
        let dir = ray_direction(ray, grid.rays);
        if d < 0.0 {
            backs += 1u;
            if -d < nearest_back.w {
                nearest_back = vec4<f32>(dir, -d);
            }
            continue;
        }
        if d < nearest_front.w {
            nearest_front = vec4<f32>(dir, d);
        }
    }
    let spacing = min(min(grid.spacing.x, grid.spacing.y), grid.spacing.z);
    let inside = f32(backs) > INSIDE_SHARE * f32(grid.rays);
    var offset = ddgi[probe].xyz;
    if grid.relocate == 1u {
        var moved = offset;
        if inside {
            // Through the nearest back, past it by a little.
            moved = offset + nearest_back.xyz * (nearest_back.w + NEAREST_SURFACE * 0.5 * spacing);
        } else if nearest_front.w < NEAREST_SURFACE * spacing {
            // Straight away from the nearest surface seen (a probe lying on a plane sees it at
            // about 0 along rays that graze it, and leaves it: moving toward its farthest view
            // could slide along the plane).
            moved = offset - nearest_front.xyz * (NEAREST_SURFACE * spacing - nearest_front.w);
        }
        if all(abs(moved) < grid.spacing * MOST_OFFSET) {
            offset = moved;
        }
    }
    let off = grid.classify == 1u && inside;
    ddgi[probe] = vec4<f32>(offset, select(1.0, 0.0, off));
    if grid.count == 1u {
        atomicAdd(&ddgi_counts[0], u32(!off));
        atomicAdd(&ddgi_counts[1], u32(any(offset != vec3<f32>(0.0))));
        atomicAdd(&ddgi_counts[2], u32(inside));
    }
}
