//! Named resources: a technique declares each texture once ([`TextureSpec`]: name, size,
//! layers, format, usage, how to view it); [`NamedTextures`] makes them, makes them again
//! when their spec or the output's size changes, and answers `resources()`, `debug_view()`
//! and `debug_volume()` from the declarations.

use glam::{UVec2, UVec3};

use crate::GpuContext;
use crate::technique::{
    DebugImage, DebugVolume, RenderContext, ResourceInfo, ViewMapping, VolumeSlice,
};

/// The size of a named texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureSize {
    /// The output's size divided by `divisor` (rounded up; 1 for full size).
    Screen { divisor: u32 },
    /// A size of its own.
    Fixed(UVec2),
    /// A 3D texture of its own size: one layer, viewed whole as `D3` (shown through
    /// [`NamedTextures::debug_volume`]).
    Volume(UVec3),
}

impl TextureSize {
    /// The output's size.
    pub const SCREEN: TextureSize = TextureSize::Screen { divisor: 1 };

    /// Width, height and depth (1 for 2D textures) at output size `screen`.
    fn resolve(self, screen: UVec2) -> UVec3 {
        match self {
            TextureSize::Screen { divisor } => screen.map(|s| s.div_ceil(divisor.max(1))).extend(1),
            TextureSize::Fixed(size) => size.extend(1),
            TextureSize::Volume(size) => size,
        }
        .max(UVec3::ONE)
    }
}

/// One texture a technique declares.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureSpec {
    /// As `resources()` lists it and the viewer's menu shows it.
    pub name: &'static str,
    pub size: TextureSize,
    /// Array layers (1: a plain 2D texture unless `array`).
    pub layers: u32,
    /// Viewed whole as a 2D array even with one layer (which gets a spare layer on GL, see
    /// [`crate::gpu::array_layers`]).
    pub array: bool,
    pub format: wgpu::TextureFormat,
    /// Usages besides sampling (`TEXTURE_BINDING`), which every named texture has.
    pub usage: wgpu::TextureUsages,
    /// How the debug view shows it (its first layer); `None`: listed, not viewable.
    pub view: Option<ViewMapping>,
    /// More names that show this texture, each as its mapping (one image that a debug pass
    /// draws one of several things into): listed too, with no memory of their own.
    pub aliases: Vec<(&'static str, ViewMapping)>,
}

/// What a texture is made of: its spec less how it is viewed.
type Shape = (
    TextureSize,
    u32,
    bool,
    wgpu::TextureFormat,
    wgpu::TextureUsages,
);

impl TextureSpec {
    fn shape(&self) -> Shape {
        (self.size, self.layers, self.array, self.format, self.usage)
    }

    /// What it is made for at output size `screen`: its shape, and the output's size where
    /// its size follows it.
    fn made_for(&self, screen: UVec2) -> (Shape, UVec2) {
        let screen = match self.size {
            TextureSize::Screen { .. } => screen,
            _ => UVec2::ZERO,
        };
        (self.shape(), screen)
    }

    /// Whether it is viewed whole as a 2D array.
    fn is_array(&self) -> bool {
        !self.is_volume() && (self.array || self.layers != 1)
    }

    fn is_volume(&self) -> bool {
        matches!(self.size, TextureSize::Volume(_))
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
            array: false,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view,
            aliases: Vec::new(),
        }
    }

    /// How it is shown as `name` (its own name or an alias), where viewable.
    fn mapping(&self, name: &str) -> Option<ViewMapping> {
        if self.name == name {
            return self.view;
        }
        let alias = self.aliases.iter().find(|(alias, _)| *alias == name);
        alias.map(|(_, mapping)| *mapping)
    }
}

/// A texture made from its spec.
struct Made {
    /// The shape and output size it was made for.
    made_for: (Shape, UVec2),
    texture: wgpu::Texture,
    /// The whole texture (a 2D array view where it is an array, 3D where a volume).
    view: wgpu::TextureView,
    /// One 2D view per layer (none for a volume).
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

    /// Replaces the spec of each texture named in `specs` by that spec, as [`Self::respec`]
    /// does (for techniques that declare their textures with a function of their settings).
    pub fn respec_all(&mut self, specs: impl IntoIterator<Item = TextureSpec>) {
        for spec in specs {
            self.respec(spec.name, |old| *old = spec);
        }
    }

    /// Makes every texture not yet made, or made for another shape or (screen-sized ones)
    /// output size; returns whether any was (bind groups over them must then be made again).
    pub fn prepare(&mut self, ctx: &RenderContext<'_>) -> bool {
        self.prepare_at(ctx.gpu, ctx.size)
    }

