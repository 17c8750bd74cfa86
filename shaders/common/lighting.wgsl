// Direct lighting terms, identical for every technique (and matched by the CPU judge).
// Expects `common/frame.wgsl` to be imported first.

// Unit vector from `p` toward the light.
fn light_vector(light: Light, p: vec3<f32>) -> vec3<f32> {
    if light.kind == LIGHT_DIRECTIONAL {
        return -light.direction;
    }
    return normalize(light.position - p);
}

// Distance and cone falloff in [0, 1]; exactly 0 outside the range and the spot cone.
fn light_falloff(light: Light, p: vec3<f32>) -> f32 {
    if light.kind == LIGHT_DIRECTIONAL {
        return 1.0;
    }
    let d = distance(light.position, p);
    let ratio = d / light.range;
    let window = saturate(1.0 - ratio * ratio * ratio * ratio);
    var falloff = window * window / max(d * d, 1e-4);
    if light.kind == LIGHT_SPOT {
        let cos_angle = dot(normalize(p - light.position), light.direction);
        if cos_angle <= light.cos_outer {
            return 0.0;
        }
        falloff *= smoothstep(light.cos_outer, light.cos_inner, cos_angle);
    }
    return falloff;
}

// Unshadowed Lambert + Blinn-Phong radiance from one light.
fn direct_light(light: Light, p: vec3<f32>, n: vec3<f32>, view_dir: vec3<f32>,
                albedo: vec3<f32>, specular: f32, shininess: f32) -> vec3<f32> {
    let l = light_vector(light, p);
    let n_dot_l = dot(n, l);
    if n_dot_l <= 0.0 {
        return vec3<f32>(0.0);
    }
    let h = normalize(l + view_dir);
    let spec = specular * pow(max(dot(n, h), 0.0), max(shininess, 1.0));
    return light.radiance * light_falloff(light, p) * (albedo * n_dot_l + vec3<f32>(spec * n_dot_l));
}
