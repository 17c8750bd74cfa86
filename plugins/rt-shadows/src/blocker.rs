//! The `blocker distance` debug view: for one light, the distance from each pixel's surface to
//! the nearest blocking caster toward the light's centre, traced by a closest-hit ray
//! (`rt_closest`, `fs_blocker_distance`); 0 where nothing blocks it.

use zoo_host::gpu::PassRecorder;
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo, ViewMapping};

use crate::RtLight;
use zoo_ray_tracing::TracePass;

/// The debug view's (and resource's) name.
pub const VIEW: &str = "blocker distance";

/// Its format: a distance per pixel (red), in a format every backend renders to (GL cannot
/// render to `R32Float`).
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The distances and the pass that traces them, both made when first asked for.
pub struct BlockerView {
    /// The tracing shader's text for the chosen tracer.
    text: String,
    pass: Option<TracePass<RtLight>>,
    /// The distances, made (and viewable) when first traced.
    targets: kit::NamedTextures,
}

impl BlockerView {
    /// The view of fragment `fs_blocker_distance` of the tracing shader `text`.
    pub fn new(text: &str) -> BlockerView {
        BlockerView {
            text: text.to_string(),
            pass: None,
            targets: kit::NamedTextures::new(
                "rt-shadows",
                [kit::TextureSpec {
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                    ..kit::TextureSpec::screen_target(VIEW, FORMAT, None)
                }],
            ),
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
            let target = zoo_ray_tracing::replace_target(FORMAT);
            let pass = TracePass::new(ctx, "Blocker distance", entry, target, tracing)?;
            self.pass = Some(pass);
        }
        let pass = self.pass.as_mut().expect("made above");
        // Black at the surface, white at the scene's diagonal.
        let (min, max) = ctx.scene.bounds();
        let far = (max - min).length().max(f32::MIN_POSITIVE);
        self.targets.respec(VIEW, |spec| {
            spec.view = Some(ViewMapping::Channel {
                channel: 0,
                min: 0.0,
                max: far,
            })
        });
        self.targets.prepare(ctx);
        let view = self.targets.view(VIEW).expect("made above");
        let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
        let target = |l: usize| (l == light).then_some((view, clear));
        let no_blend = |_| None;
        pass.record(ctx, recorder, tracing, per_light, target, no_blend)
    }

    /// The distances as a viewable resource, once traced.
    pub fn resource(&self) -> Option<ResourceInfo> {
        self.targets.resources().pop()
    }

    /// The distances for the debug view, black at the surface and white at the scene's
    /// diagonal, once traced.
    pub fn debug_image(&self) -> Option<DebugImage<'_>> {
        self.targets.debug_view(VIEW)
    }
}
