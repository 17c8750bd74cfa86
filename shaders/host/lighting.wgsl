// Deferred lighting: ambient + sum over lights of visibility * transmittance * direct + indirect.
// Every technique is shaded by this same pass from the visibility it wrote.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "common/fullscreen.wgsl"

@group(2) @binding(0) var visibility: texture_2d_array<f32>;
@group(2) @binding(1) var indirect: texture_2d<f32>;
// The colour each light keeps through translucent casters: a layer per visibility slot, or one
// white texel for techniques that do not write it.
@group(2) @binding(2) var transmittance: texture_2d_array<f32>;

// Light `light`'s transmittance colour at `pixel` (white where no technique wrote one).
fn light_transmittance(light: Light, pixel: vec2<i32>) -> vec3<f32> {
    let size = vec2<i32>(textureDimensions(transmittance));
    let slots = textureNumLayers(transmittance);
    let slot = min(light.slot_layer * 4u + light.slot_channel, slots - 1u);
    return textureLoad(transmittance, min(pixel, size - vec2<i32>(1)), slot, 0).rgb;
}

fn tonemap(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(1.0) - exp(-c);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.position.xy);
    let s = load_surface(pixel);
    if !s.valid {
        let sky = mix(vec3<f32>(0.02, 0.02, 0.025), vec3<f32>(0.05, 0.06, 0.08), in.uv.y);
        return vec4<f32>(sky, 1.0);
    }
    let view_dir = normalize(camera.position - s.position);
    var color = camera.ambient * s.albedo;
    // The light buffer holds the scene's lights (one dark placeholder when there are none).
    // Bounding the loop by the uniform light count would let lavapipe inline the camera
    // uniform and recompile this shader every time the camera moves.
    for (var i = 0u; i < arrayLength(&lights); i++) {
        let light = lights[i];
        if all(light.radiance == vec3<f32>(0.0)) {
            continue;
        }
        let v = textureLoad(visibility, pixel, light.slot_layer, 0)[light.slot_channel];
        if v > 0.0 {
            color += v * light_transmittance(light, pixel) * direct_light(light, s.position, s.normal, view_dir,
                                      s.albedo, s.specular, s.shininess);
        }
    }
    color += textureLoad(indirect, pixel, 0).rgb * s.albedo;
    return vec4<f32>(tonemap(color), 1.0);
}
