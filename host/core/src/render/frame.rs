//! Bind group 0: camera, lights and objects, laid out as in `shaders/common/frame.wgsl`.

use glam::{Mat4, UVec2, UVec4, Vec2, Vec3, Vec4};

use super::visibility::SlotAssignment;
use crate::gpu::{GpuContext, GpuType, gpu_bytes};
use crate::scene::{Camera, Light, LightKind, Scene};

crate::gpu_struct! {
    "common/camera.wgsl" =>
    /// `Camera` in WGSL (`common/frame.wgsl` aliases it).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct CameraUniform {
        pub view: Mat4,
        pub proj: Mat4,
        pub view_proj: Mat4,
        pub inv_view_proj: Mat4,
        pub position: Vec3,
        pub near: f32,
        /// Output size in pixels.
        pub size: Vec2,
        pub far: f32,
        pub light_count: u32,
        pub ambient: Vec3,
        /// Frames this renderer rendered before this one: the per-frame seed of stochastic
        /// filters (0 for the first frame, so a fresh renderer's frames repeat exactly).
        pub frame: u32,
    }
}

crate::gpu_struct! {
    "common/light.wgsl" =>
    /// `Light` in WGSL (`common/frame.wgsl` aliases it).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct GpuLight {
        pub position: Vec3,
        /// `LIGHT_DIRECTIONAL`, `LIGHT_POINT` or `LIGHT_SPOT` in `common/frame.wgsl`.
        pub kind: u32,
        /// Unit direction the light travels (directional, spot).
        pub direction: Vec3,
        pub range: f32,
        /// Colour times intensity.
        pub radiance: Vec3,
        /// Emitter radius (point, spot) or angular radius in radians (directional).
        pub radius: f32,
        pub cos_outer: f32,
        pub cos_inner: f32,
        /// Visibility slot of this light: array layer and channel (0..3).
        pub slot_layer: u32,
        pub slot_channel: u32,
    }
}

crate::gpu_struct! {
    "common/object.wgsl" =>
    /// `Object` in WGSL (`common/frame.wgsl` aliases it).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct GpuObject {
        /// [`crate::scene::SceneObject::placement`]: stored vertices to world space.
        pub placement: Mat4,
        /// rgb albedo, a specular strength.
        pub color: Vec4,
        /// x shininess, y casts shadows (0 or 1).
        pub material: Vec4,
        /// Translucent casters: the colour they let through and w = 1; opaque: (0, 0, 0, 0).
        pub transmittance: Vec4,
        /// Its first drawn triangle (instances counted, in object order), its first stored
        /// triangle, its triangle count, 0.
        pub drawn: UVec4,
    }
}

/// The view and projection of the current camera at the current size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraMatrices {
    pub view: Mat4,
    pub proj: Mat4,
    pub view_proj: Mat4,
    /// Camera position.
    pub eye: Vec3,
    /// Output size the projection was made for.
    pub size: UVec2,
}

impl CameraMatrices {
    /// Matrices of `camera` for an output of `size` pixels.
    pub fn new(camera: &Camera, size: UVec2) -> CameraMatrices {
        let view = camera.view();
        let proj = camera.projection(size.x as f32 / size.y.max(1) as f32);
        CameraMatrices {
            view,
            proj,
            view_proj: proj * view,
            eye: camera.position,
            size,
        }
    }
}

impl GpuLight {
    /// GPU form of `light` writing into `slot` = (layer, channel).
    pub fn new(light: &Light, slot: (u32, u32)) -> GpuLight {
        let outer = light.spot_angle;
        let inner = outer * (1.0 - light.spot_softness);
        GpuLight {
            position: light.position,
            kind: match light.kind {
                LightKind::Directional => 0,
                LightKind::Point => 1,
                LightKind::Spot => 2,
            },
            direction: light.direction,
            range: if light.range.is_finite() {
                light.range
            } else {
                f32::MAX
            },
            radiance: light.radiance,
            radius: light.radius,
            cos_outer: outer.cos(),
            cos_inner: inner.cos(),
            slot_layer: slot.0,
            slot_channel: slot.1,
        }
    }
}

/// Buffers and bind group 0.
pub struct FrameBindings {
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    pub camera_buffer: wgpu::Buffer,
    pub light_buffer: wgpu::Buffer,
    pub object_buffer: wgpu::Buffer,
    /// Matrices last uploaded.
    pub matrices: CameraMatrices,
    /// Frames uploaded so far (the next frame's [`CameraUniform::frame`]).
    pub frames: u32,
}

