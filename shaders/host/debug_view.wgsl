// Shows one texture (G-buffer channel, visibility slot or technique resource) on screen.

#import "common/fullscreen.wgsl"

#import "host/view_params.wgsl"

@group(0) @binding(0) var<uniform> params: ViewParams;
@group(0) @binding(1) var source_float: texture_2d<f32>;
// A depth texture bound as unfilterable float (GLSL cannot fetch texels of depth textures).
@group(0) @binding(2) var source_depth: texture_2d<f32>;
@group(0) @binding(3) var source_uint: texture_2d<u32>;
@group(0) @binding(4) var source_volume: texture_3d<f32>;

// The output is sRGB-encoded on write; views show their values as they are, so they are
// decoded first.
fn display(c: vec3<f32>) -> vec4<f32> {
    let linear = select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
    return vec4<f32>(linear, params.opacity);
}

fn source_pixel(in: FullscreenOut, size: vec2<u32>) -> vec2<i32> {
    return vec2<i32>(min(vec2<u32>(in.uv * vec2<f32>(size)), size - vec2<u32>(1u)));
}

fn remap(v: f32) -> f32 {
    return saturate((v - params.min_value) / max(params.max_value - params.min_value, 1e-12));
}

@fragment
fn fs_float(in: FullscreenOut) -> @location(0) vec4<f32> {
    let texel = textureLoad(source_float, source_pixel(in, textureDimensions(source_float)), 0);
    if params.mode == 1u {
        return display(vec3<f32>(remap(texel[params.channel])));
    }
    return display(vec3<f32>(remap(texel.r), remap(texel.g), remap(texel.b)));
}

@fragment
fn fs_depth(in: FullscreenOut) -> @location(0) vec4<f32> {
    let d = textureLoad(source_depth, source_pixel(in, textureDimensions(source_depth)), 0).r;
    var v = d;
    if params.mode == 3u {
        if d >= 1.0 {
            return display(vec3<f32>(0.0));
        }
        v = params.near * params.far / (params.far - d * (params.far - params.near));
    }
    return display(vec3<f32>(1.0 - remap(v)));
}

@fragment
fn fs_uint(in: FullscreenOut) -> @location(0) vec4<f32> {
    let texel = textureLoad(source_uint, source_pixel(in, textureDimensions(source_uint)), 0);
    if params.mode == 5u {
        return display(vec3<f32>(remap(bitcast<f32>(texel[params.channel]))));
    }
    let v = texel.r;
    if v == 0u || params.mode != 4u {
        return display(vec3<f32>(0.0));
    }
    // Distinct hues for small integers.
    let h = fract(f32(v) * 0.618034);
    let c = saturate(abs(fract(vec3<f32>(h) + vec3<f32>(0.0, 2.0 / 3.0, 1.0 / 3.0)) * 6.0 - 3.0) - 1.0);
    return display(c);
}

// A slice of a 3D texture: across x shows z across and y up; across y, x across and z up;
// across z, x across and y up.
@fragment
fn fs_volume(in: FullscreenOut) -> @location(0) vec4<f32> {
    let size = vec3<i32>(textureDimensions(source_volume));
    let axis = min(params.slice_axis, 2u);
    let index = min(i32(params.slice_index), size[axis] - 1);
    let across = vec2<f32>(in.uv.x, 1.0 - in.uv.y);
    var texel: vec3<i32>;
    switch axis {
        case 0u: {
            texel = vec3<i32>(index, i32(across.y * f32(size.y)), i32(across.x * f32(size.z)));
        }
        case 1u: {
            texel = vec3<i32>(i32(across.x * f32(size.x)), index, i32(across.y * f32(size.z)));
        }
        default: {
            texel = vec3<i32>(i32(across.x * f32(size.x)), i32(across.y * f32(size.y)), index);
        }
    }
    let value = textureLoad(source_volume, clamp(texel, vec3<i32>(0), size - vec3<i32>(1)), 0);
    if params.mode == 1u {
        return display(vec3<f32>(remap(value[params.channel])));
    }
    return display(vec3<f32>(remap(value.r), remap(value.g), remap(value.b)));
}
