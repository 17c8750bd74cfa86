//! Error metrics of a technique's visibility against the reference.

use crate::reference::LightReference;

/// Scores of one technique for one light.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Metrics {
    /// Contributing pixels (the denominator of the fractions).
    pub pixels: usize,
    /// Technique shadowed (v < 0.5) where the reference is lit: acne, over-darkening.
    pub false_shadow: f64,
    /// Technique lit where the reference is shadowed: leaks, Peter Panning, missing shadows.
    pub false_lit: f64,
    /// `false_shadow` with the one-pixel band around reference shadow boundaries left out.
    pub false_shadow_core: f64,
    /// `false_lit` with the one-pixel band around reference shadow boundaries left out.
    pub false_lit_core: f64,
    /// Mean absolute error against the area reference.
    pub mae: f64,
    /// 95th percentile of the absolute error against the area reference.
    pub p95_error: f64,
}

/// One of the judge's metrics, by name (bounds in tests, the claims report).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    FalseShadow,
    FalseLit,
    FalseShadowCore,
    FalseLitCore,
    Mae,
    P95Error,
}

impl Metric {
    /// Every metric.
    pub const ALL: [Metric; 6] = [
        Metric::FalseShadow,
        Metric::FalseLit,
        Metric::FalseShadowCore,
        Metric::FalseLitCore,
        Metric::Mae,
        Metric::P95Error,
    ];

