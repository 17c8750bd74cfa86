//! A judgement of the view: what it was computed for ([`JudgedView`]) and the verdict
//! ([`Judgement`]), from the CPU judge or the live one alike.

use zoo_host::Renderer;
use zoo_host::image::RgbaImage;
use zoo_host::judge::Metrics;
use zoo_host::params::ParamValues;
use zoo_host::scene::{Camera, Light};

/// What a judgement was computed for; a different key makes it stale.
#[derive(Debug, Clone, PartialEq)]
pub struct JudgedView {
    pub technique: String,
    pub params: ParamValues,
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub size: zoo_host::glam::UVec2,
}

impl JudgedView {
    /// The key of what `renderer` shows now.
    pub fn of(renderer: &Renderer) -> JudgedView {
        JudgedView {
            technique: renderer.technique().id.to_string(),
            params: renderer.technique_params().clone(),
            camera: *renderer.camera(),
            lights: renderer.lights().to_vec(),
            size: renderer.size(),
        }
    }
}

/// The judge's verdict on one view.
pub struct Judgement {
    pub view: JudgedView,
    /// Per light: metrics, or `None` where the technique does not support the light's kind.
    pub metrics: Vec<Option<Metrics>>,
    /// Per light: red false shadow, blue false lit, grey both shadowed, the image dimmed.
    pub error_maps: Vec<RgbaImage>,
    pub occluder_triangles: usize,
    pub seconds: f64,
    /// For the live judge's, the area rays a pixel it had traced; `None` for the CPU judge's.
    pub live_samples: Option<u32>,
}
