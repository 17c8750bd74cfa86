// G-buffer pass: view depth (f32 bits), normal + shininess, albedo + specular.

#import "common/frame.wgsl"
#import "common/materials.wgsl"
#import "common/vertices.wgsl"

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @builtin(instance_index) object: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) object: u32,
    @location(3) uv: vec2<f32>,
}

@vertex
fn vs_main(v: VertexIn, placement: Placement) -> VertexOut {
    let world = placed_position(placement, v.position);
    var out: VertexOut;
    out.clip = camera.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.normal = placed_normal(placement, v.normal);
    out.object = v.object;
    out.uv = v.uv;
    return out;
}

struct GBufferOut {
    // View-space depth (> 0) as bits; the clear value 0 marks the background.
    @location(0) view_depth: u32,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front: bool) -> GBufferOut {
    let object = objects[in.object];
    // Sampled before the alpha test: derivatives need uniform control flow.
    let texel = albedo_texel(in.object, in.uv);
    if !covered(in.object, in.uv) {
        discard;
    }
    var n = normalize(in.normal);
    // Back faces (open meshes seen from inside) are shaded from their visible side.
    if !front {
        n = -n;
    }
    var out: GBufferOut;
    out.view_depth = bitcast<u32>(-(camera.view * vec4<f32>(in.world, 1.0)).z);
    out.normal = vec4<f32>(n, object.material.x / 256.0);
    out.albedo = vec4<f32>(object.color.rgb * texel, object.color.a);
    return out;
}
