//! Keeps one rendered frame for the page: the renderer's output copied into a buffer and
//! mapped when the browser has it (nothing in a frame may wait for the GPU).

use std::sync::{Arc, Mutex};

use zoo_host::Renderer;
use zoo_host::gpu::readback::TextureCopy;

/// A frame's pixels (sRGB RGBA8, rows from the top).
pub struct Frame {
    /// Which frame it is, counted from 1.
    pub number: u64,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

/// The frame to keep, and where it lands once mapped.
pub struct Capture {
    wanted: Option<u64>,
    pub kept: Arc<Mutex<Option<Frame>>>,
}

impl Capture {
    /// Keeps frame `wanted` (counted from 1), if any.
    pub fn new(wanted: Option<u64>) -> Capture {
        Capture {
            wanted,
            kept: Arc::default(),
        }
    }

    /// Called after frame `number` was rendered: copies it out when it is the wanted one.
    pub fn after_frame(&mut self, number: u64, renderer: &Renderer) {
        if self.wanted != Some(number) {
            return;
        }
        self.wanted = None;
        let texture = renderer.output_texture();
        let (width, height) = (texture.width(), texture.height());
        let copy = TextureCopy::submit(
            renderer.gpu(),
            texture,
            0,
            zoo_host::wgpu::TextureAspect::All,
            4,
        );
        let kept = self.kept.clone();
        let buffer = copy.buffer.clone();
        buffer
            .slice(..)
            .map_async(zoo_host::wgpu::MapMode::Read, move |result| {
                if let Err(e) = result {
                    log::error!("cannot read frame {number} back: {e}");
                    return;
                }
                let rgba = match copy.buffer.slice(..).get_mapped_range() {
                    Ok(bytes) => copy.unpadded(&bytes),
                    Err(e) => {
                        log::error!("cannot read frame {number} back: {e}");
                        return;
                    }
                };
                copy.buffer.unmap();
                if let Ok(mut kept) = kept.lock() {
                    *kept = Some(Frame {
                        number,
                        width,
                        height,
                        rgba,
                    });
                }
            });
    }
}
