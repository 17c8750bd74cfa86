//! Textures of a scene's materials: albedo images and alpha masks, read from image files and
//! resampled to one square size, so that the GPU's texture array and the judge read the very
//! same texels.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use crate::description::{MeshDesc, ObjectDesc};
use crate::gltf_file::{GltfAlpha, GltfMaterial};
use crate::image_source::ImageSource;

/// Largest side of the scene's texture layers; bigger images are scaled down to it.
pub const MAX_TEXTURE_SIZE: u32 = 1024;

/// Most texture layers a scene may use (distinct images, each as albedo or as mask): the array
/// layers every WebGPU device offers.
pub const MAX_TEXTURE_LAYERS: usize = 256;

/// Which channel of an image a layer serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TextureUse {
    /// Colour (sRGB-encoded RGB) that multiplies an object's albedo.
    Albedo,
    /// Coverage in the layer's alpha: the image's alpha channel, or its red channel when it has
    /// none (greyscale masks, as `map_d` files usually are).
    Mask,
}

impl ImageSource {
    fn decode(&self) -> image::ImageResult<image::DynamicImage> {
        match self {
            ImageSource::File(path) => {
                let bytes = crate::files::read(path).map_err(image::ImageError::IoError)?;
                let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes));
                if let Ok(format) = image::ImageFormat::from_path(path) {
                    reader.set_format(format);
                }
                reader.decode()
            }
            ImageSource::Encoded { bytes, .. } => image::load_from_memory(bytes),
        }
    }
}

/// An alpha-tested material: where its mask's alpha (bilinear at full resolution, see
/// [`Textures::alpha`]) is below `cutoff`, the surface is a hole that neither shows nor casts
/// a shadow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaMask {
    /// Layer of [`Textures`] holding the mask.
    pub layer: u32,
    pub cutoff: f32,
}

/// One texture layer: `size`² RGBA8 texels, rows from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureLayer {
    /// The image file it came from.
    pub source: PathBuf,
    pub usage: TextureUse,
    pub rgba: Vec<u8>,
}

/// Every texture of a scene, as layers of one size.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Textures {
    /// Side of every layer in texels (a power of two; 0 when there are no layers).
    pub size: u32,
    pub layers: Vec<TextureLayer>,
}

impl Textures {
    /// The alpha of `layer` at `uv`: bilinear between the four nearest texel centres of the
    /// full-resolution layer, coordinates repeating outside [0, 1]. The GPU's alpha tests
    /// read the same (level 0, linear filtering, repeat addressing).
    pub fn alpha(&self, layer: u32, uv: Vec2) -> f32 {
        self.bilinear(layer, uv, |t| f32::from(t[3]) / 255.0)
            .unwrap_or(1.0)
    }

    /// The linear colour of `layer` at `uv`: its sRGB texels decoded, then bilinear as
    /// [`Self::alpha`] (the full-resolution value that GPU filtering of an sRGB texture
    /// approaches). A missing layer is white.
    pub fn linear_rgb(&self, layer: u32, uv: Vec2) -> Vec3 {
        let decode = |c: u8| crate::shading::srgb_to_linear(f32::from(c) / 255.0);
        self.bilinear(layer, uv, |t| {
            Vec3::new(decode(t[0]), decode(t[1]), decode(t[2]))
        })
        .unwrap_or(Vec3::ONE)
    }

