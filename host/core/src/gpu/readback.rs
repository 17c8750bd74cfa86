//! Copying textures back to the CPU.

use super::GpuContext;

/// Reads one layer (and aspect) of a 2D texture as tightly packed rows of `bytes_per_texel`.
pub fn read_texture(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    layer: u32,
    aspect: wgpu::TextureAspect,
    bytes_per_texel: u32,
) -> Vec<u8> {
    let copy = TextureCopy::submit(gpu, texture, layer, aspect, bytes_per_texel);
    copy.unpadded(&map_buffer(gpu, &copy.buffer))
}

/// A texture layer copied into a `MAP_READ` buffer, its rows padded to wgpu's alignment; map
/// it and call [`Self::unpadded`] (at once with [`map_buffer`], or later where nothing may
/// block, as in a browser).
pub struct TextureCopy {
    pub buffer: wgpu::Buffer,
    padded_row: u32,
    row: u32,
}

impl TextureCopy {
    /// Records and submits the copy of one layer (and aspect) of `texture`.
    pub fn submit(
        gpu: &GpuContext,
        texture: &wgpu::Texture,
        layer: u32,
        aspect: wgpu::TextureAspect,
        bytes_per_texel: u32,
    ) -> TextureCopy {
        let (width, height) = (texture.width(), texture.height());
        let row = width * bytes_per_texel;
        let padded_row =
            row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback buffer"),
            size: u64::from(padded_row * height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("readback encoder"),
            });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer,
                },
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        gpu.queue.submit([encoder.finish()]);
        TextureCopy {
            buffer,
            padded_row,
            row,
        }
    }

    /// The tightly packed rows of the mapped buffer's `bytes`.
    pub fn unpadded(&self, bytes: &[u8]) -> Vec<u8> {
        (bytes.chunks_exact(self.padded_row as usize))
            .flat_map(|row| &row[..self.row as usize])
            .copied()
            .collect()
    }
}

/// Texture copies read back without blocking a frame: each is mapped as soon as it is
/// submitted, and [`Self::take`] hands over all their bytes once every one has arrived.
pub struct PendingCopies {
    copies: Vec<TextureCopy>,
    states: Vec<std::sync::Arc<std::sync::Mutex<MapState>>>,
    taken: bool,
}

#[derive(Debug, Clone, PartialEq)]
enum MapState {
    Mapping,
    Mapped,
    Failed(String),
}

impl PendingCopies {
    /// Starts mapping every copy of `copies` (already submitted).
    pub fn map(copies: Vec<TextureCopy>) -> PendingCopies {
        let states = copies
            .iter()
            .map(|copy| {
                let state = std::sync::Arc::new(std::sync::Mutex::new(MapState::Mapping));
                let shared = state.clone();
                copy.buffer
                    .slice(..)
                    .map_async(wgpu::MapMode::Read, move |result| {
                        if let Ok(mut state) = shared.lock() {
                            *state = match result {
                                Ok(()) => MapState::Mapped,
                                Err(e) => MapState::Failed(e.to_string()),
                            };
                        }
                    });
                state
            })
            .collect();
        PendingCopies {
            copies,
            states,
            taken: false,
        }
    }

    /// Every copy's tightly packed bytes, in the order given, once all have arrived (waiting
    /// for the GPU when `wait`); `None` while some are still on their way. The bytes are handed
    /// over once: later calls return an error.
    pub fn take(&mut self, gpu: &GpuContext, wait: bool) -> Option<Result<Vec<Vec<u8>>, String>> {
        if self.taken {
            return Some(Err("the copies were already taken".into()));
        }
        if wait {
            gpu.wait_idle();
        } else {
            let _ = gpu.device.poll(wgpu::PollType::Poll);
        }
        let states: Vec<MapState> = (self.states.iter())
            .map(|s| s.lock().map_or(MapState::Mapping, |s| s.clone()))
            .collect();
        if let Some(MapState::Failed(e)) = states.iter().find(|s| matches!(s, MapState::Failed(_)))
        {
            return Some(Err(format!("buffer mapping failed: {e}")));
        }
        if states.contains(&MapState::Mapping) {
            return None;
        }
        self.taken = true;
        let mut all = Vec::with_capacity(self.copies.len());
        for copy in std::mem::take(&mut self.copies) {
            let bytes = match copy.buffer.slice(..).get_mapped_range() {
                Ok(view) => copy.unpadded(&view),
                Err(e) => return Some(Err(format!("buffer mapping failed: {e}"))),
            };
            copy.buffer.unmap();
            all.push(bytes);
        }
        Some(Ok(all))
    }
}

/// Maps a `MAP_READ` buffer, waits for it, and copies its contents out.
pub fn map_buffer(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Vec<u8> {
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        let _ = sender.send(result);
    });
    gpu.wait_idle();
    match receiver.recv() {
        Ok(Ok(())) => {
            let data = match slice.get_mapped_range() {
                Ok(view) => view.to_vec(),
                Err(e) => {
                    log::error!("buffer mapping failed: {e}");
                    return vec![0; buffer.size() as usize];
                }
            };
            buffer.unmap();
            data
        }
        other => {
            log::error!("buffer mapping failed: {other:?}");
            vec![0; buffer.size() as usize]
        }
    }
}

