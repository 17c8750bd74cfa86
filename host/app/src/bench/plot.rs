//! PNG plots of benchmark results: per-pass bars and sweep lines.

use std::path::Path;

use anyhow::Context;
use plotters::prelude::*;

use crate::font::{FONT, register as register_font};

fn save(buffer: Vec<u8>, (width, height): (u32, u32), path: &Path) -> anyhow::Result<()> {
    image::RgbImage::from_raw(width, height, buffer)
        .context("plot buffer size")?
        .save(path)
        .with_context(|| format!("cannot write {}", path.display()))
}

fn plot_error(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("plotting failed: {e}")
}

/// One bar: a label and its stacked segments (name, milliseconds).
pub struct Bar {
    pub label: String,
    pub segments: Vec<(String, f64)>,
}

/// Stacked horizontal bars of per-pass median times.
pub fn pass_bars(bars: &[Bar], title: &str, path: &Path) -> anyhow::Result<()> {
    register_font();
    let size = (1200u32, (120 + 36 * bars.len() as u32).max(360));
    let mut buffer = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let max = bars
            .iter()
            .map(|b| b.segments.iter().map(|s| s.1).sum::<f64>())
            .fold(0.0, f64::max)
            .max(1e-3)
            * 1.4;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, (FONT, 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(330)
            .build_cartesian_2d(0.0..max, (0..bars.len()).into_segmented())
            .map_err(plot_error)?;
        let labels: Vec<String> = bars.iter().map(|b| b.label.clone()).collect();
        chart
            .configure_mesh()
            .disable_y_mesh()
            .x_desc("median GPU time (ms)")
            .y_labels(bars.len() + 1)
            .y_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) => labels.get(*i).cloned().unwrap_or_default(),
                _ => String::new(),
            })
            .label_style((FONT, 13))
            .draw()
            .map_err(plot_error)?;
        for (n, name) in segment_names(bars).iter().enumerate() {
            let color = Palette99::pick(n).to_rgba();
            chart
                .draw_series(segment_rects(bars, name, color))
                .map_err(plot_error)?
                .label(name.as_str())
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 12, y + 5)], color.filled())
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 12))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(plot_error)?;
        root.present().map_err(plot_error)?;
    }
    save(buffer, size, path)
}

/// The segments' names over all bars, in order of first appearance.
fn segment_names(bars: &[Bar]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for bar in bars {
        for (name, _) in &bar.segments {
            if !names.contains(name) {
                names.push(name.clone());
            }
        }
    }
    names
}

/// The rectangles of segment `name` in each bar that has it, after the segments before it.
fn segment_rects(
    bars: &[Bar],
    name: &str,
    color: RGBAColor,
) -> Vec<Rectangle<(f64, SegmentValue<usize>)>> {
    bars.iter()
        .enumerate()
        .filter_map(|(i, bar)| {
            let start: f64 = bar
                .segments
                .iter()
                .take_while(|s| s.0 != name)
                .map(|s| s.1)
                .sum();
            let value = bar.segments.iter().find(|s| s.0 == name)?.1;
            Some(Rectangle::new(
                [
                    (start, SegmentValue::Exact(i)),
                    (start + value, SegmentValue::Exact(i + 1)),
                ],
                color.filled(),
            ))
        })
        .collect()
}

/// One line of a sweep plot: a name and (x, y) points.
pub struct Line {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// A line plot of a sweep (median frame time against the swept value).
pub fn sweep_lines(lines: &[Line], title: &str, x_label: &str, path: &Path) -> anyhow::Result<()> {
    register_font();
    let size = (1000u32, 600u32);
    let mut buffer = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let xs = lines.iter().flat_map(|l| l.points.iter().map(|p| p.0));
        let (x0, x1) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        let y1 = lines
            .iter()
            .flat_map(|l| l.points.iter().map(|p| p.1))
            .fold(0.0, f64::max)
            .max(1e-3)
            * 1.1;
        let (x0, x1) = if x0 < x1 {
            (x0, x1)
        } else {
            (x0 - 1.0, x0 + 1.0)
        };
        let mut chart = ChartBuilder::on(&root)
            .caption(title, (FONT, 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, 0.0..y1)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc("median frame time (ms)")
            .label_style((FONT, 14))
            .draw()
            .map_err(plot_error)?;
        for (n, line) in lines.iter().enumerate() {
            let color = Palette99::pick(n).to_rgba();
            chart
                .draw_series(LineSeries::new(
                    line.points.iter().copied(),
                    color.stroke_width(2),
                ))
                .map_err(plot_error)?
                .label(line.name.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
                });
            chart
                .draw_series(
                    line.points
                        .iter()
                        .map(|p| Circle::new(*p, 4, color.filled())),
                )
                .map_err(plot_error)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 13))
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(plot_error)?;
        root.present().map_err(plot_error)?;
    }
    save(buffer, size, path)
}
