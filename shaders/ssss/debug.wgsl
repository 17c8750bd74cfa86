// Debug views of the layered soft shadows, drawn into one colour image.

#import "common/frame.wgsl"
#import "common/gbuffer.wgsl"
#import "common/lighting.wgsl"
#import "ssss/data.wgsl"

// Views, one per `DebugView` variant of the plugin (`DEBUG_` and its name in capitals).
const DEBUG_LAYERS: u32 = 0u;
const DEBUG_PENUMBRA: u32 = 1u;
const DEBUG_HARD: u32 = 2u;
const DEBUG_BLURRED: u32 = 3u;
const DEBUG_TRANSLUCENCY: u32 = 4u;

@group(2) @binding(1) var penumbra: texture_2d_array<f32>;
@group(2) @binding(2) var bits: texture_2d_array<u32>;
@group(2) @binding(3) var visibility: texture_2d_array<f32>;
@group(2) @binding(4) var transmittance: texture_2d_array<f32>;
@group(2) @binding(5) var image: texture_storage_2d<rgba8unorm, write>;

// Distinct colours for layers (red, green, blue and yellow first, as in the seed's figure).
fn layer_color(layer: u32) -> vec3<f32> {
    switch layer % 8u {
        case 0u: { return vec3<f32>(1.0, 0.2, 0.2); }
        case 1u: { return vec3<f32>(0.2, 1.0, 0.2); }
        case 2u: { return vec3<f32>(0.25, 0.4, 1.0); }
        case 3u: { return vec3<f32>(1.0, 0.9, 0.2); }
        case 4u: { return vec3<f32>(1.0, 0.3, 1.0); }
        case 5u: { return vec3<f32>(0.2, 1.0, 1.0); }
        case 6u: { return vec3<f32>(1.0, 0.6, 0.2); }
        default: { return vec3<f32>(0.7, 0.7, 0.7); }
    }
}

fn heat(t: f32) -> vec3<f32> {
    let x = saturate(t);
    return saturate(vec3<f32>(3.0 * x, 3.0 * x - 1.0, 3.0 * x - 2.0));
}

@compute @workgroup_size(8, 8)
fn cs_debug(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.size);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let settings = data.settings;
    let s = load_surface(pixel);
    var color = vec3<f32>(0.0);
    if s.valid {
        let shade = 0.35 + 0.65 * abs((camera.view * vec4<f32>(s.normal, 0.0)).z);
        var covering = 0.0;
        var sum = vec3<f32>(0.0);
        var max_sigma = 0.0;
        for (var i = 0u; i < arrayLength(&data.lights); i++) {
            let sl = data.lights[i];
            if sl.layer_count == 0u || light_falloff(lights[i], s.position) <= 0.0 {
                continue;
            }
            let layer = sl.layer;
            covering += 1.0;
            let occluded = (textureLoad(bits, pixel, word_of(layer), 0).x & bit_of(layer)) != 0u;
            switch settings.debug_mode {
                case DEBUG_LAYERS: { sum += layer_color(layer); }
                case DEBUG_PENUMBRA: {
                    max_sigma = max(max_sigma, textureLoad(penumbra, pixel, group_of(layer), 0)[layer % 4u]);
                }
                case DEBUG_HARD: { sum += select(vec3<f32>(1.0), vec3<f32>(0.0), occluded); }
                case DEBUG_BLURRED: {
                    let slot = settings.layer_base + layer;
                    sum += vec3<f32>(textureLoad(visibility, pixel, group_of(slot), 0)[slot % 4u]);
                }
                default: {
                    if settings.translucent == 1u {
                        sum += textureLoad(transmittance, pixel, settings.layer_base + layer, 0).rgb;
                    } else {
                        sum += vec3<f32>(1.0);
                    }
                }
            }
        }
        if settings.debug_mode == DEBUG_PENUMBRA {
            color = heat(max_sigma / max(settings.params.max_blur, 1.0)) * 0.8 + 0.2 * shade;
        } else if covering > 0.0 {
            color = sum / covering * shade;
        } else {
            color = vec3<f32>(0.08) * shade;
        }
    }
    textureStore(image, pixel, vec4<f32>(color, 1.0));
}
