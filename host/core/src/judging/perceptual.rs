//! The perceptual score of a final image against the reference image: ꟻLIP (Andersson et
//! al., "FLIP: A Difference Evaluator for Alternating Images", 2020), through the `nv-flip`
//! crate, at its default viewing condition (67 pixels per degree: a 0.7 m wide 4K monitor seen
//! from 0.7 m).

use image::{RgbImage, RgbaImage};

use super::{Judged, SceneReference, shade_on_cpu};
use crate::render::Renderer;

/// A FLIP comparison: the mean and the 95th percentile (nearest rank over pixels) of the
/// per-pixel error in [0, 1], and its map.
#[derive(Debug, Clone)]
pub struct FlipScore {
    pub mean: f64,
    pub p95: f64,
    /// The error mapped through FLIP's magma colour map (black: none, yellow: large).
    pub map: RgbImage,
}

/// FLIP of `test` against `reference` (sRGB images of the same size; alpha is ignored).
/// `None` when the sizes differ or the images are empty, and in the browser build (FLIP's
/// library is C++, which that build does not compile).
#[cfg(target_arch = "wasm32")]
pub fn flip(_reference: &RgbaImage, _test: &RgbaImage) -> Option<FlipScore> {
    None
}

/// FLIP of `test` against `reference` (sRGB images of the same size; alpha is ignored).
/// `None` when the sizes differ or the images are empty.
#[cfg(not(target_arch = "wasm32"))]
pub fn flip(reference: &RgbaImage, test: &RgbaImage) -> Option<FlipScore> {
    let (width, height) = reference.dimensions();
    if test.dimensions() != (width, height) || width == 0 || height == 0 {
        return None;
    }
    let rgb = |image: &RgbaImage| -> Vec<u8> {
        image
            .as_raw()
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect()
    };
    let errors = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference)),
        nv_flip::FlipImageRgb8::with_data(width, height, &rgb(test)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let mut pool = nv_flip::FlipPool::from_image(&errors);
    let colours = errors.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    let map = RgbImage::from_fn(width, height, |x, y| {
        let i = 3 * (y * width + x) as usize;
        image::Rgb([colours[i], colours[i + 1], colours[i + 2]])
    });
    Some(FlipScore {
        mean: f64::from(pool.mean()),
        // Unweighted: the error of the pixel at the 95th percentile (the weighted form is the
        // error below which 95 % of the summed error lies, nonzero for a few bad pixels).
        p95: f64::from(pool.get_percentile(0.95, false)),
        map,
    })
}

/// The frame a technique's final image is judged against: the reference's area visibility
/// shaded on the CPU by the same lighting model (the contact sheet's "area" tile), with the
/// one-bounce indirect reference in place of the ambient when `adds_light` (traced with
/// `samples` rays per pixel on first use). `background` gives the pixels without a surface.
pub fn reference_image(
    renderer: &Renderer,
    reference: &mut SceneReference,
    adds_light: bool,
    samples: u32,
    background: &RgbaImage,
) -> RgbaImage {
    let indirect = adds_light.then(|| {
        reference
            .indirect(renderer.scene(), renderer.lights(), samples)
            .to_vec()
    });
    let area: Vec<&[f32]> = reference.lights.iter().map(|l| l.area.as_slice()).collect();
    shade_on_cpu(
        renderer,
        &reference.gbuffer,
        &area,
        indirect.as_deref(),
        background,
    )
}

/// FLIP of `judged`'s final image against [`reference_image`] (the one with indirect light
/// for techniques that add light), or `None` when the images cannot be compared.
pub fn score_image(
    renderer: &Renderer,
    reference: &mut SceneReference,
    judged: &Judged,
    samples: u32,
) -> Option<FlipScore> {
    let expected = reference_image(
        renderer,
        reference,
        judged.indirect.is_some(),
        samples,
        &judged.image,
    );
    flip(&expected, &judged.image)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(f: impl Fn(u32, u32) -> [u8; 3]) -> RgbaImage {
        RgbaImage::from_fn(64, 48, |x, y| {
            let [r, g, b] = f(x, y);
            image::Rgba([r, g, b, 255])
        })
    }

    #[test]
    fn identical_images_score_zero_and_differences_grow_the_score() {
        let grey = image(|x, _| [(x * 3) as u8, 100, 120]);
        let same = flip(&grey, &grey).unwrap();
        assert_eq!(same.mean, 0.0);
        assert_eq!(same.p95, 0.0);
        // A dark block over a tenth of the image: errors there, none elsewhere.
        let shadowed = image(|x, y| {
            if x < 16 && y < 12 {
                [0, 0, 0]
            } else {
                [(x * 3) as u8, 100, 120]
            }
        });
        let small = flip(&grey, &shadowed).unwrap();
        assert!(small.mean > 0.01 && small.mean < 0.2, "{}", small.mean);
        // Bright (large error) in the block's corner, black far from it.
        let brightness = |x: u32, y: u32| {
            small
                .map
                .get_pixel(x, y)
                .0
                .iter()
                .map(|c| *c as u32)
                .sum::<u32>()
        };
        assert!(
            brightness(0, 0) > 200 && brightness(63, 47) < 60,
            "{} {}",
            brightness(0, 0),
            brightness(63, 47)
        );
        // A sixteenth of the pixels are wrong: the 95th percentile lies among them.
        assert!(small.p95 > 0.1, "{}", small.p95);
        let larger = image(|x, y| {
            if x < 40 && y < 30 {
                [0, 0, 0]
            } else {
                [(x * 3) as u8, 100, 120]
            }
        });
        let large = flip(&grey, &larger).unwrap();
        assert!(large.mean > small.mean && large.p95 >= small.p95);
        // A single wrong pixel moves the mean, not the (unweighted) 95th percentile.
        let speck = image(|x, y| {
            if (x, y) == (30, 20) {
                [0, 0, 0]
            } else {
                [(x * 3) as u8, 100, 120]
            }
        });
        let speck = flip(&grey, &speck).unwrap();
        assert!(
            speck.mean > 0.0 && speck.p95 < 0.01,
            "{} {}",
            speck.mean,
            speck.p95
        );
        assert_eq!(small.map.dimensions(), (64, 48));
        // Different sizes are not compared.
        assert!(flip(&grey, &RgbaImage::new(8, 8)).is_none());
    }
}
