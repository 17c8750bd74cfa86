//! The zoo on one page: every available technique and the ray-traced reference (hard and area)
//! rendered from the same view, each tile labelled with its name, frame time and judged error.

use std::fmt::Write as _;

use anyhow::Context;
use image::{Rgb, RgbImage, RgbaImage};
use plotters::prelude::*;
use zoo_host::judging::perceptual::score_image;
use zoo_host::judging::{Judged, SceneReference, judge_technique, shade_on_cpu};
use zoo_host::params::ParamValues;
use zoo_host::{GpuContext, Renderer, Scene, TechniqueRegistration};

use crate::font::{self, FONT};

/// Judged error of one technique, summed over the lights it supports (weighted by each light's
/// contributing pixels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    pub false_shadow_core: f64,
    pub false_lit_core: f64,
    pub mae: f64,
    /// Mean ꟻLIP of the final image against the reference image (`None` when not scored).
    pub flip: Option<f64>,
}

impl Summary {
    /// The pixel-weighted mean over the lights `judged` was scored for (`None` if none).
    pub fn of(judged: &Judged) -> Option<Summary> {
        let scored: Vec<_> = judged
            .scores
            .iter()
            .filter_map(|s| s.metrics.as_ref())
            .collect();
        let pixels: usize = scored.iter().map(|m| m.pixels).sum();
        if pixels == 0 {
            return None;
        }
        let mean = |f: &dyn Fn(&zoo_host::judge::Metrics) -> f64| {
            scored.iter().map(|m| f(m) * m.pixels as f64).sum::<f64>() / pixels as f64
        };
        Some(Summary {
            false_shadow_core: mean(&|m| m.false_shadow_core),
            false_lit_core: mean(&|m| m.false_lit_core),
            mae: mean(&|m| m.mae),
            flip: None,
        })
    }
}

/// One row of the sheet's table (and one tile).
#[derive(Debug, Clone)]
pub struct Row {
    /// Technique id, or `reference (hard)` / `reference (area)`.
    pub id: String,
    /// Human-readable name.
    pub name: String,
    /// GPU time of the whole frame, and of the technique's own passes (ms); `None` for the
    /// reference, whose tracing time is in `note`.
    pub frame_ms: Option<f64>,
    pub technique_ms: Option<f64>,
    /// The technique's pass timings.
    pub timings: Option<zoo_host::gpu::FrameTimings>,
    pub summary: Option<Summary>,
    /// Lights the technique does not support (rendered unshadowed, not scored).
    pub unsupported: Vec<usize>,
    /// Whether it treated the scene's masked casters as opaque.
    pub masks_opaque: bool,
    /// Why the technique failed, if it did.
    pub failure: Option<String>,
    /// Extra note (for the reference tiles).
    pub note: Option<String>,
}

impl Row {
    /// A row with nothing measured.
    fn new(id: &str, name: String) -> Row {
        Row {
            id: id.to_string(),
            name,
            frame_ms: None,
            technique_ms: None,
            timings: None,
            summary: None,
            unsupported: Vec::new(),
            masks_opaque: false,
            failure: None,
            note: None,
        }
    }

    fn label_lines(&self) -> Vec<String> {
        let title = if self.note.is_some() {
            self.name.clone()
        } else {
            format!("{}  ({})", self.name, self.id)
        };
        let mut lines = vec![title];
        if let Some(failure) = &self.failure {
            lines.push(format!("failed: {failure}"));
            return lines;
        }
        let mut timing = String::new();
        if let Some(ms) = self.frame_ms {
            let _ = write!(timing, "frame {ms:.2} ms");
        }
        if let Some(ms) = self.technique_ms {
            let _ = write!(timing, "  (technique {ms:.2} ms)");
        }
        if let Some(note) = &self.note {
            if !timing.is_empty() {
                timing.push_str("  ");
            }
            timing.push_str(note);
        }
        lines.push(timing);
        match &self.summary {
            Some(s) => {
                let mut line = format!(
                    "false shadow {:.4}  false lit {:.4}  mae {:.4}",
                    s.false_shadow_core, s.false_lit_core, s.mae
                );
                if let Some(flip) = s.flip {
                    let _ = write!(line, "  FLIP {flip:.3}");
                }
                lines.push(line)
            }
            None if self.id == "reference (hard)" => {
                lines.push("the judge's exact visibility".to_string())
            }
            None if self.id.starts_with("reference") => {
                lines.push("the judge's soft reference (mae baseline)".to_string())
            }
            None => lines.push("not scored: no supported light".to_string()),
        }
        if !self.unsupported.is_empty() {
            let lights: Vec<String> = self.unsupported.iter().map(usize::to_string).collect();
            let last = lines.last_mut().expect("three lines");
            let _ = write!(last, "  (lights {} unshadowed)", lights.join(","));
        }
        if self.masks_opaque {
            let last = lines.last_mut().expect("three lines");
            let _ = write!(last, "  ({})", zoo_host::MaskedCasters::Opaque.describe());
        }
        lines
    }
}

