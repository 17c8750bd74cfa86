// Shadow-map filters that fix no bindings. The importing shader supplies the map access:
//
//   fn shadow_tap(p: vec3<f32>, linear: bool) -> f32
//       one depth comparison at world point p (1 = lit; bilinear when `linear`; points
//       outside the map are lit),
//   fn shadow_depths(p: vec3<f32>) -> vec3<f32>
//       (1 when p projects inside the map else 0, p's depth along the map's axis, the stored
//       depth there in the same units),
//
// and calls the filters with the receiver's `TapPlane` and a tangent frame (`tangent_frame`)
// perpendicular to the light's rays at the receiver: taps are placed in world space across the
// rays, moved along their ray onto the receiver's plane and each projected by itself (seamless
// across cube faces).

#import "shadow-maps/layers.wgsl"

// Poisson disc, 16 points in the unit disk, minimum spacing 0.423.
const POISSON_16: array<vec2<f32>, 16> = array<vec2<f32>, 16>(
    vec2<f32>(0.0118, -0.1794),
    vec2<f32>(-0.8401, -0.1568),
    vec2<f32>(-0.0068, 0.3801),
    vec2<f32>(0.4789, 0.3546),
    vec2<f32>(0.8432, -0.1561),
    vec2<f32>(0.6935, -0.7197),
    vec2<f32>(0.1784, -0.9475),
    vec2<f32>(-0.6969, -0.5744),
    vec2<f32>(0.2624, 0.7274),
    vec2<f32>(-0.6019, 0.7281),
    vec2<f32>(-0.6308, 0.2454),
    vec2<f32>(0.2945, -0.4959),
    vec2<f32>(-0.2507, -0.8731),
    vec2<f32>(-0.1435, 0.9813),
    vec2<f32>(0.8964, 0.4394),
    vec2<f32>(-0.4136, -0.1654),
);

// Poisson disc, 32 points in the unit disk, minimum spacing 0.282.
const POISSON_32: array<vec2<f32>, 32> = array<vec2<f32>, 32>(
    vec2<f32>(-0.6682, -0.6513),
    vec2<f32>(0.4346, 0.9006),
    vec2<f32>(-0.2654, -0.2610),
    vec2<f32>(-0.1212, 0.9853),
    vec2<f32>(-0.5647, 0.0362),
    vec2<f32>(0.8074, -0.2949),
    vec2<f32>(-0.2463, -0.9410),
    vec2<f32>(0.1881, 0.3581),
    vec2<f32>(-0.6987, -0.2835),
    vec2<f32>(-0.3201, 0.6051),
    vec2<f32>(-0.7995, 0.5465),
    vec2<f32>(0.4193, -0.5893),
    vec2<f32>(-0.0013, -0.7142),
    vec2<f32>(0.0254, -0.2954),
    vec2<f32>(-0.9079, 0.1392),
    vec2<f32>(0.5672, 0.5483),
    vec2<f32>(-0.0402, 0.1679),
    vec2<f32>(0.5645, 0.1509),
    vec2<f32>(0.8734, 0.4058),
    vec2<f32>(0.2160, 0.0168),
    vec2<f32>(-0.3108, -0.5523),
    vec2<f32>(0.7254, -0.6554),
    vec2<f32>(0.0343, 0.7370),
    vec2<f32>(0.9795, 0.1444),
    vec2<f32>(0.2523, -0.8969),
    vec2<f32>(-0.5561, 0.3951),
    vec2<f32>(0.3312, -0.3040),
    vec2<f32>(-0.5921, 0.7865),
    vec2<f32>(-0.9631, -0.1598),
    vec2<f32>(-0.3184, 0.2193),
    vec2<f32>(0.5695, -0.1380),
    vec2<f32>(-0.0765, 0.4555),
);


fn interleaved_gradient_noise(pixel: vec2<f32>) -> f32 {
    return fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
}

// A per-pixel rotation of the Poisson discs (interleaved gradient noise).
fn rotation(pixel: vec2<f32>) -> mat2x2<f32> {
    let angle = 6.2831853 * interleaved_gradient_noise(pixel);
    let c = cos(angle);
    let s = sin(angle);
    return mat2x2<f32>(c, s, -s, c);
}