    /// `texel(rgba)` filtered bilinearly at `uv` in `layer` (`None` for a missing layer or
    /// non-finite coordinates, which read as opaque white).
    fn bilinear<T>(&self, layer: u32, uv: Vec2, texel: impl Fn(&[u8]) -> T) -> Option<T>
    where
        T: std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
    {
        let texels = &self.layers.get(layer as usize)?.rgba;
        // Coordinates repeat; wrapped first, so that huge ones cannot overflow the texel index.
        let uv = uv - uv.floor();
        if !uv.is_finite() {
            return None;
        }
        let n = self.size as i64;
        let x = uv * self.size as f32 - 0.5;
        let base = x.floor();
        let f = x - base;
        let at = |dx: i64, dy: i64| {
            let i = (base.x as i64 + dx).rem_euclid(n);
            let j = (base.y as i64 + dy).rem_euclid(n);
            let start = ((j * n + i) * 4) as usize;
            texel(&texels[start..start + 4])
        };
        let top = at(0, 0) * (1.0 - f.x) + at(1, 0) * f.x;
        let bottom = at(0, 1) * (1.0 - f.x) + at(1, 1) * f.x;
        Some(top * (1.0 - f.y) + bottom * f.y)
    }
}

/// Collects the images a scene's materials name, then loads them as [`Textures`].
#[derive(Debug, Default)]
pub(crate) struct TextureRequests {
    requests: Vec<(ImageSource, TextureUse)>,
    index: HashMap<(PathBuf, TextureUse), u32>,
}

impl TextureRequests {
    /// The layer `file` will have, used as `usage`.
    pub(crate) fn request(&mut self, file: &Path, usage: TextureUse) -> u32 {
        self.request_source(&ImageSource::File(file.to_path_buf()), usage)
    }

    /// The layer the image `source` will have, used as `usage`.
    pub(crate) fn request_source(&mut self, source: &ImageSource, usage: TextureUse) -> u32 {
        let key = (source.name().to_path_buf(), usage);
        let next = self.requests.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.requests.push((source.clone(), usage));
            next
        })
    }

    /// Number of layers requested.
    pub(crate) fn len(&self) -> usize {
        self.requests.len()
    }

    /// Reads every requested image and resamples it to the common size: the largest image's
    /// side rounded up to a power of two, at most [`MAX_TEXTURE_SIZE`]. An image that cannot
    /// be read becomes a white, opaque layer and a warning naming the file.
    pub(crate) fn load(self, warnings: &mut Vec<String>) -> Textures {
        // Each image is decoded (and an unreadable one reported) once, whatever its uses.
        let mut decoded: HashMap<&Path, Option<image::DynamicImage>> = HashMap::new();
        for (source, _) in &self.requests {
            decoded.entry(source.name()).or_insert_with(|| {
                source
                    .decode()
                    .map_err(|e| {
                        warnings.push(format!(
                            "texture {}: {e}; the material is drawn without it",
                            source.name().display()
                        ))
                    })
                    .ok()
            });
        }
        let images: Vec<Option<image::RgbaImage>> = self
            .requests
            .iter()
            .map(|(source, usage)| {
                let image = decoded.get(source.name())?.as_ref()?;
                Some(as_layer(image, *usage))
            })
            .collect();
        drop(decoded);
        let largest = images
            .iter()
            .flatten()
            .map(|i| i.width().max(i.height()))
            .max()
            .unwrap_or(1);
        let size = largest.next_power_of_two().min(MAX_TEXTURE_SIZE);
        let layers = self
            .requests
            .into_iter()
            .zip(images)
            .map(|((source, usage), image)| {
                let rgba = match image {
                    Some(i) if i.dimensions() == (size, size) => i.into_raw(),
                    Some(i) => {
                        let filter = image::imageops::FilterType::Triangle;
                        image::imageops::resize(&i, size, size, filter).into_raw()
                    }
                    None => vec![255; (size * size * 4) as usize],
                };
                TextureLayer {
                    source: source.name().to_path_buf(),
                    usage,
                    rgba,
                }
            })
            .collect::<Vec<_>>();
        Textures {
            size: if layers.is_empty() { 0 } else { size },
            layers,
        }
    }
}

/// The image as RGBA8; for masks, coverage moves into alpha.
fn as_layer(image: &image::DynamicImage, usage: TextureUse) -> image::RgbaImage {
    let has_alpha = image.color().has_alpha();
    let mut rgba = image.to_rgba8();
    if usage == TextureUse::Mask && !has_alpha {
        for texel in rgba.pixels_mut() {
            texel[3] = texel[0];
        }
    }
    rgba
}