    /// As [`Self::prepare`], for output size `screen` on `gpu`.
    pub fn prepare_at(&mut self, gpu: &GpuContext, screen: UVec2) -> bool {
        let mut changed = false;
        for (spec, made) in self.specs.iter().zip(&mut self.made) {
            let wanted = spec.made_for(screen);
            if made.as_ref().is_none_or(|m| m.made_for != wanted) {
                *made = Some(make(gpu, &self.label, spec, screen));
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

    /// The whole of texture `name` (an array view where it is an array, 3D where a volume),
    /// once made.
    pub fn view(&self, name: &str) -> Option<&wgpu::TextureView> {
        self.find(name).map(|m| &m.view)
    }

    /// Layer `layer` of texture `name` as a 2D view, once made (none for a volume).
    pub fn layer_view(&self, name: &str, layer: u32) -> Option<&wgpu::TextureView> {
        self.find(name)?.layer_views.get(layer as usize)
    }

    /// Every made texture, then each of its aliases, for `resources()`.
    pub fn resources(&self) -> Vec<ResourceInfo> {
        let mut out = Vec::new();
        for (spec, made) in self.specs.iter().zip(&self.made) {
            let Some(made) = made else { continue };
            let own = ResourceInfo::texture(spec.name, &made.texture, spec.view.is_some());
            out.push(own);
            for (alias, _) in &spec.aliases {
                let mut info = ResourceInfo::texture(*alias, &made.texture, true);
                info.bytes = 0;
                out.push(info);
            }
        }
        out
    }

    /// The made texture shown as `name` (its own name or an alias), with its spec and how
    /// it is shown.
    fn shown(&self, name: &str) -> Option<(&TextureSpec, &Made, ViewMapping)> {
        (self.specs.iter().zip(&self.made)).find_map(|(spec, made)| {
            let mapping = spec.mapping(name)?;
            Some((spec, made.as_ref()?, mapping))
        })
    }

    /// The first layer of the 2D texture shown as `name` as its spec says to show it, for
    /// `debug_view()`.
    pub fn debug_view(&self, name: &str) -> Option<DebugImage<'_>> {
        let (spec, made, mapping) = self.shown(name)?;
        (!spec.is_volume()).then(|| DebugImage {
            view: &made.layer_views[0],
            mapping,
        })
    }

    /// Slice `slice` of the volume shown as `name` as its spec says to show it, for
    /// `debug_volume()`.
    pub fn debug_volume(&self, name: &str, slice: VolumeSlice) -> Option<DebugVolume<'_>> {
        let (spec, made, mapping) = self.shown(name)?;
        spec.is_volume().then_some(DebugVolume {
            view: &made.view,
            mapping,
            slice,
        })
    }
}

fn make(gpu: &GpuContext, label: &str, spec: &TextureSpec, screen: UVec2) -> Made {
    let size = spec.size.resolve(screen);
    let layers = spec.layers.max(1);
    let label = format!("{label} {}", spec.name);
    let (dimension, depth) = if spec.is_volume() {
        (wgpu::TextureDimension::D3, size.z)
    } else if spec.is_array() {
        let padded = crate::gpu::array_layers(gpu, size.x, size.y, layers);
        (wgpu::TextureDimension::D2, padded)
    } else {
        (wgpu::TextureDimension::D2, layers)
    };
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(&label),
        size: wgpu::Extent3d {
            width: size.x,
            height: size.y,
            depth_or_array_layers: depth,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension,
        format: spec.format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | spec.usage,
        view_formats: &[],
    });
    let (view, layer_views) = views(&texture, &label, spec);
    Made {
        made_for: spec.made_for(screen),
        texture,
        view,
        layer_views,
    }
}

/// The whole view and the layer views of `texture`, made from `spec`.
fn views(
    texture: &wgpu::Texture,
    label: &str,
    spec: &TextureSpec,
) -> (wgpu::TextureView, Vec<wgpu::TextureView>) {
    let view_of = |label: String, dimension, base_array_layer, count| {
        texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some(&label),
            dimension: Some(dimension),
            base_array_layer,
            array_layer_count: Some(count),
            ..Default::default()
        })
    };
    let layers = spec.layers.max(1);
    use wgpu::TextureViewDimension as D;
    let (dimension, count) = match (spec.is_volume(), spec.is_array()) {
        (true, _) => (D::D3, 1),
        (_, true) => (D::D2Array, layers),
        _ => (D::D2, 1),
    };
    let whole = view_of(format!("{label} view"), dimension, 0, count);
    if spec.is_volume() {
        return (whole, Vec::new());
    }
    let layer_views = (0..layers)
        .map(|layer| {
            let label = format!("{label} layer {layer}");
            view_of(label, D::D2, layer, 1)
        })
        .collect();
    (whole, layer_views)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screen_sizes_follow_the_output_and_never_vanish() {
        let screen = UVec2::new(257, 128);
        assert_eq!(TextureSize::SCREEN.resolve(screen), screen.extend(1));
        let half = TextureSize::Screen { divisor: 2 };
        assert_eq!(half.resolve(screen), UVec3::new(129, 64, 1));
        assert_eq!(half.resolve(UVec2::new(1, 0)), UVec3::ONE);
        let fixed = TextureSize::Fixed(UVec2::new(8, 4));
        assert_eq!(fixed.resolve(screen), UVec3::new(8, 4, 1));
    }

    #[test]
    fn volumes_keep_their_depth_and_are_never_arrays() {
        let volume = TextureSize::Volume(UVec3::new(8, 4, 2));
        assert_eq!(volume.resolve(UVec2::new(640, 480)), UVec3::new(8, 4, 2));
        assert_eq!(
            TextureSize::Volume(UVec3::ZERO).resolve(UVec2::ONE),
            UVec3::ONE
        );
        let spec = TextureSpec {
            size: volume,
            array: true,
            ..TextureSpec::screen_target("grid", wgpu::TextureFormat::Rgba16Float, None)
        };
        assert!(spec.is_volume() && !spec.is_array());
    }

    #[test]
    fn aliases_show_the_texture_with_their_own_mapping() {
        let own = ViewMapping::Color { min: 0.0, max: 1.0 };
        let other = ViewMapping::Color { min: 0.0, max: 2.0 };
        let spec = TextureSpec {
            aliases: vec![("other", other)],
            ..TextureSpec::screen_target("own", wgpu::TextureFormat::Rgba8Unorm, Some(own))
        };
        assert_eq!(spec.mapping("own"), Some(own));
        assert_eq!(spec.mapping("other"), Some(other));
        assert_eq!(spec.mapping("neither"), None);
    }
}
