// Shadow-map lookup: one full-screen pass per light writes that light's visibility, filtered by
// the shadow-map library's filters through its header lookup (`shadow-maps/header_lookup.wgsl`),
// which projects each tap by itself (for point lights into whichever cube face it falls in),
// so filtering is seamless across cube faces.

#import "common/fullscreen.wgsl"
#import "shadow-maps/header_lookup.wgsl"

struct ShadowLight {
    map: MapHeader,
    map_filter: MapFilter,
    // 1 when this light's diagnostics are written.
    debug: u32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

// The light being looked up; the maps come from `shadow-maps/depth_lookup.wgsl` (group 3).
@group(2) @binding(0) var<uniform> shadow_light: ShadowLight;

struct Outputs {
    @location(0) visibility: vec4<f32>,
    // r: inside the map (coverage), g: receiver minus stored depth in texels.
    @location(1) diagnostics: vec4<f32>,
}

@fragment
fn fs_lookup(in: FullscreenOut) -> Outputs {
    let sl = shadow_light;
    let receiver = map_receiver(sl.map, in.position.xy);
    var out: Outputs;
    out.visibility = vec4<f32>(look_up(sl.map, sl.map_filter, receiver, in.position.xy));
    out.diagnostics = vec4<f32>(0.0);
    let position = receiver.surface.position;
    if sl.debug == 1u && header_point(sl.map, position).inside {
        let difference = header_depth_difference(sl.map, position);
        out.diagnostics = vec4<f32>(1.0, difference / receiver.texel, 0.0, 1.0);
    }
    return out;
}
