//! Reading frames back: the output image, a light's visibility and the G-buffer, at once
//! (waiting for the GPU) or without blocking a frame ([`Renderer::request_readout`]).

use glam::{UVec2, Vec3, Vec4};

use super::Renderer;
use crate::gpu::readback::{self, PendingCopies, TextureCopy};
use crate::render::frame::CameraMatrices;

/// The G-buffer as read back for the judge: one entry per pixel, row-major from the top.
#[derive(Debug, Clone)]
pub struct GBufferData {
    pub size: UVec2,
    /// The camera position it was rendered from.
    pub eye: Vec3,
    /// World position; w = 1 on geometry, 0 on background.
    pub positions: Vec<Vec4>,
    /// World normal (facing the camera).
    pub normals: Vec<Vec3>,
    /// Albedo (rgb), specular strength and shininess per pixel.
    pub materials: Vec<crate::scene::shading::Material>,
}

impl Renderer {
    /// The output image's view (sRGB RGBA8), e.g. to show it in a UI.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.output_view
    }

    /// The output image's texture (sRGB RGBA8).
    pub fn output_texture(&self) -> &wgpu::Texture {
        &self.output
    }

    /// The output image (sRGB RGBA8).
    pub fn read_output(&self) -> image::RgbaImage {
        decode_output(self.size, self.read(&self.output, 0, 4))
    }

    /// Visibility of light `light` per pixel, in [0, 1].
    pub fn read_visibility(&self, light: usize) -> Vec<f32> {
        let (layer, channel) = self.visibility.slots.slot(light);
        decode_visibility(&self.read(&self.visibility.texture, layer, 4), channel)
    }

    /// The colour light `light` keeps through translucent casters per pixel, in [0, 1]
    /// (white everywhere when the technique does not write transmittance).
    pub fn read_transmittance(&self, light: usize) -> Vec<Vec3> {
        if !self.transmittance.in_use {
            return vec![Vec3::ONE; (self.size.x * self.size.y) as usize];
        }
        let (layer, channel) = self.visibility.slots.slot(light);
        decode_transmittance(&self.read(&self.transmittance.texture, layer * 4 + channel, 4))
    }

    /// The indirect light per pixel (irradiance over π; zero unless the technique adds light).
    pub fn read_indirect(&self) -> Vec<Vec3> {
        readback::f16s(&self.read(&self.indirect.texture, 0, 8))
            .chunks_exact(4)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect()
    }

    /// World positions and normals per pixel.
    pub fn read_gbuffer(&self) -> GBufferData {
        // The camera the G-buffer was rendered with (the last one uploaded).
        decode_gbuffer(
            &self.frame.matrices,
            self.size,
            [
                self.read(&self.gbuffer.view_depth, 0, 4),
                self.read(&self.gbuffer.normal, 0, 8),
                self.read(&self.gbuffer.albedo, 0, 4),
            ],
        )
    }

    /// Starts copying what `request` names out of the last frame, to collect later without
    /// waiting ([`PendingReadout::poll`]).
    pub fn request_readout(&self, request: ReadoutRequest) -> PendingReadout {
        let mut copies = Vec::new();
        let mut copy = |texture: &wgpu::Texture, layer: u32, bytes_per_texel: u32| {
            copies.push(TextureCopy::submit(
                &self.gpu,
                texture,
                layer,
                wgpu::TextureAspect::All,
                bytes_per_texel,
            ));
            copies.len() - 1
        };
        let gbuffer = request.gbuffer.then(|| {
            [
                copy(&self.gbuffer.view_depth, 0, 4),
                copy(&self.gbuffer.normal, 0, 8),
                copy(&self.gbuffer.albedo, 0, 4),
            ]
        });
        let output = request.output.then(|| copy(&self.output, 0, 4));
        let coloured = self.transmittance.in_use
            && (self.technique_instance()).writes_transmittance(&self.scene);
        let mut layers = std::collections::HashMap::new();
        let lights = match request.lights {
            false => Vec::new(),
            true => (0..self.lights.len())
                .map(|light| {
                    let (layer, channel) = self.visibility.slots.slot(light);
                    let visibility = *(layers.entry(layer))
                        .or_insert_with(|| copy(&self.visibility.texture, layer, 4));
                    let transmittance =
                        coloured.then(|| copy(&self.transmittance.texture, layer * 4 + channel, 4));
                    (visibility, channel, transmittance)
                })
                .collect(),
        };
        PendingReadout {
            copies: PendingCopies::map(copies),
            matrices: self.frame.matrices,
            size: self.size,
            gbuffer,
            output,
            lights,
        }
    }

    /// One layer of `texture`, read at once.
    fn read(&self, texture: &wgpu::Texture, layer: u32, bytes_per_texel: u32) -> Vec<u8> {
        let aspect = wgpu::TextureAspect::All;
        readback::read_texture(&self.gpu, texture, layer, aspect, bytes_per_texel)
    }
}