// A pixel's filter noise: the Poisson discs' rotation and a point of [0, 1)^2, the same every
// frame (so still frames do not flicker), and for stochastic filters a point that moves every
// frame.
struct FilterNoise {
    rotation: mat2x2<f32>,
    still: vec2<f32>,
    moving: vec2<f32>,
}

// Golden-ratio steps of the plastic-number (R2) sequence: consecutive frames' points of one
// pixel spread evenly over the unit square.
const R2_STEP: vec2<f32> = vec2<f32>(0.7548777, 0.5698403);

// The noise of `pixel` in the renderer's frame `frame` (the `camera.frame` seed): the moving
// point starts at two decorrelated interleaved-gradient values and walks the R2 sequence.
fn filter_noise(pixel: vec2<f32>, frame: u32) -> FilterNoise {
    let start = vec2<f32>(interleaved_gradient_noise(pixel), interleaved_gradient_noise(pixel.yx + vec2<f32>(47.0, 17.0)));
    return FilterNoise(rotation(pixel), start, fract(start + f32(frame % 4096u) * R2_STEP));
}

// The receiver's tangent plane and the light's rays, for placing filter taps.
struct TapPlane {
    // The lookup point (on the plane) and the receiver's normal there.
    point: vec3<f32>,
    normal: vec3<f32>,
    // The light's position (rays from a point) or, when `parallel`, its direction of travel.
    apex: vec3<f32>,
    parallel: bool,
}

// Largest depth change per unit of offset across the rays when a tap moves onto the receiver's
// plane (rays about 89 degrees from the receiver's normal): steeper receivers keep the rest as
// slope.
const TAP_PLANE_MAX_SLOPE: f32 = 64.0;

// The tap q (across the light's rays at the lookup point) moved along its own ray onto the
// receiver's plane, so it compares the receiver's depth there: a flat receiver lit at up to
// about 89 degrees never shadows itself, however wide the kernel or close the light. Taps whose ray does not travel into the
// plane's front stay where they are.
fn on_receiver(plane: TapPlane, q: vec3<f32>) -> vec3<f32> {
    var ray = plane.apex;
    if !plane.parallel {
        ray = normalize(q - plane.apex);
    }
    let into = dot(plane.normal, ray);
    if into > -1e-4 {
        return q;
    }
    let limit = TAP_PLANE_MAX_SLOPE * distance(q, plane.point);
    let along = dot(plane.normal, plane.point - q) / into;
    return q + ray * clamp(along, -limit, limit);
}

// The tap at `offset` (world units along the frame's axes) from the lookup point.
fn plane_tap(plane: TapPlane, frame: mat2x3<f32>, offset: vec2<f32>) -> vec3<f32> {
    return on_receiver(plane, plane.point + frame[0] * offset.x + frame[1] * offset.y);
}

// n x n bilinear comparison taps one texel apart.
fn grid_pcf(plane: TapPlane, frame: mat2x3<f32>, texel: f32, n: i32) -> f32 {
    var sum = 0.0;
    // Offsets a texel apart, centred on the receiver: whole texels for odd n, halves for even.
    let centre = 0.5 * f32(n - 1);
    for (var j = 0; j < n; j++) {
        for (var i = 0; i < n; i++) {
            let offset = vec2<f32>(f32(i), f32(j)) - centre;
            sum += shadow_tap(plane_tap(plane, frame, offset * texel), true);
        }
    }
    return sum / f32(n * n);
}

// 32 bilinear taps on a rotated Poisson disc of world radius `radius`.
fn poisson_pcf(plane: TapPlane, frame: mat2x3<f32>, radius: f32, r: mat2x2<f32>) -> f32 {
    var sum = 0.0;
    for (var k = 0u; k < 32u; k++) {
        sum += shadow_tap(plane_tap(plane, frame, r * POISSON_32[k] * radius), true);
    }
    return sum / 32.0;
}

