//! The `blocker distance` debug view: for one light, the distance from each pixel's surface to
//! the nearest blocking caster toward the light's centre, traced by a closest-hit ray
//! (`rt_closest`, `fs_blocker_distance`); 0 where nothing blocks it.

use zoo_host::gpu::PassRecorder;
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};

use crate::RtLight;
use crate::trace_pass::TracePass;

/// The debug view's (and resource's) name.
pub const VIEW: &str = "blocker distance";

/// Its format: a distance per pixel (red), in a format every backend renders to (GL cannot
/// render to `R32Float`).
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The distances and the pass that traces them, both made when first asked for.
pub struct BlockerView {
    /// The tracing shader's text for the chosen tracer.
    text: String,
    pass: Option<TracePass>,
    target: Option<(wgpu::Texture, wgpu::TextureView)>,
    /// The farthest distance shown white (the scene's diagonal).
    far: f32,
}

impl BlockerView {
    /// The view of fragment `fs_blocker_distance` of the tracing shader `text`.
    pub fn new(text: &str) -> BlockerView {
        BlockerView {
            text: text.to_string(),
            pass: None,
            target: None,
            far: 1.0,
        }
    }

    /// Traces light `light`'s blocker distances at the output's size, with the ray-tracing
    /// group `tracing` of shader `shader`.
    pub fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        (shader, tracing): (&str, &dyn kit::SharedGroup),
        per_light: impl Fn(usize) -> RtLight,
        light: usize,
    ) -> TechniqueResult {
        if self.pass.is_none() {
            let entry = (shader, self.text.as_str(), "fs_blocker_distance");
            let target = TracePass::replace(FORMAT);
            let pass = TracePass::new(ctx, "Blocker distance", entry, target, tracing)?;
            self.pass = Some(pass);
        }
        let pass = self.pass.as_mut().expect("made above");
        let size = ctx.visibility.texture.size();
        let fits = |(texture, _): &(wgpu::Texture, wgpu::TextureView)| {
            texture.width() == size.width && texture.height() == size.height
        };
        if !self.target.as_ref().is_some_and(fits) {
            let texture = ctx.gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("rt-shadows blocker distance"),
                size: wgpu::Extent3d {
                    depth_or_array_layers: 1,
                    ..size
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let view = texture.create_view(&Default::default());
            self.target = Some((texture, view));
        }
        let (min, max) = ctx.scene.bounds();
        self.far = (max - min).length().max(f32::MIN_POSITIVE);
        let view = &self.target.as_ref().expect("made above").1;
        let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
        let target = |l: usize| (l == light).then_some((view, clear));
        let no_blend = |_| None;
        pass.record(ctx, recorder, tracing, per_light, target, no_blend)
    }

    /// The distances as a viewable resource, once traced.
    pub fn resource(&self) -> Option<ResourceInfo> {
        let (texture, _) = self.target.as_ref()?;
        Some(ResourceInfo::texture(VIEW, texture, true))
    }

    /// The distances for the debug view, black at the surface and white at the scene's
    /// diagonal.
    pub fn debug_image(&self) -> Option<DebugImage<'_>> {
        let (_, view) = self.target.as_ref()?;
        Some(DebugImage {
            view,
            mapping: ViewMapping::Channel {
                channel: 0,
                min: 0.0,
                max: self.far,
            },
        })
    }
}
