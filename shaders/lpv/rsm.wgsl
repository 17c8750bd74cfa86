// Reflective shadow map (seed 002 §4): every texel a virtual point light. Writes, from one
// light's view, the light the visible surface reflects (rgb: albedo x radiance x falloff x the
// texel's area across the light's rays, so a texel's intensity is that times the cosine to
// its normal, zero where the surface faces away), its normal and area (w), and its position
// (relative to the scene's centre: 16-bit floats keep 1e-3 of the scene's size, and every
// backend renders them).

// Alpha-masked surfaces reflect nothing where their masks have holes, and albedo textures
// colour the reflected light, as in the G-buffer.

#import "common/frame.wgsl"
#import "common/lighting.wgsl"
#import "common/vertices.wgsl"
#import "common/materials.wgsl"
#import "lpv/rsm_camera.wgsl"

@group(2) @binding(0) var<uniform> rsm_camera: RsmCamera;

struct RsmVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) object: u32,
    @location(3) uv: vec2<f32>,
}

@vertex
fn vs_rsm(
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @builtin(instance_index) object: u32,
    placement: Placement,
) -> RsmVertex {
    let world = placed_position(placement, position);
    var out: RsmVertex;
    out.clip = rsm_camera.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.normal = placed_normal(placement, normal);
    out.object = object;
    out.uv = uv;
    return out;
}

struct RsmTexel {
    @location(0) flux: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) position: vec4<f32>,
}

@fragment
fn fs_rsm(v: RsmVertex, @builtin(front_facing) front: bool) -> RsmTexel {
    let textured = albedo_texel(v.object, v.uv);
    if !covered(v.object, v.uv) {
        discard;
    }
    let light = lights[rsm_camera.light];
    var n = normalize(v.normal);
    let l = light_vector(light, v.world);
    // Two-sided: the side that faces the light reflects.
    if dot(n, l) < 0.0 && !front {
        n = -n;
    }
    let cosine = max(dot(n, l), 0.0);
    var texel = rsm_camera.axis.w;
    if rsm_camera.eye.w > 0.0 {
        texel *= dot(v.world - rsm_camera.eye.xyz, rsm_camera.axis.xyz);
    }
    let across = texel * texel;
    let albedo = saturate(objects[v.object].color.rgb * textured);
    var out: RsmTexel;
    out.flux = vec4<f32>(select(vec3<f32>(0.0), albedo * light.radiance * light_falloff(light, v.world) * across, cosine > 0.0), 1.0);
    out.normal = vec4<f32>(n, across / max(cosine, 0.05));
    out.position = vec4<f32>(v.world - rsm_camera.origin.xyz, 1.0);
    return out;
}