// Taps of the stochastic filter.
const STOCHASTIC_TAPS: u32 = 4u;

// Stochastic PCF: a few bilinear taps on the disc of world radius `radius`, one in each of
// STOCHASTIC_TAPS rings of equal area, placed by the pixel's moving noise `u`. Each tap is
// uniform over its ring as `u` is over the square, so the mean over frames is the whole disc's
// filtered visibility (a Poisson kernel's limit) at an eighth of its taps; one frame is noisy.
fn stochastic_pcf(plane: TapPlane, frame: mat2x3<f32>, radius: f32, u: vec2<f32>) -> f32 {
    var sum = 0.0;
    for (var k = 0u; k < STOCHASTIC_TAPS; k++) {
        let ring = sqrt((f32(k) + u.x) / f32(STOCHASTIC_TAPS));
        let angle = 6.2831853 * fract(u.y + f32(k) * 0.618034);
        let offset = vec2<f32>(cos(angle), sin(angle)) * ring * radius;
        sum += shadow_tap(plane_tap(plane, frame, offset), true);
    }
    return sum / f32(STOCHASTIC_TAPS);
}

// What PCSS needs to know about the light and the map.
struct PcssLight {
    // Radius (point, spot) or tangent of the angular radius (directional).
    size: f32,
    // The map's near plane, and whether it is a perspective map.
    near: f32,
    perspective: bool,
    // Largest search and penumbra radius, in texels.
    max_texels: f32,
}

