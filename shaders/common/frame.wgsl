// Per-frame data shared by the host and every technique: bind group 0.
// Layouts mirror `zoo_host::render::frame` (CameraUniform, GpuLight, GpuObject).

struct Camera {
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    position: vec3<f32>,
    near: f32,
    size: vec2<f32>,
    far: f32,
    light_count: u32,
    ambient: vec3<f32>,
    _pad: f32,
}

const LIGHT_DIRECTIONAL: u32 = 0u;
const LIGHT_POINT: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;

struct Light {
    position: vec3<f32>,
    kind: u32,
    // Unit direction the light travels (directional, spot).
    direction: vec3<f32>,
    range: f32,
    // Colour times intensity.
    radiance: vec3<f32>,
    // Emitter radius (point, spot) or angular radius in radians (directional).
    radius: f32,
    cos_outer: f32,
    cos_inner: f32,
    // Visibility slot of this light: array layer and channel (0..3).
    slot_layer: u32,
    slot_channel: u32,
}

struct Object {
    model: mat4x4<f32>,
    // rgb albedo, a specular strength.
    color: vec4<f32>,
    // x shininess, y casts shadows (0 or 1).
    material: vec4<f32>,
    // Translucent casters: rgb the colour they let through, w = 1; opaque casters: all 0.
    transmittance: vec4<f32>,
}

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> objects: array<Object>;
