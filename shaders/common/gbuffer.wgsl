// G-buffer textures as read by lighting and techniques: bind group 1.
// World positions are rebuilt from the view-space depth (f32 bits, 0 on background pixels)
// along the ray through the pixel's centre; `reconstruct_position` in
// `zoo_host::render::gbuffer` is the CPU mirror.

@group(1) @binding(0) var gbuffer_view_depth: texture_2d<u32>;
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

// World-space ray through the centre of full-resolution `pixel`, scaled to unit view-space
// depth (any perspective projection, off-centre ones included).
fn pixel_ray(pixel: vec2<i32>) -> vec3<f32> {
    let ndc = vec2<f32>(
        (f32(pixel.x) + 0.5) / camera.size.x * 2.0 - 1.0,
        1.0 - (f32(pixel.y) + 0.5) / camera.size.y * 2.0,
    );
    let view_ray = vec3<f32>(
        (ndc.x + camera.proj[2][0]) / camera.proj[0][0],
        (ndc.y + camera.proj[2][1]) / camera.proj[1][1],
        -1.0,
    );
    let rotation = mat3x3<f32>(camera.view[0].xyz, camera.view[1].xyz, camera.view[2].xyz);
    return transpose(rotation) * view_ray;
}

fn load_surface(pixel: vec2<i32>) -> Surface {
    let depth = bitcast<f32>(textureLoad(gbuffer_view_depth, pixel, 0).r);
    let n = textureLoad(gbuffer_normal, pixel, 0);
    let a = textureLoad(gbuffer_albedo, pixel, 0);
    var s: Surface;
    s.position = camera.position + pixel_ray(pixel) * depth;
    s.normal = normalize(n.xyz + vec3<f32>(0.0, 0.0, 1e-9));
    s.albedo = a.rgb;
    s.specular = a.a;
    s.shininess = n.w * 256.0;
    s.valid = depth > 0.0;
    return s;
}
