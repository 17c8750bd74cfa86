// Variance shadow maps: the lookup. The filtered moments (mean depth m1 and mean squared
// depth m2 over the filter region) bound the fraction of the region in front of a receiver at
// depth t by Chebyshev's one-sided inequality:
//     p_max = variance / (variance + (t - m1)^2)  for t > m1,  variance = m2 - m1^2.
// Where two casters at different depths share the region the bound is loose and light bleeds
// through; the reduction cuts visibility below `bleeding_reduction` to 0 and rescales the rest.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/fullscreen.wgsl"
#import "shadow-maps/layers.wgsl"

struct VsmLight {
    first_layer: u32,
    // 1 (spot, directional) or 6 (point: cube faces).
    layer_count: u32,
    // Index of the scene light.
    light: u32,
    perspective: u32,
    // World size of a texel: per unit of distance along the layer's axis (perspective) or
    // absolute (orthographic).
    texel_scale: f32,
    normal_offset: f32,
    min_variance: f32,
    bleeding_reduction: f32,
}

// One layer's camera in a 256-byte slot of the depth pass's uniform buffer.
struct CameraSlot {
    camera: LayerCamera,
    _pad: array<vec4<f32>, 7>,
}

@group(2) @binding(0) var<uniform> vsm: VsmLight;
@group(3) @binding(0) var moments: texture_2d_array<f32>;
@group(3) @binding(1) var moments_sampler: sampler;
@group(3) @binding(2) var<storage, read> cameras: array<CameraSlot>;

fn chebyshev_visibility(m: vec2<f32>, t: f32) -> f32 {
    if t <= m.x {
        return 1.0;
    }
    let variance = max(m.y - m.x * m.x, vsm.min_variance);
    let d = t - m.x;
    let p_max = variance / (variance + d * d);
    return clamp((p_max - vsm.bleeding_reduction) / (1.0 - vsm.bleeding_reduction), 0.0, 1.0);
}

// World size of one map texel at p.
fn texel_world(light: Light, p: vec3<f32>) -> f32 {
    if vsm.perspective == 0u {
        return vsm.texel_scale;
    }
    let d = p - light.position;
    if vsm.layer_count == 6u {
        let a = abs(d);
        return vsm.texel_scale * max(a.x, max(a.y, a.z));
    }
    return vsm.texel_scale * dot(d, light.direction);
}

@fragment
fn fs_vsm(in: FullscreenOut) -> @location(0) vec4<f32> {
    let s = load_surface(vec2<i32>(in.position.xy));
    if !s.valid {
        return vec4<f32>(1.0);
    }
    let light = lights[vsm.light];
    let p = s.position + s.normal * (vsm.normal_offset * texel_world(light, s.position));
    let layer = light_layer(vsm.first_layer, vsm.layer_count, light.position, p);
    let camera = cameras[layer].camera;
    let clip = camera.view_proj * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    // Points outside the map are lit.
    if clip.w <= 0.0 || any(abs(ndc.xy) > vec2<f32>(1.0)) || ndc.z < 0.0 || ndc.z > 1.0 {
        return vec4<f32>(1.0);
    }
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let m = textureSampleLevel(moments, moments_sampler, uv, layer, 0.0).xy;
    return vec4<f32>(chebyshev_visibility(m, light_depth(camera, p)));
}
