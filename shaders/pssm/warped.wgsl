// Warped single maps (LiSPSM, PSM): the lookup. Texel sizes vary over a warped map, so the
// lookup measures the texel's world size where it filters (finite differences of the map
// projection across the light's rays), and PCSS measures blocker distances in world space by
// unprojecting the stored depth.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/fullscreen.wgsl"
#import "shadow-maps/filters.wgsl"
#import "shadow-maps/depth_lookup.wgsl"
#import "pssm/density.wgsl"

// Per-light settings; everything that changes from frame to frame (the layer's matrices)
// is read from the layer cameras instead, because lavapipe recompiles a shader whose
// uniforms it inlined whenever their values change.
#import "pssm/warped_light.wgsl"

@group(2) @binding(0) var<uniform> warped: WarpedLight;

// Unit direction light rays travel at p.
fn ray_direction(light: Light, p: vec3<f32>) -> vec3<f32> {
    if light.kind == LIGHT_DIRECTIONAL {
        return light.direction;
    }
    return normalize(p - light.position);
}

// World size of one map texel at p across the rays (the larger side).
fn texel_world(p: vec3<f32>, frame: mat2x3<f32>) -> f32 {
    let step = 1e-3 * max(distance(p, camera.position), camera.near);
    let at = map_point(warped.layer, p).uv;
    let across = map_point(warped.layer, p + frame[0] * step).uv - at;
    let along = map_point(warped.layer, p + frame[1] * step).uv - at;
    let texels = min(length(across), length(along)) * warped.resolution / step;
    return 1.0 / max(texels, 1e-9);
}

// The world-space distance along the light to p: from the light (spot) or along its
// direction (directional).
fn light_distance(light: Light, p: vec3<f32>) -> f32 {
    if light.kind == LIGHT_DIRECTIONAL {
        return dot(p, light.direction);
    }
    return distance(p, light.position);
}

var<private> looked_up: Light;

// One comparison tap (the filters' map access).
fn shadow_tap(p: vec3<f32>, linear: bool) -> f32 {
    return compare_map(map_point(warped.layer, p), linear);
}

// (inside, receiver distance, blocker distance) at p, along the light in world units; the
// blocker's position comes from unprojecting the stored depth.
fn shadow_depths(p: vec3<f32>) -> vec3<f32> {
    let m = map_point(warped.layer, p);
    if !m.inside {
        return vec3<f32>(0.0);
    }
    let ndc = vec2<f32>(m.uv.x * 2.0 - 1.0, 1.0 - m.uv.y * 2.0);
    let inverse = layer_cameras[warped.layer].camera.inv_view_proj;
    let stored = inverse * vec4<f32>(ndc, stored_map_depth(m), 1.0);
    let blocker = stored.xyz / stored.w;
    return vec3<f32>(1.0, light_distance(looked_up, p), light_distance(looked_up, blocker));
}

struct Outputs {
    @location(0) visibility: vec4<f32>,
    // Effective texel density in false colour.
    @location(1) density: vec4<f32>,
}

@fragment
fn fs_warped(in: FullscreenOut) -> Outputs {
    var out: Outputs;
    out.visibility = vec4<f32>(1.0);
    out.density = vec4<f32>(0.0);
    let s = load_surface(vec2<i32>(in.position.xy));
    if !s.valid {
        return out;
    }
    let light = lights[warped.light];
    looked_up = light;
    // Write only where the light reaches, so lights with disjoint influence can share a slot.
    if light.kind != LIGHT_DIRECTIONAL {
        let to_surface = s.position - light.position;
        let d = length(to_surface);
        if d >= light.range || dot(to_surface, light.direction) <= light.cos_outer * d {
            discard;
        }
    }
    let frame = tangent_frame(ray_direction(light, s.position));
    let texel = texel_world(s.position, frame);
    let p = s.position + s.normal * (warped.normal_offset * texel);
    let noise = filter_noise(in.position.xy, camera.frame);
    // A warped map has no single near plane to size the PCSS blocker search by: the search
    // takes the largest radius (`search_texels`). Distances are measured from the light
    // (spot) or along it (directional, where only differences matter).
    let spot = light.kind != LIGHT_DIRECTIONAL;
    let near = select(-1e30, 0.0, spot);
    let plane = TapPlane(p, s.normal, select(light.direction, light.position, spot), !spot);
    let visibility = filter_map(warped.map_filter, plane, frame, texel, noise, near, spot);
    out.visibility = vec4<f32>(visibility);
    if warped.diagnostics == 1u {
        let depth = -(camera.view * vec4<f32>(s.position, 1.0)).z;
        out.density = vec4<f32>(density_colour(texels_per_pixel(depth, texel)), 1.0);
    }
    return out;
}