/// The variables of the frame group as `common/frame.wgsl` declares them (a kit test checks).
pub const FRAME_VARIABLES: &[&str] = &["camera", "lights", "objects"];

/// Layout of bind group 0 (`common/frame.wgsl`).
pub fn frame_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let storage = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("frame bind group layout"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            storage(1),
            storage(2),
        ],
    })
}

impl FrameBindings {
    /// Creates the buffers for `scene` (its light count fixes the light buffer's size).
    pub fn new(gpu: &GpuContext, scene: &Scene) -> FrameBindings {
        let device = &gpu.device;
        let layout = frame_layout(device);
        let buffer = |label: &str, size: usize, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16) as u64,
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let camera_buffer = buffer(
            "camera uniform",
            CameraUniform::SIZE,
            wgpu::BufferUsages::UNIFORM,
        );
        let object_buffer = buffer(
            "objects storage",
            GpuObject::SIZE * scene.objects.len(),
            wgpu::BufferUsages::STORAGE,
        );
        let light_capacity = scene.lights.len();
        let mut drawn = 0;
        let objects: Vec<GpuObject> = scene
            .objects
            .iter()
            .map(|o| GpuObject {
                placement: o.placement,
                drawn: {
                    let (first, count) = (o.indices.start / 3, o.indices.len() / 3);
                    drawn += count;
                    UVec4::new((drawn - count) as u32, first as u32, count as u32, 0)
                },
                color: o.color.extend(o.specular),
                material: Vec4::new(o.shininess, f32::from(u8::from(o.casts_shadows)), 0.0, 0.0),
                transmittance: o.transmittance().map_or(Vec4::ZERO, |t| t.extend(1.0)),
            })
            .collect();
        gpu.queue
            .write_buffer(&object_buffer, 0, &gpu_bytes(&objects));
        let light_buffer = light_buffer(gpu, light_capacity);
        let bind_group = bind_group(gpu, &layout, &camera_buffer, &light_buffer, &object_buffer);
        FrameBindings {
            layout,
            bind_group,
            camera_buffer,
            light_buffer,
            object_buffer,
            matrices: CameraMatrices::new(&scene.camera, UVec2::ONE),
            frames: 0,
        }
    }

    /// Resizes the light buffer for `count` lights.
    pub fn set_light_capacity(&mut self, gpu: &GpuContext, count: usize) {
        self.light_buffer = light_buffer(gpu, count);
        self.bind_group = bind_group(
            gpu,
            &self.layout,
            &self.camera_buffer,
            &self.light_buffer,
            &self.object_buffer,
        );
    }

    /// Uploads the camera, ambient term and lights with their slots, and counts the frame.
    pub fn update(
        &mut self,
        gpu: &GpuContext,
        camera: &Camera,
        ambient: Vec3,
        lights: &[Light],
        slots: &SlotAssignment,
        size: UVec2,
    ) {
        let m = CameraMatrices::new(camera, size);
        let uniform = CameraUniform {
            view: m.view,
            proj: m.proj,
            view_proj: m.view_proj,
            inv_view_proj: m.view_proj.inverse(),
            position: camera.position,
            near: camera.near,
            size: size.as_vec2(),
            far: camera.far,
            light_count: lights.len() as u32,
            ambient,
            frame: self.frames,
        };
        self.frames = self.frames.wrapping_add(1);
        gpu.queue
            .write_buffer(&self.camera_buffer, 0, &gpu_bytes(&[uniform]));
        let gpu_lights: Vec<GpuLight> = lights
            .iter()
            .enumerate()
            .map(|(i, l)| GpuLight::new(l, slots.slot(i)))
            .collect();
        gpu.queue
            .write_buffer(&self.light_buffer, 0, &gpu_bytes(&gpu_lights));
        self.matrices = m;
    }
}

fn light_buffer(gpu: &GpuContext, count: usize) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("lights storage"),
        size: (GpuLight::SIZE * count.max(1)) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn bind_group(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    camera: &wgpu::Buffer,
    lights: &wgpu::Buffer,
    objects: &wgpu::Buffer,
) -> wgpu::BindGroup {
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("frame bind group"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: camera.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: lights.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: objects.as_entire_binding(),
            },
        ],
    })
}