/// Converts little-endian f32 bytes.
pub fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// Converts little-endian IEEE half-float bytes.
pub fn f16s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(2)
        .map(|b| half_to_f32(u16::from_le_bytes([b[0], b[1]])))
        .collect()
}

fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = ((h >> 10) & 0x1f) as i32;
    let mantissa = (h & 0x3ff) as f32;
    sign * match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_floats_decode() {
        assert_eq!(half_to_f32(0x3c00), 1.0);
        assert_eq!(half_to_f32(0xc000), -2.0);
        assert_eq!(half_to_f32(0x3555), 0.333_251_95);
        assert_eq!(half_to_f32(0x0001), 2f32.powi(-24));
        assert!(half_to_f32(0x7e00).is_nan());
        assert_eq!(half_to_f32(0x7c00), f32::INFINITY);
    }
}

/// Small GPU results (counters, statistics) read back without stalling a frame: each frame
/// copies into a free staging buffer of the ring; reading maps the buffers whose frames have
/// been submitted, polls without waiting and returns the newest data that has arrived, so
/// results come a frame or two late. Call [`Self::target`] while recording and
/// [`Self::latest`] between frames (never between recording and submission).
pub struct ReadbackRing {
    slots: Vec<RingSlot>,
    latest: Option<(u64, Vec<u8>)>,
    frame: u64,
}

struct RingSlot {
    buffer: wgpu::Buffer,
    state: std::sync::Arc<std::sync::Mutex<SlotState>>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum SlotState {
    Free,
    /// Copied into during frame `n`; not yet mapped.
    Written(u64),
    Mapping(u64),
    Mapped(u64),
    Failed,
}

impl ReadbackRing {
    /// `slots` staging buffers of `size` bytes.
    pub fn new(device: &wgpu::Device, label: &str, size: u64, slots: usize) -> ReadbackRing {
        ReadbackRing {
            slots: (0..slots.max(2))
                .map(|i| RingSlot {
                    buffer: device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(&format!("{label} readback {i}")),
                        size: size.max(4).next_multiple_of(4),
                        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                        mapped_at_creation: false,
                    }),
                    state: std::sync::Arc::new(std::sync::Mutex::new(SlotState::Free)),
                })
                .collect(),
            latest: None,
            frame: 0,
        }
    }

    /// A buffer to copy this frame's results into: a free one, else the oldest one written but
    /// not yet read (its older results are superseded; copies stay in GPU order), or `None`
    /// when every buffer is being mapped (this frame's results are then skipped).
    pub fn target(&mut self) -> Option<&wgpu::Buffer> {
        self.frame += 1;
        let frame = self.frame;
        let state_of = |s: &RingSlot| *s.state.lock().expect("ring state");
        let free = self
            .slots
            .iter()
            .position(|s| state_of(s) == SlotState::Free);
        let oldest_written = || {
            self.slots
                .iter()
                .enumerate()
                .filter_map(|(i, s)| match state_of(s) {
                    SlotState::Written(f) => Some((f, i)),
                    _ => None,
                })
                .min()
                .map(|(_, i)| i)
        };
        let index = free.or_else(oldest_written)?;
        let slot = &self.slots[index];
        *slot.state.lock().expect("ring state") = SlotState::Written(frame);
        Some(&slot.buffer)
    }

    /// The frames counted so far by [`Self::target`] calls (the last one's number).
    pub fn frames(&self) -> u64 {
        self.frame
    }

    /// The newest results that have arrived (and the frame they come from, counted by
    /// [`Self::target`] calls), without waiting for the GPU.
    pub fn latest(&mut self, device: &wgpu::Device) -> Option<(u64, &[u8])> {
        for slot in &self.slots {
            let written = {
                let mut state = slot.state.lock().expect("ring state");
                match *state {
                    SlotState::Written(frame) => {
                        *state = SlotState::Mapping(frame);
                        Some(frame)
                    }
                    _ => None,
                }
            };
            if let Some(frame) = written {
                let shared = slot.state.clone();
                slot.buffer
                    .slice(..)
                    .map_async(wgpu::MapMode::Read, move |result| {
                        if let Ok(mut state) = shared.lock() {
                            *state = match result {
                                Ok(()) => SlotState::Mapped(frame),
                                Err(_) => SlotState::Failed,
                            };
                        }
                    });
            }
        }
        let _ = device.poll(wgpu::PollType::Poll);
        for slot in &self.slots {
            let mut state = slot.state.lock().expect("ring state");
            match *state {
                SlotState::Mapped(frame) => {
                    if self.latest.as_ref().is_none_or(|(f, _)| *f < frame)
                        && let Ok(view) = slot.buffer.slice(..).get_mapped_range()
                    {
                        self.latest = Some((frame, view.to_vec()));
                    }
                    slot.buffer.unmap();
                    *state = SlotState::Free;
                }
                SlotState::Failed => *state = SlotState::Free,
                _ => {}
            }
        }
        self.latest
            .as_ref()
            .map(|(frame, data)| (*frame, data.as_slice()))
    }
}
