//! What every figure shares: the text style, the legend box, and writing a
//! figure as SVG and PNG atomically.

use std::path::Path;

use anyhow::{Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::font::FONT_FAMILY;

/// A figure that can be drawn on any plotters backend.
pub(crate) trait Drawing {
    /// Draws the whole figure onto `root`.
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static;
}

/// A text style of the registered font. Use even sizes: plotters' ab_glyph
/// backend rounds each glyph's vertical offset separately, which for odd sizes
/// moves some glyphs (the decimal point) by a pixel.
pub(crate) fn font(size: f64) -> TextStyle<'static> {
    (FONT_FAMILY, size).into_font().color(&BLACK)
}

/// Draws the legend of `chart`'s labelled series in a framed, translucent box.
pub(crate) fn draw_legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    margin: u32,
    font_size: f64,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    CT: CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(position)
        .margin(margin)
        .label_font(font(font_size))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(120, 120, 120))
        .draw()?;
    Ok(())
}

/// Writes `drawing` of `size` pixels as SVG and PNG, each atomically: the
/// SVG drawn into memory, the PNG drawn into an RGB buffer and encoded with
/// the `png` crate.
pub(crate) fn write_svg_and_png(
    drawing: &impl Drawing,
    size: (u32, u32),
    svg_path: &Path,
    png_path: &Path,
) -> Result<()> {
    let mut svg = String::new();
    draw_on(drawing, SVGBackend::with_string(&mut svg, size), svg_path)?;
    psa_sim::io::write_atomic(svg_path, svg.as_bytes())?;
    let (width, height) = size;
    let pixels = draw_rgb(drawing, size, png_path)?;
    psa_sim::io::write_atomic_with(png_path, |out| {
        let mut encoder = png::Encoder::new(out, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&pixels)?;
        writer.finish()?;
        Ok(())
    })
    .with_context(|| format!("writing {}", png_path.display()))
}

/// `drawing` of `size` pixels as RGB bytes, row after row (errors name
/// `path`, what it is for).
pub(crate) fn draw_rgb(drawing: &impl Drawing, size: (u32, u32), path: &Path) -> Result<Vec<u8>> {
    let mut pixels = vec![0u8; size.0 as usize * size.1 as usize * 3];
    draw_on(drawing, BitMapBackend::with_buffer(&mut pixels, size), path)?;
    Ok(pixels)
}

/// Draws `drawing` whole onto `backend` (errors name `path`, the file it is for).
fn draw_on<DB>(drawing: &impl Drawing, backend: DB, path: &Path) -> Result<()>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let root = backend.into_drawing_area();
    drawing
        .draw(&root)
        .with_context(|| format!("drawing {}", path.display()))?;
    root.present().with_context(|| format!("drawing {}", path.display()))?;
    Ok(())
}
