//! Named resources: a technique declares each texture once ([`TextureSpec`]: name, size,
//! layers, format, usage, how to view it); [`NamedTextures`] makes them, makes them again
//! when their spec or the output's size changes, and answers `resources()` and
//! `debug_view()` from the declarations.

use glam::UVec2;

use crate::technique::{DebugImage, RenderContext, ResourceInfo, ViewMapping};

/// The size of a named texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureSize {
    /// The output's size divided by `divisor` (rounded up; 1 for full size).
    Screen { divisor: u32 },
    /// A size of its own.
    Fixed(UVec2),
}

impl TextureSize {
    /// The output's size.
    pub const SCREEN: TextureSize = TextureSize::Screen { divisor: 1 };

    fn resolve(self, screen: UVec2) -> UVec2 {
        match self {
            TextureSize::Screen { divisor } => screen.map(|s| s.div_ceil(divisor.max(1))),
            TextureSize::Fixed(size) => size,
        }
        .max(UVec2::ONE)
    }
}

/// One texture a technique declares.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureSpec {
    /// As `resources()` lists it and the viewer's menu shows it.
    pub name: &'static str,
    pub size: TextureSize,
    /// Array layers (1: a plain 2D texture).
    pub layers: u32,
    pub format: wgpu::TextureFormat,
    /// Usages besides sampling (`TEXTURE_BINDING`), which every named texture has.
    pub usage: wgpu::TextureUsages,
    /// How the debug view shows it (its first layer); `None`: listed, not viewable.
    pub view: Option<ViewMapping>,
}

/// What a texture is made of: its spec less how it is viewed.
type Shape = (TextureSize, u32, wgpu::TextureFormat, wgpu::TextureUsages);

impl TextureSpec {
    fn shape(&self) -> Shape {
        (self.size, self.layers, self.format, self.usage)
    }

    /// A full-size render target of `format`, viewable as `view`.
    pub fn screen_target(
        name: &'static str,
        format: wgpu::TextureFormat,
        view: Option<ViewMapping>,
    ) -> TextureSpec {
        TextureSpec {
            name,
            size: TextureSize::SCREEN,
            layers: 1,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view,
        }
    }
}

/// A texture made from its spec.
struct Made {
    /// The shape and output size it was made for.
    made_for: (Shape, UVec2),
    texture: wgpu::Texture,
    /// The whole texture (a 2D array view where it has layers).
    view: wgpu::TextureView,
    /// One 2D view per layer.
    layer_views: Vec<wgpu::TextureView>,
}

/// A technique's declared textures (see [the module](self)).
pub struct NamedTextures {
    label: String,
    specs: Vec<TextureSpec>,
    made: Vec<Option<Made>>,
}

impl NamedTextures {
    /// The textures of `specs`, made at the first [`Self::prepare`]; `label` prefixes their
    /// labels.
    pub fn new(label: &str, specs: impl IntoIterator<Item = TextureSpec>) -> NamedTextures {
        let specs: Vec<TextureSpec> = specs.into_iter().collect();
        NamedTextures {
            label: label.to_string(),
            made: specs.iter().map(|_| None).collect(),
            specs,
        }
    }

    /// Changes the spec of `name` (made again at the next [`Self::prepare`] if its shape
    /// differs; a new view applies at once).
    pub fn respec(&mut self, name: &str, change: impl FnOnce(&mut TextureSpec)) {
        if let Some(spec) = self.specs.iter_mut().find(|s| s.name == name) {
            change(spec);
        }
    }

    /// Makes every texture not yet made, or made for another spec or output size; returns
    /// whether any was (bind groups over them must then be made again).
    pub fn prepare(&mut self, ctx: &RenderContext<'_>) -> bool {
        self.prepare_at(&ctx.gpu.device, ctx.size)
    }

    /// As [`Self::prepare`], for output size `screen` on `device`.
    pub fn prepare_at(&mut self, device: &wgpu::Device, screen: UVec2) -> bool {
        let mut changed = false;
        for (spec, made) in self.specs.iter().zip(&mut self.made) {
            let wanted = (spec.shape(), screen);
            if made.as_ref().is_none_or(|m| m.made_for != wanted) {
                *made = Some(make(device, &self.label, spec, screen));
                changed = true;
            }
        }
        changed
    }

    fn find(&self, name: &str) -> Option<&Made> {
        let index = self.specs.iter().position(|s| s.name == name)?;
        self.made[index].as_ref()
    }

    /// The texture `name`, once made.
    pub fn texture(&self, name: &str) -> Option<&wgpu::Texture> {
        self.find(name).map(|m| &m.texture)
    }

    /// The whole of texture `name` (an array view where it has layers), once made.
    pub fn view(&self, name: &str) -> Option<&wgpu::TextureView> {
        self.find(name).map(|m| &m.view)
    }

    /// Layer `layer` of texture `name` as a 2D view, once made.
    pub fn layer_view(&self, name: &str, layer: u32) -> Option<&wgpu::TextureView> {
        self.find(name)?.layer_views.get(layer as usize)
    }

    /// Every made texture, for `resources()`.
    pub fn resources(&self) -> Vec<ResourceInfo> {
        (self.specs.iter().zip(&self.made))
            .filter_map(|(spec, made)| {
                let made = made.as_ref()?;
                Some(ResourceInfo::texture(
                    spec.name,
                    &made.texture,
                    spec.view.is_some(),
                ))
            })
            .collect()
    }

    /// The first layer of texture `name` as its spec says to show it, for `debug_view()`.
    pub fn debug_view(&self, name: &str) -> Option<DebugImage<'_>> {
        let index = self.specs.iter().position(|s| s.name == name)?;
        let mapping = self.specs[index].view?;
        let made = self.made[index].as_ref()?;
        Some(DebugImage {
            view: &made.layer_views[0],
            mapping,
        })
    }
}

fn make(device: &wgpu::Device, label: &str, spec: &TextureSpec, screen: UVec2) -> Made {
    let size = spec.size.resolve(screen);
    let layers = spec.layers.max(1);
    let label = format!("{label} {}", spec.name);
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(&label),
        size: wgpu::Extent3d {
            width: size.x,
            height: size.y,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: spec.format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | spec.usage,
        view_formats: &[],
    });
    let view_of = |label: String, dimension, base_array_layer, count| {
        texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some(&label),
            dimension: Some(dimension),
            base_array_layer,
            array_layer_count: Some(count),
            ..Default::default()
        })
    };
    let whole = match spec.layers {
        1 => wgpu::TextureViewDimension::D2,
        _ => wgpu::TextureViewDimension::D2Array,
    };
    let view = view_of(format!("{label} view"), whole, 0, layers);
    let layer_views = (0..layers)
        .map(|layer| {
            let label = format!("{label} layer {layer}");
            view_of(label, wgpu::TextureViewDimension::D2, layer, 1)
        })
        .collect();
    Made {
        made_for: (spec.shape(), screen),
        texture,
        view,
        layer_views,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screen_sizes_follow_the_output_and_never_vanish() {
        let screen = UVec2::new(257, 128);
        assert_eq!(TextureSize::SCREEN.resolve(screen), screen);
        let half = TextureSize::Screen { divisor: 2 };
        assert_eq!(half.resolve(screen), UVec2::new(129, 64));
        assert_eq!(half.resolve(UVec2::new(1, 0)), UVec2::ONE);
        let fixed = TextureSize::Fixed(UVec2::new(8, 4));
        assert_eq!(fixed.resolve(screen), UVec2::new(8, 4));
    }
}
