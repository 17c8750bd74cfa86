// The per-light uniform of rt-shadows' passes (group 2): `RtLight` in
// plugins/rt-shadows/src/lib.rs.

#import "rt-shadows/rt_light.wgsl"

@group(2) @binding(0) var<uniform> rt_light: RtLight;