/// The material of one object part, before its textures are loaded.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ObjectMaterial {
    /// The MTL material's name.
    pub(crate) name: Option<String>,
    pub(crate) color: Vec3,
    pub(crate) specular: f32,
    pub(crate) shininess: f32,
    pub(crate) opacity: f32,
    pub(crate) albedo_texture: Option<u32>,
    pub(crate) alpha_mask: Option<AlphaMask>,
    /// The object's cutoff, for masks its file's materials bring.
    pub(crate) alpha_cutoff: f32,
    /// Whether back faces are drawn.
    pub(crate) double_sided: bool,
}

impl ObjectMaterial {
    /// The material an object's own fields describe (images relative to `base`).
    pub(crate) fn of(
        object: &ObjectDesc,
        base: &Path,
        textures: &mut TextureRequests,
    ) -> ObjectMaterial {
        ObjectMaterial {
            name: None,
            color: object.color,
            specular: object.specular,
            shininess: object.shininess,
            opacity: object.opacity,
            albedo_texture: (object.texture.as_ref())
                .map(|f| textures.request(&base.join(f), TextureUse::Albedo)),
            alpha_mask: object.alpha_mask.as_ref().map(|f| AlphaMask {
                layer: textures.request(&base.join(f), TextureUse::Mask),
                cutoff: object.alpha_cutoff,
            }),
            alpha_cutoff: object.alpha_cutoff,
            double_sided: true,
        }
    }

    /// An MTL material: `Kd` the colour, the largest of `Ks` the specular strength, `Ns` the
    /// shininess, `d` the opacity, `map_Kd` the albedo texture and `map_d` the alpha mask
    /// (with the object's cutoff); what it leaves out comes from `own`. Images are relative to
    /// `folder` (the OBJ file's).
    pub(crate) fn from_mtl(
        m: &tobj::Material,
        own: &ObjectMaterial,
        folder: &Path,
        textures: &mut TextureRequests,
    ) -> ObjectMaterial {
        let finite = |v: f32| v.is_finite().then_some(v);
        let colour = |c: [f32; 3]| {
            let c = Vec3::from(c);
            c.is_finite().then(|| c.clamp(Vec3::ZERO, Vec3::ONE))
        };
        let mut request = |file: &Option<String>, usage| {
            file.as_deref()
                .map(|f| textures.request(&folder.join(image_file(f)), usage))
        };
        let albedo_texture = request(&m.diffuse_texture, TextureUse::Albedo);
        let mask = request(&m.dissolve_texture, TextureUse::Mask);
        // A masked material is an alpha-tested opaque one: `d` counts only without `map_d`.
        let opacity = match (mask, m.dissolve.and_then(finite)) {
            (Some(_), _) => 1.0,
            (None, Some(d)) => d.clamp(0.0, 1.0),
            (None, None) => own.opacity,
        };
        ObjectMaterial {
            name: Some(m.name.clone()),
            color: m.diffuse.and_then(colour).unwrap_or(own.color),
            specular: (m.specular.and_then(colour)).map_or(own.specular, |s| s.max_element()),
            shininess: (m.shininess.and_then(finite))
                .map_or(own.shininess, |n| n.clamp(1.0, 4096.0)),
            opacity,
            albedo_texture: albedo_texture.or(own.albedo_texture),
            // A translucent material is not masked: the object's own mask stays off it.
            alpha_mask: mask
                .map(|layer| AlphaMask {
                    layer,
                    cutoff: own.alpha_cutoff,
                })
                .or(own.alpha_mask)
                .filter(|_| opacity >= 1.0),
            alpha_cutoff: own.alpha_cutoff,
            double_sided: own.double_sided,
        }
    }