    /// The metric whose [`Self::name`] is `name`.
    pub fn named(name: &str) -> Option<Metric> {
        Metric::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Column name as in `results.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Metric::FalseShadow => "false_shadow",
            Metric::FalseLit => "false_lit",
            Metric::FalseShadowCore => "false_shadow_core",
            Metric::FalseLitCore => "false_lit_core",
            Metric::Mae => "mae",
            Metric::P95Error => "p95_error",
        }
    }

    /// This metric's value in `metrics`.
    pub fn of(self, metrics: &Metrics) -> f64 {
        match self {
            Metric::FalseShadow => metrics.false_shadow,
            Metric::FalseLit => metrics.false_lit,
            Metric::FalseShadowCore => metrics.false_shadow_core,
            Metric::FalseLitCore => metrics.false_lit_core,
            Metric::Mae => metrics.mae,
            Metric::P95Error => metrics.p95_error,
        }
    }
}

/// How a pixel's technique visibility compares with the hard reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorClass {
    /// The light does not reach the surface: not scored.
    NotContributing,
    BothLit,
    BothShadowed,
    FalseShadow,
    FalseLit,
}

/// Classifies pixel `i`.
pub fn error_class(reference: &LightReference, visibility: &[f32], i: usize) -> ErrorClass {
    if !reference.contributing[i] {
        return ErrorClass::NotContributing;
    }
    match (visibility[i] < 0.5, reference.hard[i] < 0.5) {
        (false, false) => ErrorClass::BothLit,
        (true, true) => ErrorClass::BothShadowed,
        (true, false) => ErrorClass::FalseShadow,
        (false, true) => ErrorClass::FalseLit,
    }
}

/// Contributing pixels that touch a reference shadow boundary: some 8-neighbour is also
/// contributing and has the other hard visibility. Both sides of an edge are in the band.
pub fn edge_band(reference: &LightReference, width: usize, height: usize) -> Vec<bool> {
    let shadowed = |i: usize| reference.hard[i] < 0.5;
    let mut band = vec![false; width * height];
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            if !reference.contributing[i] {
                continue;
            }
            'neighbours: for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx < 0 || ny < 0 || nx >= width as i64 || ny >= height as i64 {
                        continue;
                    }
                    let j = ny as usize * width + nx as usize;
                    if reference.contributing[j] && shadowed(j) != shadowed(i) {
                        band[i] = true;
                        break 'neighbours;
                    }
                }
            }
        }
    }
    band
}

/// Nearest-rank percentile `p` (in [0, 1]) of ascending `sorted` values; 0 when empty.
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (p * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

impl Metrics {
    /// Scores `visibility` (one value per pixel, row-major `width` x `height`) against
    /// `reference`, counting only pixels where `mask` is true (all pixels when `None`).
    pub fn compute(
        reference: &LightReference,
        visibility: &[f32],
        width: usize,
        height: usize,
        mask: Option<&[bool]>,
    ) -> Metrics {
        assert_eq!(
            visibility.len(),
            width * height,
            "visibility has the wrong size"
        );
        let band = edge_band(reference, width, height);
        let (mut pixels, mut core) = (0usize, 0usize);
        let (mut false_shadow, mut false_lit, mut false_shadow_core, mut false_lit_core) =
            (0usize, 0usize, 0usize, 0usize);
        let mut errors = Vec::new();
        for i in 0..visibility.len() {
            if mask.is_some_and(|m| !m[i]) {
                continue;
            }
            let class = error_class(reference, visibility, i);
            if class == ErrorClass::NotContributing {
                continue;
            }
            pixels += 1;
            let in_core = !band[i];
            core += usize::from(in_core);
            match class {
                ErrorClass::FalseShadow => {
                    false_shadow += 1;
                    false_shadow_core += usize::from(in_core);
                }
                ErrorClass::FalseLit => {
                    false_lit += 1;
                    false_lit_core += usize::from(in_core);
                }
                _ => {}
            }
            errors.push((visibility[i].clamp(0.0, 1.0) - reference.area[i]).abs() as f64);
        }
        let fraction = |n: usize, d: usize| if d == 0 { 0.0 } else { n as f64 / d as f64 };
        let mae = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
        errors.sort_by(f64::total_cmp);
        Metrics {
            pixels,
            false_shadow: fraction(false_shadow, pixels),
            false_lit: fraction(false_lit, pixels),
            false_shadow_core: fraction(false_shadow_core, core),
            false_lit_core: fraction(false_lit_core, core),
            mae,
            p95_error: percentile(&errors, 0.95),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(hard: &[f32]) -> LightReference {
        LightReference {
            contributing: vec![true; hard.len()],
            hard: hard.to_vec(),
            area: hard.to_vec(),
            color: None,
            samples: 1,
        }
    }

    #[test]
    fn percentiles_use_nearest_rank() {
        let data: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&data, 0.95), 95.0);
        assert_eq!(percentile(&data, 0.5), 50.0);
        assert_eq!(percentile(&data, 1.0), 100.0);
        assert_eq!(percentile(&data, 0.0), 1.0);
        assert_eq!(percentile(&[], 0.5), 0.0);
    }

    #[test]
    fn band_marks_both_sides_of_a_shadow_edge() {
        // 6 x 3: left three columns shadowed.
        let hard: Vec<f32> = (0..18).map(|i| if i % 6 < 3 { 0.0 } else { 1.0 }).collect();
        let band = edge_band(&reference(&hard), 6, 3);
        for (i, in_band) in band.iter().enumerate() {
            assert_eq!(*in_band, i % 6 == 2 || i % 6 == 3, "pixel {i}");
        }
    }

    #[test]
    fn metrics_count_each_error_kind() {
        // 6 x 3, left half shadowed in the reference.
        let hard: Vec<f32> = (0..18).map(|i| if i % 6 < 3 { 0.0 } else { 1.0 }).collect();
        let r = reference(&hard);
        // The technique: everything lit except pixel 5 (acne in the lit half, column 5 is core)
        // and pixel 2 lit in the shadow (an edge error).
        let mut v: Vec<f32> = hard.clone();
        v[5] = 0.0;
        v[2] = 1.0;
        v[0] = 1.0; // core false lit
        let m = Metrics::compute(&r, &v, 6, 3, None);
        assert_eq!(m.pixels, 18);
        assert_eq!(m.false_shadow, 1.0 / 18.0);
        assert_eq!(m.false_lit, 2.0 / 18.0);
        // Core: columns 0, 1, 4, 5 (12 pixels); pixel 5 and pixel 0 are core errors.
        assert_eq!(m.false_shadow_core, 1.0 / 12.0);
        assert_eq!(m.false_lit_core, 1.0 / 12.0);
        assert!((m.mae - 3.0 / 18.0).abs() < 1e-12);
        assert_eq!(m.p95_error, 1.0);
    }

    #[test]
    fn non_contributing_and_masked_pixels_are_left_out() {
        let mut r = reference(&[0.0, 1.0, 1.0, 1.0]);
        r.contributing[0] = false;
        let v = [1.0, 0.0, 1.0, 1.0];
        let m = Metrics::compute(&r, &v, 4, 1, None);
        assert_eq!(m.pixels, 3);
        assert_eq!(m.false_lit, 0.0);
        assert_eq!(m.false_shadow, 1.0 / 3.0);
        let mask = [true, false, true, true];
        let m = Metrics::compute(&r, &v, 4, 1, Some(&mask));
        assert_eq!(m.pixels, 2);
        assert_eq!(m.false_shadow, 0.0);
    }
}
