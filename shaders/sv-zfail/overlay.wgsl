// The volumes debug view: volumes accumulated translucently, front faces orange, back faces
// blue.

#import "shadow-volumes/draw.wgsl"

@fragment
fn fs_volume_debug(@builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    return select(vec4<f32>(0.0, 0.04, 0.10, 1.0), vec4<f32>(0.10, 0.04, 0.0, 1.0), front);
}
