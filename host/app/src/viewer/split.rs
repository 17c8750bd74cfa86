//! A/B comparison: a second technique rendered on the same frame, shown side by side with a
//! draggable divider or as a difference image.

use zoo_host::render::ImageDifference;
use zoo_host::{Renderer, ShaderLibrary};

/// How the two techniques are shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplitMode {
    /// A left of the divider, B right of it.
    Split,
    /// Red where A is darker, blue where B is darker.
    Difference,
}

/// The B side and how A and B are shown.
pub struct AbCompare {
    /// Renders technique B with the same camera, lights and size as A.
    pub renderer: Renderer,
    pub mode: SplitMode,
    /// Divider position across the view, 0..=1.
    pub divider: f32,
    /// Amplification of the difference image.
    pub gain: f32,
    pub difference: ImageDifference,
}

impl AbCompare {
    /// B starts on `renderer`'s scene and `shaders`.
    pub fn new(
        gpu: std::sync::Arc<zoo_host::GpuContext>,
        scene: zoo_host::Scene,
        size: zoo_host::glam::UVec2,
        shaders: ShaderLibrary,
    ) -> anyhow::Result<AbCompare> {
        let difference = ImageDifference::new(&gpu, &shaders)?;
        Ok(AbCompare {
            renderer: Renderer::with_shaders(gpu, scene, size, shaders)?,
            mode: SplitMode::Split,
            divider: 0.5,
            gain: 4.0,
            difference,
        })
    }
}
