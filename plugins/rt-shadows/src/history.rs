//! Accumulation over frames: soft lights' traced visibility averaged, by blending, into a
//! floating-point history laid out like the visibility slots (each light's layer and channel),
//! while nothing moves. The filter pass then resolves the history into the slots.

use zoo_host::kit::{NamedTextures, TextureSize, TextureSpec};
use zoo_host::prelude::*;
use zoo_host::technique::ResourceInfo;

/// Format of the history: averages of many frames need more than the slots' eight bits.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const HISTORY: &str = "soft lights' history";

/// The history and its binding.
pub struct History {
    texture: NamedTextures,
    /// The slots' size and layers it was made for.
    made_for: wgpu::Extent3d,
    /// The history as the filter pass reads it.
    pub group: kit::StageBindGroup,
}

impl History {
    /// A history shaped like `ctx`'s visibility slots, bound as the `history` of the filter
    /// pass's `stage`.
    pub fn new(ctx: &RenderContext<'_>, stage: &kit::Stage) -> TechniqueResult<History> {
        let made_for = ctx.visibility.texture.size();
        let spec = TextureSpec {
            size: TextureSize::Fixed(glam::UVec2::new(made_for.width, made_for.height)),
            layers: made_for.depth_or_array_layers,
            array: true,
            ..TextureSpec::screen_target(HISTORY, FORMAT, None)
        };
        let mut texture = NamedTextures::new("rt-shadows", [spec]);
        texture.prepare(ctx);
        let view = texture
            .view(HISTORY)
            .ok_or_else(TechniqueError::not_prepared)?;
        let history = ("history", wgpu::BindingResource::TextureView(view));
        let group = stage.bind(ctx, "rt-shadows history", &[history])?;
        Ok(History {
            texture,
            made_for,
            group,
        })
    }

    /// Whether it still has the slots' shape.
    pub fn fits(&self, ctx: &RenderContext<'_>) -> bool {
        self.made_for == ctx.visibility.texture.size()
    }

    /// The history, for the memory table.
    pub fn resources(&self) -> Vec<ResourceInfo> {
        self.texture.resources()
    }
}

/// The accumulation pass's target: the slots' blend (source times the constant, plus the
/// destination times one minus it) on the history's format. With the light's channel of the
/// blend constant set to the new frame's weight w ([`History::blend`]) it keeps the other
/// channels and gives `traced · w + history · (1 − w)`: the averaging is done by blending.
pub fn accumulation_target() -> wgpu::ColorTargetState {
    wgpu::ColorTargetState {
        format: FORMAT,
        ..kit::slot_target()
    }
}

impl History {
    /// Where light `light`'s traced visibility accumulates: its layer, kept (none for a light
    /// beyond the slots it was made for).
    pub fn target(
        &self,
        ctx: &RenderContext<'_>,
        light: usize,
    ) -> Option<(&wgpu::TextureView, wgpu::LoadOp<wgpu::Color>)> {
        let (layer, _) = ctx.visibility.slots.slot(light);
        let view = self.texture.layer_view(HISTORY, layer)?;
        Some((view, wgpu::LoadOp::Load))
    }

    /// The blend constant that weighs the new frame by `weight` in light `light`'s channel.
    pub fn blend(ctx: &RenderContext<'_>, light: usize, weight: f64) -> wgpu::Color {
        let channel = ctx.visibility.light_slot(light).blend_constant;
        wgpu::Color {
            r: channel.r * weight,
            g: channel.g * weight,
            b: channel.b * weight,
            a: channel.a * weight,
        }
    }
}
