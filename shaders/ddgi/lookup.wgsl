// Every pixel's indirect light from the probes (ddgi), into the host's indirect target:
// irradiance over pi at the G-buffer's surface, seen from the eye.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "ddgi/probes.wgsl"

@compute @workgroup_size(8, 8, 1)
fn cs_lookup(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= u32(camera.size.x) || id.y >= u32(camera.size.y) {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let s = load_surface(pixel);
    var light = vec3<f32>(0.0);
    if s.valid {
        light = ddgi_irradiance(s.position, s.normal, normalize(s.position - camera.position));
    }
    textureStore(indirect_out, pixel, vec4<f32>(light, 1.0));
}
