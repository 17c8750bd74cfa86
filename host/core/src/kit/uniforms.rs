//! Uniforms for many draws in one buffer, addressed by dynamic offsets.

use std::marker::PhantomData;

use crate::GpuContext;
use crate::kit::reflect::ReflectedBinding;
use crate::kit::stage::SharedGroup;

/// A value [`UniformSlots`] holds: a [`gpu_struct!`](crate::gpu_struct) type, laid out by
/// WGSL's rules.
pub trait UniformValue {
    /// Its size in bytes as the shader reads it.
    const SIZE: usize;
    /// The WGSL struct's name, by which stages recognise the variables it fills.
    const WGSL_TYPE: &'static str;
    /// Writes it at the start of `out` (at least [`Self::SIZE`] bytes).
    fn write_bytes(&self, out: &mut [u8]);
}

/// `count` values of `T`, each at a multiple of the device's
/// `min_uniform_buffer_offset_alignment`, with a bind group that exposes one value at a time
/// (binding 0, dynamic offset). Write the values for a frame, then bind with
/// [`Self::offset`] per draw.
pub struct UniformSlots<T: UniformValue> {
    label: String,
    stride: u64,
    usage: wgpu::BufferUsages,
    capacity: usize,
    buffer: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    _value: PhantomData<T>,
}

impl<T: UniformValue> UniformSlots<T> {
    /// Room for `capacity` values, visible to `visibility` stages.
    pub fn new(
        gpu: &GpuContext,
        label: &str,
        capacity: usize,
        visibility: wgpu::ShaderStages,
    ) -> UniformSlots<T> {
        let alignment = u64::from(gpu.device.limits().min_uniform_buffer_offset_alignment);
        let stride = (T::SIZE as u64).max(1).div_ceil(alignment) * alignment;
        let usage = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        Self::with_layout(gpu, label, capacity, visibility, (stride, usage))
    }

    /// As [`Self::new`], with the slots `stride` bytes apart (a multiple of 256, which divides
    /// every device's offset alignment) in a buffer that shaders may also read whole, as a
    /// storage array of `stride`-byte elements.
    pub fn readable_as_array(
        gpu: &GpuContext,
        label: &str,
        capacity: usize,
        visibility: wgpu::ShaderStages,
        stride: u64,
    ) -> UniformSlots<T> {
        assert!(
            stride.is_multiple_of(256) && stride >= T::SIZE as u64,
            "slots of {} bytes hold no {}-byte value at every alignment",
            stride,
            T::SIZE
        );
        let usage = wgpu::BufferUsages::UNIFORM
            | wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST;
        Self::with_layout(gpu, label, capacity, visibility, (stride, usage))
    }

    fn with_layout(
        gpu: &GpuContext,
        label: &str,
        capacity: usize,
        visibility: wgpu::ShaderStages,
        (stride, usage): (u64, wgpu::BufferUsages),
    ) -> UniformSlots<T> {
        let device = &gpu.device;
        let capacity = capacity.max(1);
        let buffer = Self::create_buffer(device, label, (stride, usage), capacity);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(&format!("{label} layout")),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(T::SIZE as u64),
                },
                count: None,
            }],
        });
        let bind_group = Self::bind(device, label, &layout, &buffer);
        UniformSlots {
            label: label.to_string(),
            stride,
            usage,
            capacity,
            buffer,
            layout,
            bind_group,
            _value: PhantomData,
        }
    }

    fn create_buffer(
        device: &wgpu::Device,
        label: &str,
        (stride, usage): (u64, wgpu::BufferUsages),
        capacity: usize,
    ) -> wgpu::Buffer {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: stride * capacity as u64,
            usage,
            mapped_at_creation: false,
        })
    }

    fn bind(
        device: &wgpu::Device,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        buffer: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&format!("{label} bind group")),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(T::SIZE as u64),
                }),
            }],
        })
    }

    /// Writes `values` from slot 0 on, growing the buffer (and replacing the bind group, whose
    /// layout stays the same) when they do not fit. Once per frame: queued writes all land
    /// before the frame is submitted, so a second write in the same frame replaces the first
    /// for every draw of that frame. Returns whether the buffer was replaced (bind groups
    /// others made over [`Self::buffer`] must then be made again).
    pub fn write(&mut self, gpu: &GpuContext, values: &[T]) -> bool {
        let grow = values.len() > self.capacity;
        if grow {
            self.capacity = values.len().next_power_of_two();
            let layout = (self.stride, self.usage);
            self.buffer = Self::create_buffer(&gpu.device, &self.label, layout, self.capacity);
            self.bind_group = Self::bind(&gpu.device, &self.label, &self.layout, &self.buffer);
        }
        let mut bytes = vec![0u8; self.stride as usize * values.len()];
        for (chunk, value) in bytes.chunks_exact_mut(self.stride as usize).zip(values) {
            value.write_bytes(chunk);
        }
        gpu.queue.write_buffer(&self.buffer, 0, &bytes);
        grow
    }

    /// The dynamic offset of slot `index`.
    pub fn offset(&self, index: usize) -> u32 {
        (self.stride * index as u64) as u32
    }

    /// Distance in bytes between slots (a multiple of the device's offset alignment).
    pub fn stride(&self) -> u64 {
        self.stride
    }

    /// The layout of [`Self::bind_group`].
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The bind group (binding 0: one `T`, dynamic offset).
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    /// The buffer, for the memory table.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }
}

impl<T: UniformValue> UniformSlots<T> {
    /// Slot `index`, as the group of stages whose shader reads one `T` as a uniform.
    pub fn at(&self, index: usize) -> UniformSlot<'_, T> {
        UniformSlot {
            slots: self,
            offset: [self.offset(index)],
        }
    }
}

/// One slot of [`UniformSlots`] (from [`UniformSlots::at`]): a [`SharedGroup`] that declares
/// a uniform of `T`'s WGSL type at binding 0.
pub struct UniformSlot<'a, T: UniformValue> {
    slots: &'a UniformSlots<T>,
    offset: [u32; 1],
}

impl<T: UniformValue> SharedGroup for UniformSlot<'_, T> {
    fn declares(&self, binding: &ReflectedBinding) -> bool {
        binding.entry.binding == 0
            && binding.type_name.as_deref() == Some(T::WGSL_TYPE)
            && matches!(
                binding.entry.ty,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    ..
                }
            )
    }
    fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.slots.layout
    }
    fn bound(&self) -> Option<(&wgpu::BindGroup, &[u32])> {
        Some((&self.slots.bind_group, &self.offset))
    }
}