    /// A glTF material: the base colour factor the colour, its texture the albedo; metallic
    /// and roughness turned into Blinn-Phong terms (specular 0.04 for dielectrics up to 1 for
    /// metals; exponent 2 / α² - 2 with α = roughness²); `MASK` an alpha test of the base
    /// colour texture's alpha, `BLEND` a translucent caster.
    pub(crate) fn from_gltf(
        m: &GltfMaterial,
        own: &ObjectMaterial,
        textures: &mut TextureRequests,
    ) -> ObjectMaterial {
        let alpha = (m.roughness * m.roughness).max(1e-3);
        let albedo_texture =
            (m.texture.as_ref()).map(|source| textures.request_source(source, TextureUse::Albedo));
        // The albedo layer keeps the image's alpha (opaque without one): the mask reads it.
        let alpha_mask = match m.alpha {
            GltfAlpha::Mask { cutoff } => albedo_texture.map(|layer| AlphaMask { layer, cutoff }),
            _ => None,
        };
        ObjectMaterial {
            name: Some(m.name.clone()),
            color: m.color,
            specular: 0.04 + 0.96 * m.metallic,
            shininess: (2.0 / (alpha * alpha) - 2.0).clamp(1.0, 4096.0),
            opacity: match m.alpha {
                GltfAlpha::Blend { opacity } => opacity,
                _ => 1.0,
            },
            albedo_texture: albedo_texture.or(own.albedo_texture),
            // A translucent material is not masked: the object's own mask stays off it.
            alpha_mask: match m.alpha {
                GltfAlpha::Blend { .. } => None,
                _ => alpha_mask.or(own.alpha_mask),
            },
            alpha_cutoff: own.alpha_cutoff,
            double_sided: m.double_sided,
        }
    }

    /// A mesh file's material (see [`Self::from_mtl`] and [`Self::from_gltf`]).
    pub(crate) fn from_file(
        m: &FileMaterial,
        own: &ObjectMaterial,
        folder: &Path,
        textures: &mut TextureRequests,
    ) -> ObjectMaterial {
        match m {
            FileMaterial::Mtl(m) => Self::from_mtl(m, own, folder, textures),
            FileMaterial::Gltf(m) => Self::from_gltf(m, own, textures),
        }
    }
}

/// The material a mesh file gives some of its faces.
#[derive(Debug, Clone)]
pub(crate) enum FileMaterial {
    Mtl(Box<tobj::Material>),
    Gltf(GltfMaterial),
}

/// The file of an MTL texture statement: its last word (options such as `-bm 1` come
/// first), with Windows separators turned around.
fn image_file(statement: &str) -> String {
    statement
        .split_whitespace()
        .last()
        .unwrap_or(statement)
        .replace('\\', "/")
}

/// The folder a mesh's own files (MTL libraries, textures) are relative to.
pub(crate) fn mesh_folder(mesh: &MeshDesc, base: &Path) -> PathBuf {
    match mesh {
        MeshDesc::Obj(file) | MeshDesc::Gltf(file) => base
            .join(file)
            .parent()
            .map_or_else(|| base.to_path_buf(), Path::to_path_buf),
        _ => base.to_path_buf(),
    }
}

