// Moment shadow maps, the depth pass's fragment stage: the moments a method stores for the
// light depth `z` (`light_depth`), which filter linearly unlike depth tests. The importer
// supplies the method:
//
//   fn moments(z: f32, spread: f32) -> vec4<f32>
//       what one texel stores; `spread` is z's variance over the texel (its slope, so that
//       surfaces sloped towards the light do not shadow themselves: Donnelly and Lauritzen
//       2006). The moments of the far plane (z = 1, no spread) are 1 in every channel: maps
//       clear to white.

#import "shadow-maps/depth_masked.wgsl"

// The moments of the fragment at `in`. No entry point here: the library composes the method
// and this file and adds `fs_moments`, which returns this.
fn store_moments(in: DepthVertex) -> vec4<f32> {
    let z = light_depth(layer_camera, in.world);
    let dx = dpdx(z);
    let dy = dpdy(z);
    return moments(z, 0.25 * (dx * dx + dy * dy));
}
