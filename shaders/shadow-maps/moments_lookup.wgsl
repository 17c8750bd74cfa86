// Moment shadow maps, the lookup: one full-screen pass per light reads the filtered moments at
// the receiver and asks the method for the visibility. The importer supplies the method:
//
//   fn moment_visibility(m: vec4<f32>, z: f32, bias: f32) -> f32
//       visibility of a receiver at light depth z behind filtered moments m, with the
//       method's bias in its own units.
//
// Points outside the maps are lit. The light-bleeding reduction is the same for every method:
// visibility below `bleeding_reduction` becomes 0 and the rest is rescaled to [0, 1].

#import "common/fullscreen.wgsl"
#import "shadow-maps/color_lookup.wgsl"
// One light's maps, the method's bias and the bleeding reduction (`MomentLight` in the
// library's Rust).
#import "shadow-maps/moment_light.wgsl"

@group(2) @binding(0) var<uniform> moment_light: MomentLight;

// The visibility at the pixel of `in`. No entry point here: the library composes the method
// and this file and adds `fs_moment_lookup`, which returns this.
fn moment_lookup(in: FullscreenOut) -> vec4<f32> {
    let r = map_receiver(moment_light.map, in.position.xy);
    let s = sample_color_map(moment_light.map, r.lookup);
    if !s.inside {
        return vec4<f32>(1.0);
    }
    let v = moment_visibility(s.value, s.depth, moment_light.bias);
    let cut = moment_light.bleeding_reduction;
    return vec4<f32>(clamp((v - cut) / (1.0 - cut), 0.0, 1.0));
}
