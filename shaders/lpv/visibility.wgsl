// Direct shadows of the light propagation volumes technique: each light's visibility from its
// shadow maps (the shadow-map library's maps, filtered by 3 x 3 PCF).

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "common/fullscreen.wgsl"
#import "shadow-maps/filters.wgsl"
#import "shadow-maps/depth_lookup.wgsl"

// One light's maps (`LpvShadow` in the plugin's Rust).
#import "lpv/lpv_shadow.wgsl"

@group(2) @binding(0) var<uniform> shadow: LpvShadow;

var<private> light_position: vec3<f32>;

fn shadow_tap(p: vec3<f32>, linear: bool) -> f32 {
    let layer = light_layer(shadow.first_layer, shadow.layer_count, light_position, p);
    return compare_map(map_point(layer, p), linear);
}

fn shadow_depths(p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn texel_world(p: vec3<f32>, light: Light) -> f32 {
    return map_texel_world(shadow.perspective == 1u, shadow.layer_count, shadow.texel_scale, light.position, light.direction, p);
}

@fragment
fn fs_visibility(in: FullscreenOut) -> @location(0) vec4<f32> {
    let s = load_surface(vec2<i32>(in.position.xy));
    if !s.valid {
        discard;
    }
    let light = lights[shadow.light];
    if light_falloff(light, s.position) <= 0.0 {
        discard;
    }
    light_position = light.position;
    let texel = texel_world(s.position, light);
    let p = s.position + s.normal * (shadow.normal_offset * texel);
    let parallel = light.kind == LIGHT_DIRECTIONAL;
    var direction = light.direction;
    if !parallel {
        direction = normalize(p - light.position);
    }
    let plane = TapPlane(p, s.normal, select(light.position, light.direction, parallel), parallel);
    return vec4<f32>(grid_pcf(plane, tangent_frame(direction), texel, 3));
}