/// What to copy out of a frame with [`Renderer::request_readout`].
#[derive(Debug, Clone, Copy, Default)]
pub struct ReadoutRequest {
    /// The G-buffer's positions, normals and materials.
    pub gbuffer: bool,
    /// The output image.
    pub output: bool,
    /// Every light's visibility (and transmittance, where the technique writes it).
    pub lights: bool,
}

/// Copies of a frame on their way back ([`Renderer::request_readout`]).
pub struct PendingReadout {
    copies: PendingCopies,
    matrices: CameraMatrices,
    size: UVec2,
    /// Indices into the copies: depth, normal and albedo.
    gbuffer: Option<[usize; 3]>,
    output: Option<usize>,
    /// Per light: its visibility layer's copy and channel, and its transmittance copy.
    lights: Vec<(usize, u32, Option<usize>)>,
}

impl PendingReadout {
    /// The readout once every copy has arrived (waiting for the GPU when `wait`), else `None`;
    /// an error when the GPU could not map them. Returns it once.
    pub fn poll(
        &mut self,
        gpu: &crate::gpu::GpuContext,
        wait: bool,
    ) -> Option<Result<Readout, String>> {
        let copies = match self.copies.take(gpu, wait)? {
            Ok(copies) => copies,
            Err(e) => return Some(Err(e)),
        };
        let gbuffer = self.gbuffer.map(|[depth, normal, albedo]| {
            let bytes = [depth, normal, albedo].map(|i| copies[i].clone());
            decode_gbuffer(&self.matrices, self.size, bytes)
        });
        let output = (self.output).map(|i| decode_output(self.size, copies[i].clone()));
        let (visibility, transmittance) = (self.lights.iter())
            .map(|&(layer, channel, transmittance)| {
                (
                    decode_visibility(&copies[layer], channel),
                    transmittance.map(|i| decode_transmittance(&copies[i])),
                )
            })
            .unzip();
        Some(Ok(Readout {
            gbuffer,
            output,
            visibility,
            transmittance,
        }))
    }
}

/// A frame's copies, decoded.
pub struct Readout {
    pub gbuffer: Option<GBufferData>,
    pub output: Option<image::RgbaImage>,
    /// Per light (when requested): visibility per pixel, in [0, 1].
    pub visibility: Vec<Vec<f32>>,
    /// Per light (when requested): the colour kept through translucent casters, where the
    /// technique writes it.
    pub transmittance: Vec<Option<Vec<Vec3>>>,
}

fn decode_output(size: UVec2, bytes: Vec<u8>) -> image::RgbaImage {
    image::RgbaImage::from_raw(size.x, size.y, bytes).expect("readback has width * height texels")
}

fn decode_visibility(bytes: &[u8], channel: u32) -> Vec<f32> {
    (bytes.chunks_exact(4))
        .map(|t| t[channel as usize] as f32 / 255.0)
        .collect()
}

fn decode_transmittance(bytes: &[u8]) -> Vec<Vec3> {
    (bytes.chunks_exact(4))
        .map(|t| Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) / 255.0)
        .collect()
}

/// The G-buffer from its depth, normal and albedo bytes, positions rebuilt with `matrices`.
fn decode_gbuffer(
    matrices: &CameraMatrices,
    size: UVec2,
    [depths, normals, albedo]: [Vec<u8>; 3],
) -> GBufferData {
    let width = size.x.max(1);
    let positions = (readback::f32s(&depths).iter().enumerate())
        .map(|(i, &depth)| {
            if depth > 0.0 {
                let pixel = UVec2::new(i as u32 % width, i as u32 / width);
                crate::render::gbuffer::reconstruct_position(matrices, pixel, depth).extend(1.0)
            } else {
                Vec4::ZERO
            }
        })
        .collect();
    let normals = readback::f16s(&normals);
    GBufferData {
        size,
        eye: matrices.eye,
        positions,
        normals: (normals.chunks_exact(4))
            .map(|n| Vec3::new(n[0], n[1], n[2]))
            .collect(),
        materials: (albedo.chunks_exact(4))
            .zip(normals.chunks_exact(4))
            .map(|(a, n)| crate::scene::shading::Material {
                albedo: Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32) / 255.0,
                specular: a[3] as f32 / 255.0,
                shininess: n[3] * 256.0,
            })
            .collect(),
    }
}