/// The sheet: tiles in reading order, with a header.
pub struct Sheet {
    pub header: String,
    pub rows: Vec<Row>,
    pub images: Vec<RgbaImage>,
}

/// Techniques the sheet shows: every registered one the device can run, plus those it cannot
/// with the reason.
pub fn available_techniques(
    gpu: &GpuContext,
) -> (
    Vec<&'static TechniqueRegistration>,
    Vec<(&'static str, String)>,
) {
    let mut available = Vec::new();
    let mut unavailable = Vec::new();
    for registration in zoo_host::registry() {
        match registration.unavailable_reason(gpu) {
            None => available.push(registration),
            Some(reason) => unavailable.push((registration.id, reason)),
        }
    }
    (available, unavailable)
}

/// Renders and judges `techniques` (with their parameter values) on `renderer`'s view and
/// traces the reference with `samples` area samples per pixel.
pub fn build(
    renderer: &mut Renderer,
    techniques: &[(&'static TechniqueRegistration, ParamValues)],
    samples: u32,
    mut progress: impl FnMut(&str),
) -> anyhow::Result<Sheet> {
    progress("reference");
    let mut reference = SceneReference::compute(renderer, samples, |_| {})?;
    let (mut rows, mut images) = reference_tiles(renderer, &reference);
    let tile_size = reference.gbuffer.size;
    for (registration, values) in techniques {
        progress(registration.id);
        let (row, image) = match judge_technique(renderer, &reference, registration.id, values) {
            Ok(judged) => {
                let flip = score_image(renderer, &mut reference, &judged, samples);
                judged_tile(registration, judged, flip.map(|f| f.mean))
            }
            Err(e) => {
                let row = Row {
                    failure: Some(e.to_string()),
                    ..Row::new(registration.id, registration.name.to_string())
                };
                let image =
                    RgbaImage::from_pixel(tile_size.x, tile_size.y, image::Rgba([60, 20, 20, 255]));
                (row, image)
            }
        };
        rows.push(row);
        images.push(image);
    }
    let scene: &Scene = renderer.scene();
    let size = renderer.size();
    Ok(Sheet {
        header: format!(
            "Shadow Zoo: {}, {}x{} per tile, on {}",
            scene.name,
            size.x,
            size.y,
            renderer.gpu().info.name
        ),
        rows,
        images,
    })
}

/// The two reference tiles, hard and area visibility shaded on the CPU over the output
/// `renderer` last rendered, with their rows.
fn reference_tiles(renderer: &Renderer, reference: &SceneReference) -> (Vec<Row>, Vec<RgbaImage>) {
    let background = renderer.read_output();
    let traced = format!(
        "ray traced in {:.2} s ({} triangles)",
        reference.seconds, reference.occluder_triangles
    );
    let reference_row = |id: &str, name: String| Row {
        note: Some(traced.clone()),
        ..Row::new(id, name)
    };
    let rows = vec![
        reference_row("reference (hard)", "Reference: hard shadows".into()),
        reference_row(
            "reference (area)",
            format!(
                "Reference: area lights, {} samples",
                reference.lights.first().map_or(0, |l| l.samples)
            ),
        ),
    ];
    let hard: Vec<&[f32]> = reference.lights.iter().map(|l| l.hard.as_slice()).collect();
    let area: Vec<&[f32]> = reference.lights.iter().map(|l| l.area.as_slice()).collect();
    let images = vec![
        shade_on_cpu(renderer, &reference.gbuffer, &hard, None, &background),
        shade_on_cpu(renderer, &reference.gbuffer, &area, None, &background),
    ];
    (rows, images)
}

/// A judged technique's tile: its row (with the mean ꟻLIP of its image, if scored) and its
/// final image.
fn judged_tile(
    registration: &TechniqueRegistration,
    judged: Judged,
    flip: Option<f64>,
) -> (Row, RgbaImage) {
    let row = Row {
        frame_ms: Some(judged.timings.frame_total()),
        technique_ms: Some(judged.gpu_ms),
        timings: Some(judged.timings.clone()),
        summary: Summary::of(&judged).map(|s| Summary { flip, ..s }),
        unsupported: judged
            .scores
            .iter()
            .filter(|s| s.metrics.is_none())
            .map(|s| s.light)
            .collect(),
        masks_opaque: judged.masks_opaque,
        ..Row::new(registration.id, registration.name.to_string())
    };
    (row, judged.image)
}

/// Columns of a sheet with `tiles` tiles: close to square.
pub fn columns(tiles: usize) -> usize {
    (tiles as f64).sqrt().ceil().max(1.0) as usize
}

const LABEL_LINES: u32 = 3;
const BACKGROUND: Rgb<u8> = Rgb([28, 28, 32]);

/// Where things go on a sheet: a header, then tiles in rows with their labels underneath.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Tile width and height in pixels.
    pub tile: (u32, u32),
    pub columns: u32,
    pub rows: u32,
    /// Label text size and line height (px).
    pub text: u32,
    pub line: u32,
    gap: u32,
    header: u32,
    label: u32,
}

impl Layout {
    /// The layout of `tiles` tiles of `tile` pixels.
    pub fn new(tile: (u32, u32), tiles: usize) -> Layout {
        let text = (tile.0 / 26).clamp(11, 20);
        let line = text * 13 / 10;
        let columns = columns(tiles) as u32;
        Layout {
            tile,
            columns,
            rows: (tiles as u32).div_ceil(columns),
            text,
            line,
            gap: (text / 2).max(4),
            header: line * 2,
            label: LABEL_LINES * line + text / 2,
        }
    }

    /// Width and height of the whole sheet.
    pub fn size(&self) -> (u32, u32) {
        (
            self.columns * self.tile.0 + (self.columns + 1) * self.gap,
            self.header + self.rows * (self.tile.1 + self.label + self.gap) + self.gap,
        )
    }

    /// Top-left corner of tile `i`'s image.
    pub fn origin(&self, i: usize) -> (u32, u32) {
        let (col, row) = (i as u32 % self.columns, i as u32 / self.columns);
        (
            self.gap + col * (self.tile.0 + self.gap),
            self.header + row * (self.tile.1 + self.label + self.gap),
        )
    }
}

/// Draws the sheet: a header line, then the tiles in rows with their labels underneath.
pub fn draw(sheet: &Sheet) -> anyhow::Result<RgbImage> {
    font::register();
    let tile = sheet
        .images
        .first()
        .map(|i| i.dimensions())
        .context("a sheet needs at least one tile")?;
    let layout = Layout::new(tile, sheet.images.len());
    let (width, height) = layout.size();
    let mut canvas = RgbImage::from_pixel(width, height, BACKGROUND);
    for (i, image) in sheet.images.iter().enumerate() {
        let (x0, y0) = layout.origin(i);
        for (x, y, p) in image.enumerate_pixels() {
            canvas.put_pixel(x0 + x, y0 + y, Rgb([p[0], p[1], p[2]]));
        }
    }
    let (text, line) = (layout.text, layout.line);
    let mut buffer = canvas.into_raw();
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        let draw_error = |e: DrawingAreaErrorKind<_>| anyhow::anyhow!("drawing the sheet: {e}");
        let title = (FONT, (text + 4) as f64).into_font().color(&WHITE);
        root.draw_text(
            &sheet.header,
            &title,
            (layout.gap as i32, (line / 3) as i32),
        )
        .map_err(draw_error)?;
        let primary = (FONT, text as f64)
            .into_font()
            .color(&RGBColor(235, 235, 235));
        let secondary = (FONT, text as f64)
            .into_font()
            .color(&RGBColor(175, 180, 190));
        for (i, row) in sheet.rows.iter().enumerate() {
            let (x0, y0) = layout.origin(i);
            let y_text = y0 + tile.1 + text / 4;
            for (k, label) in row.label_lines().iter().enumerate() {
                let style = if k == 0 { &primary } else { &secondary };
                let clipped = clip_to_width(label, tile.0, |t| {
                    root.estimate_text_size(t, style)
                        .map_or(u32::MAX, |(w, _)| w)
                });
                root.draw_text(
                    &clipped,
                    style,
                    (x0 as i32, (y_text + k as u32 * line) as i32),
                )
                .map_err(draw_error)?;
            }
        }
        root.present().map_err(draw_error)?;
    }
    RgbImage::from_raw(width, height, buffer).context("sheet buffer size")
}

/// Shortens `text` (ending it with an ellipsis) until `measure` says it fits `width` pixels.
fn clip_to_width(text: &str, width: u32, measure: impl Fn(&str) -> u32) -> String {
    if measure(text) <= width {
        return text.to_string();
    }
    let chars: Vec<char> = text.chars().collect();
    for keep in (0..chars.len()).rev() {
        let candidate: String = chars[..keep].iter().chain(['…'].iter()).collect();
        if measure(&candidate) <= width {
            return candidate;
        }
    }
    String::new()
}

/// The sheet's numbers as a text table.
pub fn table(sheet: &Sheet) -> String {
    let width = sheet
        .rows
        .iter()
        .map(|r| r.id.len())
        .max()
        .unwrap_or(8)
        .max(9);
    let mut out = format!(
        "{:width$}  {:>9}  {:>9}  {:>17}  {:>14}  {:>7}  {:>6}\n",
        "technique", "frame ms", "tech. ms", "false shadow core", "false lit core", "mae", "FLIP"
    );
    let cell = |v: Option<f64>, digits: usize| match v {
        Some(v) => format!("{v:.digits$}"),
        None => "-".to_string(),
    };
    for row in &sheet.rows {
        let _ = write!(
            out,
            "{:width$}  {:>9}  {:>9}  {:>17}  {:>14}  {:>7}  {:>6}",
            row.id,
            cell(row.frame_ms, 2),
            cell(row.technique_ms, 2),
            cell(row.summary.map(|s| s.false_shadow_core), 4),
            cell(row.summary.map(|s| s.false_lit_core), 4),
            cell(row.summary.map(|s| s.mae), 4),
            cell(row.summary.and_then(|s| s.flip), 3),
        );
        if let Some(f) = &row.failure {
            let _ = write!(out, "  failed: {f}");
        } else if let Some(note) = &row.note {
            let _ = write!(out, "  {note}");
        } else if !row.unsupported.is_empty() {
            let lights: Vec<String> = row.unsupported.iter().map(usize::to_string).collect();
            let _ = write!(out, "  lights {} not supported", lights.join(","));
        }
        if row.masks_opaque {
            let _ = write!(out, "  {}", zoo_host::MaskedCasters::Opaque.describe());
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_make_a_near_square_grid() {
        assert_eq!(columns(1), 1);
        assert_eq!(columns(4), 2);
        assert_eq!(columns(6), 3);
        assert_eq!(columns(7), 3);
        assert_eq!(columns(10), 4);
    }

    #[test]
    fn long_labels_are_clipped_to_the_tile() {
        // A monospaced measure: 6 px a character.
        let measure = |t: &str| 6 * t.chars().count() as u32;
        assert_eq!(clip_to_width("short", 200, measure), "short");
        let clipped = clip_to_width(&"x".repeat(100), 100, measure);
        assert_eq!(clipped.chars().count(), 16);
        assert!(clipped.ends_with('…'));
        assert_eq!(clip_to_width("wide", 3, measure), "");
    }
}