// Percentage-closer soft shadows: average blocker depth from a 16-tap search, then a Poisson
// kernel sized by the penumbra the light's size gives at that blocker depth. Search taps lie on
// the receiver's plane, so the receiver is never its own blocker.
fn pcss(plane: TapPlane, frame: mat2x3<f32>, texel: f32, r: mat2x2<f32>, light: PcssLight) -> f32 {
    let center = shadow_depths(plane.point);
    if center.x == 0.0 {
        return 1.0;
    }
    let receiver = center.y;
    var search = light.size * (receiver - light.near);
    if light.perspective {
        search /= max(light.near, 1e-30);
    }
    search = clamp(search, texel, light.max_texels * texel);
    var blockers = 0.0;
    var blocker_sum = 0.0;
    for (var k = 0u; k < 16u; k++) {
        let d = shadow_depths(plane_tap(plane, frame, r * POISSON_16[k] * search));
        if d.x > 0.0 && d.z < d.y {
            blockers += 1.0;
            blocker_sum += d.z;
        }
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let blocker = blocker_sum / blockers;
    var penumbra = light.size * (receiver - blocker);
    if light.perspective {
        penumbra /= max(blocker, 1e-30);
    }
    return poisson_pcf(plane, frame, clamp(penumbra, texel, light.max_texels * texel), r);
}

// What shadow-map ray tracing needs beyond PCSS's light: rays, samples a ray, where samples
// start and their depth slack (texels of the map at the receiver; `MapFilter`'s fields).
struct SmrtRays {
    rays: u32,
    samples: u32,
    start_texels: f32,
    bias_texels: f32,
}

// The golden angle, in radians: consecutive points of a Vogel disc turn by it.
const GOLDEN_ANGLE: f32 = 2.3999632;

// Halvings of the step where an SMRT ray comes out from under a surface, to find where.
const SMRT_REFINEMENTS: u32 = 4u;

// A point of an SMRT ray against the map: whether the map holds it, and its distance and the
// stored surface's from the light along its light ray (axis depths of a perspective map turned
// into distances, so samples in different cube faces compare alike).
struct RayPoint {
    known: bool,
    ray: f32,
    stored: f32,
}

fn ray_point(plane: TapPlane, x: vec3<f32>) -> RayPoint {
    let d = shadow_depths(x);
    var per_depth = 1.0;
    if !plane.parallel {
        per_depth = distance(x, plane.apex) / max(d.y, 1e-30);
    }
    return RayPoint(d.x > 0.0, d.y * per_depth, d.z * per_depth);
}

// Shadow-map ray tracing: rays from the receiver to points of the light's area (a Vogel disc
// across the rays, turned and jittered per pixel), each marched towards the light through the
// map as a height field. A sample behind the stored depth lies under a surface the map sees;
// the ray is blocked where it comes out above that surface (through it), and not where it
// comes out beside it (still behind that surface's depth, in front of a farther one: it passed
// under a caster's edge), so a receiver in the shadow of the light's centre still sees the
// light's edge past a caster's rim. Where a ray comes out is found by halving the step
// (`SMRT_REFINEMENTS`). Samples crowd towards the receiver (quadratically), where contact
// shadows need them. Visibility is the fraction of rays that reach the light: penumbrae come
// from every caster each ray meets, not from one average blocker depth as in PCSS, so
// overlapping casters at different distances soften each by its own distance.
fn smrt(plane: TapPlane, frame: mat2x3<f32>, texel: f32, noise: FilterNoise, light: PcssLight, rays: SmrtRays) -> f32 {
    let start = shadow_depths(plane.point);
    if start.x == 0.0 {
        return 1.0;
    }
    // Depth slack: a texel of a receiver tilted from the light spans `slope` texels of depth.
    var towards = -normalize(plane.apex);
    if !plane.parallel {
        towards = normalize(plane.apex - plane.point);
    }
    let c = clamp(dot(plane.normal, towards), 0.02, 1.0);
    let slope = min(sqrt(1.0 - c * c) / c, 32.0);
    let bias = rays.bias_texels * texel * (1.0 + slope);
    let first = rays.start_texels * texel;
    let count = max(rays.rays, 1u);
    let samples = max(rays.samples, 1u);
    var reached = 0.0;
    for (var k = 0u; k < count; k++) {
        // A point of the light's disc (radius `size` across the rays).
        let ring = sqrt((f32(k) + noise.still.x) / f32(count)) * light.size;
        let angle = f32(k) * GOLDEN_ANGLE + 6.2831853 * noise.still.y;
        let across = (frame[0] * cos(angle) + frame[1] * sin(angle)) * ring;
        var dir: vec3<f32>;
        var last: f32;
        if plane.parallel {
            // Against the light's travel, tilted within its angular radius, until the ray's
            // depth reaches the map's near plane, or (maps without one near plane pass it at
            // -infinity) as far as the light's width spreads the rays `max_texels` texels
            // apart: a caster beyond casts a penumbra wider than PCSS's widest.
            dir = normalize(towards + across);
            let spread = light.max_texels * texel / max(light.size, 1e-6);
            last = min((start.y - light.near) / max(dot(dir, towards), 0.05), spread);
        } else {
            // To the point of the light's sphere, stopping at the map's near plane.
            let to = plane.apex + across - plane.point;
            let length = length(to);
            dir = to / max(length, 1e-30);
            last = length - light.near;
        }
        let jitter = fract(noise.still.x * 7.13 + noise.still.y * 3.71 + f32(k) * 0.7548777);
        // Whether the ray is under a surface, that surface's distance from the light (depths
        // of a parallel map may be negative) and where along the ray it was last seen under it.
        var is_under = false;
        var under = 0.0;
        var under_at = 0.0;
        var blocked = false;
        for (var j = 0u; j < samples && !blocked; j++) {
            let f = (f32(j) + jitter) / f32(samples);
            var t = first + max(last - first, 0.0) * f * f;
            var p = ray_point(plane, plane.point + dir * t);
            if !p.known {
                // Outside the map (or a virtual map's resident pages): nothing learnt.
                continue;
            }
            if p.ray > p.stored + bias {
                is_under = true;
                under = p.stored;
                under_at = t;
                continue;
            }
            if is_under {
                // Out from under a surface between `under_at` and `t`: find where.
                var out_at = t;
                for (var r = 0u; r < SMRT_REFINEMENTS; r++) {
                    let middle = 0.5 * (under_at + out_at);
                    let q = ray_point(plane, plane.point + dir * middle);
                    if q.known && q.ray > q.stored + bias {
                        under = q.stored;
                        under_at = middle;
                    } else {
                        // Out from under it by then (or past what the map holds).
                        out_at = middle;
                        if q.known {
                            p = q;
                        }
                    }
                }
                // Through the surface (the ray now as near the light as it), or beside it.
                blocked = p.ray < under + 2.0 * bias;
                is_under = false;
            }
        }
        // A ray still under a surface at its last sample comes out above it on its way to
        // the light.
        blocked = blocked || is_under;
        reached += select(1.0, 0.0, blocked);
    }
    return reached / f32(count);
}

// Filters, one per variant of the library's Rust `Filter` choice (`FILTER_` and its name in
// capitals); the library reads their values from here, so no number is kept twice.
const FILTER_NONE: u32 = 0u;
const FILTER_HARDWARE2X2: u32 = 1u;
const FILTER_PCF3X3: u32 = 2u;
const FILTER_PCF5X5: u32 = 3u;
const FILTER_PCF7X7: u32 = 4u;
const FILTER_PCF9X9: u32 = 5u;
const FILTER_POISSON: u32 = 6u;
const FILTER_PCSS: u32 = 7u;
const FILTER_STOCHASTIC: u32 = 8u;
const FILTER_PCF4X4: u32 = 9u;
const FILTER_PCF8X8: u32 = 10u;
const FILTER_PCF11X11: u32 = 11u;
const FILTER_PCF16X16: u32 = 12u;
const FILTER_PCF23X23: u32 = 13u;
const FILTER_SMRT: u32 = 14u;

// One light's filter (`MapFilter` in the library's Rust, written by `MapFilters::filter`).
#import "shadow-maps/map_filter.wgsl"

// Visibility at the receiver `plane` (1 = lit) through filter `f`: `frame` spans the plane
// across the light's rays, `texel` is a map texel's world size there and `noise` the pixel's
// (`filter_noise`); PCSS sizes its search from the map's `near` plane (scaled by distance on
// `perspective` maps).
fn filter_map(f: MapFilter, plane: TapPlane, frame: mat2x3<f32>, texel: f32, noise: FilterNoise, near: f32, perspective: bool) -> f32 {
    let r = noise.rotation;
    var visibility = 1.0;
    switch f.mode {
        case FILTER_NONE: { visibility = shadow_tap(plane.point, false); }
        case FILTER_HARDWARE2X2: { visibility = shadow_tap(plane.point, true); }
        case FILTER_PCF3X3: { visibility = grid_pcf(plane, frame, texel, 3); }
        case FILTER_PCF5X5: { visibility = grid_pcf(plane, frame, texel, 5); }
        case FILTER_PCF7X7: { visibility = grid_pcf(plane, frame, texel, 7); }
        case FILTER_PCF9X9: { visibility = grid_pcf(plane, frame, texel, 9); }
        case FILTER_PCF4X4: { visibility = grid_pcf(plane, frame, texel, 4); }
        case FILTER_PCF8X8: { visibility = grid_pcf(plane, frame, texel, 8); }
        case FILTER_PCF11X11: { visibility = grid_pcf(plane, frame, texel, 11); }
        case FILTER_PCF16X16: { visibility = grid_pcf(plane, frame, texel, 16); }
        case FILTER_PCF23X23: { visibility = grid_pcf(plane, frame, texel, 23); }
        case FILTER_POISSON: { visibility = poisson_pcf(plane, frame, f.kernel_texels * texel, r); }
        case FILTER_STOCHASTIC: { visibility = stochastic_pcf(plane, frame, f.kernel_texels * texel, noise.moving); }
        case FILTER_SMRT: {
            let light = PcssLight(f.light_size, near, perspective, f.search_texels);
            let rays = SmrtRays(f.rays, f.ray_samples, f.ray_start_texels, f.ray_bias_texels);
            visibility = smrt(plane, frame, texel, noise, light, rays);
        }
        default: {
            let light = PcssLight(f.light_size, near, perspective, f.search_texels);
            visibility = pcss(plane, frame, texel, r, light);
        }
    }
    return visibility;
}