/// Checks an object's material fields; the error names the field.
pub(crate) fn check_material(
    object: &ObjectDesc,
    field: &str,
) -> Result<(), (String, &'static str)> {
    if !object.color.is_finite() {
        return Err((
            format!("{field}.color"),
            "coordinates must be finite numbers",
        ));
    }
    if !(0.0..=1.0).contains(&object.specular) || !object.shininess.is_finite() {
        return Err((
            format!("{field}.specular"),
            "specular must be in [0, 1] and shininess finite",
        ));
    }
    if !(0.0..=1.0).contains(&object.opacity) {
        return Err((
            format!("{field}.opacity"),
            "opacity must be in [0, 1] (1 is opaque)",
        ));
    }
    if !(object.transmission.cmpge(Vec3::ZERO).all() && object.transmission.cmple(Vec3::ONE).all())
    {
        return Err((
            format!("{field}.transmission"),
            "transmission components must be in [0, 1]",
        ));
    }
    if !(0.0..=1.0).contains(&object.alpha_cutoff) {
        return Err((format!("{field}.alpha_cutoff"), "must be in [0, 1]"));
    }
    if object.alpha_mask.is_some() && object.opacity < 1.0 {
        return Err((
            format!("{field}.opacity"),
            "an alpha-masked object is opaque where its mask covers it: opacity must be 1",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer_of(size: u32, alpha: impl Fn(u32, u32) -> u8) -> Textures {
        let mut rgba = Vec::new();
        for y in 0..size {
            for x in 0..size {
                rgba.extend_from_slice(&[255, 255, 255, alpha(x, y)]);
            }
        }
        Textures {
            size,
            layers: vec![TextureLayer {
                source: PathBuf::from("test"),
                usage: TextureUse::Mask,
                rgba,
            }],
        }
    }

    #[test]
    fn alpha_is_exact_at_texel_centres_and_linear_between_them() {
        let t = layer_of(4, |x, _| if x % 2 == 0 { 255 } else { 0 });
        assert_eq!(t.alpha(0, Vec2::new(0.125, 0.125)), 1.0);
        assert_eq!(t.alpha(0, Vec2::new(0.375, 0.625)), 0.0);
        assert!((t.alpha(0, Vec2::new(0.25, 0.5)) - 0.5).abs() < 1e-6);
        // Repeats: u = 1.125 is u = 0.125; u = 0 lies between the last and the first column.
        assert_eq!(t.alpha(0, Vec2::new(1.125, -0.875)), 1.0);
        // Huge and non-finite coordinates neither overflow nor make holes.
        assert!((0.0..=1.0).contains(&t.alpha(0, Vec2::new(1e16, -3e18))));
        assert_eq!(t.alpha(0, Vec2::new(f32::INFINITY, 0.5)), 1.0);
        assert_eq!(t.alpha(0, Vec2::new(f32::NAN, 0.5)), 1.0);
        assert!((t.alpha(0, Vec2::new(0.0, 0.3)) - 0.5).abs() < 1e-6);
        // A missing layer is opaque.
        assert_eq!(t.alpha(3, Vec2::ZERO), 1.0);
    }

    #[test]
    fn unreadable_images_warn_and_turn_white_and_masks_take_grey_levels() {
        let dir = std::env::temp_dir().join(format!("zoo-textures-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let grey = dir.join("grey.png");
        image::GrayImage::from_fn(3, 5, |x, _| image::Luma([x as u8 * 100]))
            .save(&grey)
            .unwrap();
        let mut requests = TextureRequests::default();
        let mask = requests.request(&grey, TextureUse::Mask);
        let albedo = requests.request(&grey, TextureUse::Albedo);
        let missing = requests.request(&dir.join("missing.png"), TextureUse::Albedo);
        assert_eq!(requests.request(&grey, TextureUse::Mask), mask);
        let mut warnings = Vec::new();
        let textures = requests.load(&mut warnings);
        assert_eq!(textures.size, 8, "5 rounded up to a power of two");
        assert_eq!(textures.layers.len(), 3);
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("missing.png"), "{warnings:?}");
        assert!(
            textures.layers[missing as usize]
                .rgba
                .iter()
                .all(|&c| c == 255)
        );
        // The mask's alpha follows the grey levels; the albedo's alpha is opaque.
        assert!(textures.alpha(mask, Vec2::new(0.05, 0.5)) < 0.1);
        assert!(textures.alpha(mask, Vec2::new(0.95, 0.5)) > 0.7);
        assert_eq!(textures.alpha(albedo, Vec2::new(0.05, 0.5)), 1.0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
