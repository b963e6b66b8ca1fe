//! Line charts of fitness over generations (the report's Figure 4 and one
//! figure per configuration): lines with an optional shaded band, axes with
//! units, a legend and a title, written as SVG and PNG.

use std::path::{Path, PathBuf};

use anyhow::{ensure, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::font::ensure_font;
use super::output::{draw_legend, font, write_svg_and_png, Drawing};

/// Width of a curve figure in pixels.
pub const CURVE_WIDTH: u32 = 1000;
/// Height of a curve figure in pixels.
pub const CURVE_HEIGHT: u32 = 620;

/// Line colours, in series order (repeating).
pub const CURVE_COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// One line of a curve figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// (x, y) points in order of x.
    pub points: Vec<(f64, f64)>,
    /// An optional shaded band: (x, low, high), e.g. mean ± sd.
    pub band: Option<Vec<(f64, f64, f64)>>,
}

/// A line chart.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveFigure {
    /// Title on top.
    pub title: String,
    /// x-axis description with unit, e.g. "generation".
    pub x_desc: String,
    /// y-axis description with unit, e.g. "fitness (% of theoretical maximum)".
    pub y_desc: String,
    /// The lines, drawn in order.
    pub series: Vec<Series>,
}

impl CurveFigure {
    /// The x and y ranges holding every point and band, with room above the
    /// data for the legend; y starts at 0 unless the data go below it.
    fn ranges(&self) -> ([f64; 2], [f64; 2]) {
        let mut xs = [f64::INFINITY, f64::NEG_INFINITY];
        let mut ys = [0.0f64, f64::NEG_INFINITY];
        let mut take = |x: f64, y: f64| {
            xs = [xs[0].min(x), xs[1].max(x)];
            ys = [ys[0].min(y), ys[1].max(y)];
        };
        for s in &self.series {
            s.points.iter().for_each(|&(x, y)| take(x, y));
            for &(x, lo, hi) in s.band.iter().flatten() {
                take(x, lo);
                take(x, hi);
            }
        }
        if xs[1] <= xs[0] {
            xs = [xs[0] - 0.5, xs[0] + 0.5];
        }
        let top = ys[1].max(ys[0] + 1.0);
        // A third of the height above the data is left for the legend.
        (xs, [ys[0], ys[0] + (top - ys[0]) * 1.45])
    }

    /// Checks that there is something finite to draw.
    fn validate(&self) -> Result<()> {
        ensure!(!self.series.is_empty(), "a curve figure needs at least one series");
        for s in &self.series {
            ensure!(!s.points.is_empty(), "series {:?} has no points", s.label);
            let finite = s.points.iter().all(|&(x, y)| x.is_finite() && y.is_finite())
                && s.band
                    .iter()
                    .flatten()
                    .all(|&(x, lo, hi)| x.is_finite() && lo.is_finite() && hi.is_finite());
            ensure!(finite, "series {:?} has values that are not finite", s.label);
        }
        Ok(())
    }
}

/// Writes `<stem>.svg` and `<stem>.png` into `dir` (created if needed), each
/// file whole or not at all; returns their paths (SVG first).
///
/// Fails if the figure has no series, a series has no points or a value is
/// not finite, if no font is installed (see [`super::ensure_font`]) or if a
/// file cannot be written.
pub fn write_curve_figure(figure: &CurveFigure, dir: &Path, stem: &str) -> Result<[PathBuf; 2]> {
    figure.validate()?;
    ensure!(!stem.is_empty(), "the file stem must not be empty");
    ensure_font()?;
    psa_sim::io::create_output_dir(dir)?;
    let svg_path = dir.join(format!("{stem}.svg"));
    let png_path = dir.join(format!("{stem}.png"));

    write_svg_and_png(figure, (CURVE_WIDTH, CURVE_HEIGHT), &svg_path, &png_path)?;
    Ok([svg_path, png_path])
}

impl Drawing for CurveFigure {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
    {
        draw(root, self)
    }
}

/// Draws the chart onto `root`.
fn draw<DB>(root: &DrawingArea<DB, Shift>, figure: &CurveFigure) -> Result<()>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (xs, ys) = figure.ranges();
    let mut chart = ChartBuilder::on(root)
        .caption(&figure.title, font(24.0))
        .margin(16)
        .margin_right(28)
        .x_label_area_size(56)
        .y_label_area_size(76)
        .build_cartesian_2d(xs[0]..xs[1], ys[0]..ys[1])?;
    chart
        .configure_mesh()
        .x_desc(figure.x_desc.as_str())
        .y_desc(figure.y_desc.as_str())
        .axis_desc_style(font(18.0))
        .label_style(font(16.0))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .max_light_lines(1)
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()?;
    for (i, s) in figure.series.iter().enumerate() {
        let color = CURVE_COLORS[i % CURVE_COLORS.len()];
        if let Some(band) = &s.band {
            let outline: Vec<(f64, f64)> = band
                .iter()
                .map(|&(x, _, hi)| (x, hi))
                .chain(band.iter().rev().map(|&(x, lo, _)| (x, lo)))
                .collect();
            chart.draw_series([Polygon::new(outline, color.mix(0.15).filled())])?;
        }
    }
    for (i, s) in figure.series.iter().enumerate() {
        let color = CURVE_COLORS[i % CURVE_COLORS.len()];
        chart
            .draw_series(LineSeries::new(s.points.iter().copied(), color.stroke_width(2)))?
            .label(&s.label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(3)));
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, 10, 16.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure() -> CurveFigure {
        let points: Vec<(f64, f64)> = (1..=50)
            .map(|g| (g as f64, 40.0 * (1.0 - (-(g as f64) / 10.0).exp())))
            .collect();
        let band = points.iter().map(|&(x, y)| (x, y - 5.0, y + 5.0)).collect();
        CurveFigure {
            title: "test figure".into(),
            x_desc: "generation".into(),
            y_desc: "fitness (% of theoretical maximum)".into(),
            series: vec![
                Series {
                    label: "with band".into(),
                    points: points.clone(),
                    band: Some(band),
                },
                Series {
                    label: "line".into(),
                    points: points.iter().map(|&(x, y)| (x, y / 2.0)).collect(),
                    band: None,
                },
            ],
        }
    }

    #[test]
    fn writes_svg_and_png() {
        let dir = tempfile::tempdir().unwrap();
        let [svg, png] = write_curve_figure(&figure(), dir.path(), "curves").unwrap();
        let svg_text = std::fs::read_to_string(&svg).unwrap();
        assert!(svg_text.contains("</svg>") && svg_text.contains("with band") && svg_text.contains("generation"));
        let png_bytes = std::fs::read(&png).unwrap();
        assert!(png_bytes.starts_with(b"\x89PNG\r\n\x1a\n"));
        // No temporary file is left behind.
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }

    #[test]
    fn bad_figures_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let mut empty = figure();
        empty.series.clear();
        assert!(write_curve_figure(&empty, dir.path(), "x").is_err());
        let mut nan = figure();
        nan.series[1].points[3].1 = f64::NAN;
        assert!(write_curve_figure(&nan, dir.path(), "x").is_err());
        // A single point still gets a usable x range.
        let mut one = figure();
        one.series.truncate(1);
        one.series[0].points.truncate(1);
        one.series[0].band = None;
        assert!(write_curve_figure(&one, dir.path(), "one").is_ok());
    }
}
