//! Reading frames back: the output image, a light's visibility and the G-buffer.

use glam::{UVec2, Vec3, Vec4};

use super::Renderer;
use crate::gpu::readback;

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
        let bytes = readback::read_texture(&self.gpu, &self.output, 0, wgpu::TextureAspect::All, 4);
        image::RgbaImage::from_raw(self.size.x, self.size.y, bytes)
            .expect("readback has width * height texels")
    }

    /// Visibility of light `light` per pixel, in [0, 1].
    pub fn read_visibility(&self, light: usize) -> Vec<f32> {
        let (layer, channel) = self.visibility.slots.slot(light);
        let bytes = readback::read_texture(
            &self.gpu,
            &self.visibility.texture,
            layer,
            wgpu::TextureAspect::All,
            4,
        );
        bytes
            .chunks_exact(4)
            .map(|t| t[channel as usize] as f32 / 255.0)
            .collect()
    }

    /// The colour light `light` keeps through translucent casters per pixel, in [0, 1]
    /// (white everywhere when the technique does not write transmittance).
    pub fn read_transmittance(&self, light: usize) -> Vec<glam::Vec3> {
        let pixels = (self.size.x * self.size.y) as usize;
        if !self.transmittance.in_use {
            return vec![glam::Vec3::ONE; pixels];
        }
        let (layer, channel) = self.visibility.slots.slot(light);
        let bytes = readback::read_texture(
            &self.gpu,
            &self.transmittance.texture,
            layer * 4 + channel,
            wgpu::TextureAspect::All,
            4,
        );
        bytes
            .chunks_exact(4)
            .map(|t| glam::Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) / 255.0)
            .collect()
    }

    /// The indirect light per pixel (irradiance over π; zero unless the technique adds light).
    pub fn read_indirect(&self) -> Vec<glam::Vec3> {
        let bytes = readback::read_texture(
            &self.gpu,
            &self.indirect.texture,
            0,
            wgpu::TextureAspect::All,
            8,
        );
        readback::f16s(&bytes)
            .chunks_exact(4)
            .map(|c| glam::Vec3::new(c[0], c[1], c[2]))
            .collect()
    }

    /// World positions and normals per pixel.
    pub fn read_gbuffer(&self) -> GBufferData {
        let depths = readback::f32s(&readback::read_texture(
            &self.gpu,
            &self.gbuffer.view_depth,
            0,
            wgpu::TextureAspect::All,
            4,
        ));
        // The camera the G-buffer was rendered with (the last one uploaded).
        let matrices = &self.frame.matrices;
        let width = self.size.x.max(1);
        let positions = depths
            .iter()
            .enumerate()
            .map(|(i, &depth)| {
                if depth > 0.0 {
                    let pixel = UVec2::new(i as u32 % width, i as u32 / width);
                    crate::render::gbuffer::reconstruct_position(matrices, pixel, depth).extend(1.0)
                } else {
                    Vec4::ZERO
                }
            })
            .collect();
        let normals = readback::f16s(&readback::read_texture(
            &self.gpu,
            &self.gbuffer.normal,
            0,
            wgpu::TextureAspect::All,
            8,
        ));
        let albedo = readback::read_texture(
            &self.gpu,
            &self.gbuffer.albedo,
            0,
            wgpu::TextureAspect::All,
            4,
        );
        GBufferData {
            size: self.size,
            eye: matrices.eye,
            positions,
            normals: normals
                .chunks_exact(4)
                .map(|n| Vec3::new(n[0], n[1], n[2]))
                .collect(),
            materials: albedo
                .chunks_exact(4)
                .zip(normals.chunks_exact(4))
                .map(|(a, n)| crate::scene::shading::Material {
                    albedo: Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32) / 255.0,
                    specular: a[3] as f32 / 255.0,
                    shininess: n[3] * 256.0,
                })
                .collect(),
        }
    }
}
