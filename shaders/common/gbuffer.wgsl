// G-buffer textures as read by lighting and techniques: bind group 1.
// position.w is 1 where geometry was drawn and 0 on background pixels.

@group(1) @binding(0) var gbuffer_position: texture_2d<f32>;
@group(1) @binding(1) var gbuffer_normal: texture_2d<f32>;
@group(1) @binding(2) var gbuffer_albedo: texture_2d<f32>;

struct Surface {
    position: vec3<f32>,
    normal: vec3<f32>,
    albedo: vec3<f32>,
    specular: f32,
    shininess: f32,
    valid: bool,
}

fn load_surface(pixel: vec2<i32>) -> Surface {
    let p = textureLoad(gbuffer_position, pixel, 0);
    let n = textureLoad(gbuffer_normal, pixel, 0);
    let a = textureLoad(gbuffer_albedo, pixel, 0);
    var s: Surface;
    s.position = p.xyz;
    s.normal = normalize(n.xyz + vec3<f32>(0.0, 0.0, 1e-9));
    s.albedo = a.rgb;
    s.specular = a.a;
    s.shininess = n.w * 256.0;
    s.valid = p.w > 0.5;
    return s;
}
