// Shadow-map lookup: one full-screen pass per light writes that light's visibility, filtered by
// the shadow-map library's filters through its header lookup (`shadow-maps/header_lookup.wgsl`),
// which projects each tap by itself (for point lights into whichever cube face it falls in),
// so filtering is seamless across cube faces. Technique `contact-shadows` adds a march toward
// the light through the depth buffer.

#import "common/fullscreen.wgsl"
#import "shadow-maps/header_lookup.wgsl"
#import "common/screen_space.wgsl"

// One light's maps, filter, diagnostics switch and contact march (`ShadowLight` in the
// plugin's Rust).
#import "sm-pcf/shadow_light.wgsl"

// The light being looked up; the maps come from `shadow-maps/depth_lookup.wgsl` (group 3).
@group(2) @binding(0) var<uniform> shadow_light: ShadowLight;

struct Outputs {
    @location(0) visibility: vec4<f32>,
    // r: inside the map (coverage), g: receiver minus stored depth in texels.
    @location(1) diagnostics: vec4<f32>,
}

// Contact shadows: a march toward the light through the depth buffer over the few map texels
// near a contact where bias and normal offset let the map miss its casters.
fn contact_visibility(sl: ShadowLight, r: Receiver, pixel: vec2<f32>) -> f32 {
    let light = lights[sl.map.light];
    let p = r.surface.position;
    var direction = -light.direction;
    var reach = sl.contact_texels * r.texel;
    if light.kind != LIGHT_DIRECTIONAL {
        let to_light = light.position - p;
        direction = normalize(to_light);
        reach = min(reach, 0.99 * length(to_light));
    }
    if dot(direction, r.surface.normal) <= 0.0 {
        return 1.0;
    }
    let thickness = sl.contact_thickness * reach;
    let jitter = interleaved_gradient_noise(pixel);
    return screen_space_visibility(ScreenMarch(p, direction, reach, sl.contact_steps, thickness, jitter));
}

@fragment
fn fs_lookup(in: FullscreenOut) -> Outputs {
    let sl = shadow_light;
    let receiver = map_receiver(sl.map, in.position.xy);
    var visibility = look_up(sl.map, sl.map_filter, receiver, in.position.xy);
    if sl.contact_steps > 0u && visibility > 0.0 {
        visibility *= contact_visibility(sl, receiver, in.position.xy);
    }
    var out: Outputs;
    out.visibility = vec4<f32>(visibility);
    out.diagnostics = vec4<f32>(0.0);
    let position = receiver.surface.position;
    if sl.debug == 1u && header_point(sl.map, position).inside {
        let difference = header_depth_difference(sl.map, position);
        out.diagnostics = vec4<f32>(1.0, difference / receiver.texel, 0.0, 1.0);
    }
    return out;
}
