//! Accumulation over frames: soft lights' traced visibility averaged, by blending, into a
//! floating-point history laid out like the visibility slots (each light's layer and channel),
//! while nothing moves. The filter pass then resolves the history into the slots.

use zoo_host::prelude::*;

/// Format of the history: averages of many frames need more than the slots' eight bits.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The history and its binding.
pub struct History {
    pub texture: wgpu::Texture,
    layer_views: Vec<wgpu::TextureView>,
    /// The history as the filter pass reads it.
    pub group: kit::StageBindGroup,
}

impl History {
    /// A history shaped like `ctx`'s visibility slots, bound as the `history` of the filter
    /// pass's `stage`.
    pub fn new(ctx: &RenderContext<'_>, stage: &kit::Stage) -> TechniqueResult<History> {
        let device = &ctx.gpu.device;
        let size = ctx.visibility.texture.size();
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("rt-shadows history"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let layer_views = (0..size.depth_or_array_layers)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("rt-shadows history layer {layer}")),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("rt-shadows history view"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let history = ("history", wgpu::BindingResource::TextureView(&view));
        let group = stage.bind(ctx, "rt-shadows history", &[history])?;
        Ok(History {
            texture,
            layer_views,
            group,
        })
    }

    /// Whether it still has the slots' shape.
    pub fn fits(&self, ctx: &RenderContext<'_>) -> bool {
        self.texture.size() == ctx.visibility.texture.size()
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
    /// Where light `light`'s traced visibility accumulates: its layer, kept.
    pub fn target(
        &self,
        ctx: &RenderContext<'_>,
        light: usize,
    ) -> (&wgpu::TextureView, wgpu::LoadOp<wgpu::Color>) {
        let (layer, _) = ctx.visibility.slots.slot(light);
        (&self.layer_views[layer as usize], wgpu::LoadOp::Load)
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
