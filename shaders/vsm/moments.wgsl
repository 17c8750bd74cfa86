// Variance shadow maps: the depth pass's fragment stage stores the first two moments of the
// light depth (`light_depth`), which filter linearly (bilinear, blur) unlike depth tests.

#import "shadow-maps/depth.wgsl"

@fragment
fn fs_moments(in: DepthVertex) -> @location(0) vec4<f32> {
    let z = light_depth(layer_camera, in.world);
    // The depth's spread over the texel joins the second moment (Donnelly and Lauritzen
    // 2006), so surfaces sloped towards the light do not shadow themselves.
    let dx = dpdx(z);
    let dy = dpdy(z);
    return vec4<f32>(z, z * z + 0.25 * (dx * dx + dy * dy), 0.0, 0.0);
}
