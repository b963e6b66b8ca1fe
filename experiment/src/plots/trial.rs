//! Pictures of one recorded trial: a static figure (SVG and PNG) and an
//! animated SVG that replays the trial in real time.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use anyhow::ensure;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::animation;
use super::font::ensure_font;
use super::output::{draw_legend, draw_rgb, font, write_svg_and_png, Drawing};
use super::picture::{equal_aspect, TrialPicture, THRUSTER_COLORS, THRUSTER_NAMES};

/// Width of the static figure in pixels.
pub const FIGURE_WIDTH: u32 = 1280;
/// Height of the static figure in pixels.
pub const FIGURE_HEIGHT: u32 = 760;
/// About this many heading arrows are drawn along the path.
pub const HEADING_ARROWS: usize = 25;

const PATH_COLOR: RGBColor = RGBColor(31, 119, 180);
const BOX_FILL: RGBColor = RGBColor(198, 239, 198);
const BOX_EDGE: RGBColor = RGBColor(0, 120, 0);
const ARROW_COLOR: RGBColor = RGBColor(230, 110, 0);
const END_COLOR: RGBColor = RGBColor(214, 39, 40);
const HEADING_ERROR_COLOR: RGBColor = RGBColor(128, 60, 170);
const OMEGA_COLOR: RGBColor = RGBColor(140, 86, 75);
const ON_HEADING_FILL: RGBColor = RGBColor(120, 200, 120);

/// Writes `<stem>.svg`, `<stem>.png` (the static figure) and
/// `<stem>-animation.svg` into `dir`, creating `dir` if needed; returns the
/// paths written.
///
/// The static figure shows the path in the x-y plane with the target box,
/// heading arrows, start and end; each thruster's output over time; and the
/// heading error and angular velocity over time. The animation replays the
/// trial in real time (steps x dt seconds, repeating).
///
/// Fails if the trial has no steps or is inconsistent (see
/// [`TrialPicture::validate`]), if no font is installed (see
/// [`super::ensure_font`]) or if a file cannot be written.
pub fn write_trial_pictures(picture: &TrialPicture, dir: &Path, stem: &str) -> anyhow::Result<Vec<PathBuf>> {
    picture.validate()?;
    ensure!(!stem.is_empty(), "the file stem must not be empty");
    ensure_font()?;
    psa_sim::io::create_output_dir(dir)?;

    let svg_path = dir.join(format!("{stem}.svg"));
    let png_path = dir.join(format!("{stem}.png"));
    let animation_path = dir.join(format!("{stem}-animation.svg"));

    write_svg_and_png(picture, (FIGURE_WIDTH, FIGURE_HEIGHT), &svg_path, &png_path)?;
    let svg = animation::animation_svg(picture);
    psa_sim::io::write_atomic(&animation_path, svg.as_bytes())?;

    Ok(vec![svg_path, png_path, animation_path])
}

/// The static figure of `picture` (what [`write_trial_pictures`] writes
/// as `<stem>.png`) as RGB bytes, row after row, [`FIGURE_WIDTH`] x
/// [`FIGURE_HEIGHT`] pixels: a frame of a trial under way (the Python
/// environment's `render()`). Fails as [`write_trial_pictures`] does.
pub fn trial_frame(picture: &TrialPicture) -> anyhow::Result<Vec<u8>> {
    picture.validate()?;
    ensure_font()?;
    draw_rgb(
        picture,
        (FIGURE_WIDTH, FIGURE_HEIGHT),
        Path::new("a frame of the trial"),
    )
}

/// A tick label with `decimals` decimals and no "-0.00".
fn tick_label(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    match text.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => text,
    }
}

impl Drawing for TrialPicture<'_> {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
    {
        draw_figure(root, self)
    }
}

/// Draws the whole static figure onto `root`.
fn draw_figure<DB>(root: &DrawingArea<DB, Shift>, picture: &TrialPicture) -> anyhow::Result<()>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let body = root.margin(6, 0, 0, 0).titled(&picture.title, font(26.0))?;
    let (width, _) = body.dim_in_pixel();
    let (left, right) = body.split_horizontally(width * 47 / 100);
    draw_path_panel(&left, picture)?;

    let (_, right_height) = right.dim_in_pixel();
    let (thrusters, states) = right.split_vertically(right_height * 60 / 100);
    draw_thruster_panels(&thrusters, picture)?;
    draw_state_panel(&states, picture)?;
    Ok(())
}

fn xy_builder<'a, 'b, DB: DrawingBackend>(area: &'a DrawingArea<DB, Shift>) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(12)
        .margin_right(24)
        .x_label_area_size(50)
        .y_label_area_size(70);
    builder
}

/// An arrow from `tail` of length `length` pointing along `angle` (rad,
/// anticlockwise from +x): the shaft and the two barbs.
fn arrow(tail: (f64, f64), angle: f64, length: f64) -> [Vec<(f64, f64)>; 2] {
    let tip = (tail.0 + length * angle.cos(), tail.1 + length * angle.sin());
    let barb = 0.35 * length;
    let wing = |da: f64| (tip.0 + barb * (angle + da).cos(), tip.1 + barb * (angle + da).sin());
    let barbs = vec![wing(2.6), tip, wing(-2.6)];
    [vec![tail, tip], barbs]
}

/// Direction (rad from +x) of the body's forward (+y) axis at a heading.
fn forward_angle(heading: f64) -> f64 {
    heading + std::f64::consts::FRAC_PI_2
}

/// Left panel: the path in the x-y plane.
fn draw_path_panel<DB>(area: &DrawingArea<DB, Shift>, picture: &TrialPicture) -> anyhow::Result<()>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let area = area.titled("path in the x-y plane", font(20.0))?;
    let (xs, ys) = picture.world_bounds();
    let span = (xs[1] - xs[0]).max(ys[1] - ys[0]).max(4.0 * picture.hull_radius);
    let pad = 0.08 * span + picture.hull_radius;
    let (xs, ys) = ([xs[0] - pad, xs[1] + pad], [ys[0] - pad, ys[1] + pad]);
    // Plotting-area size for these label areas; building a chart draws nothing.
    let pixels = xy_builder(&area)
        .build_cartesian_2d(0.0..1.0, 0.0..1.0)?
        .plotting_area()
        .dim_in_pixel();
    let (xs, ys) = equal_aspect(xs, ys, pixels);
    let span = (xs[1] - xs[0]).max(ys[1] - ys[0]);

    let mut chart = xy_builder(&area).build_cartesian_2d(xs[0]..xs[1], ys[0]..ys[1])?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .axis_desc_style(font(18.0))
        .label_style(font(16.0))
        .x_label_formatter(&|v| tick_label(*v, 2))
        .y_label_formatter(&|v| tick_label(*v, 2))
        .max_light_lines(1)
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()?;

    let (tx, ty, w) = (picture.target[0], picture.target[1], picture.box_half_width);
    chart
        .draw_series([
            Rectangle::new([(tx - w, ty - w), (tx + w, ty + w)], BOX_FILL.filled()),
            Rectangle::new([(tx - w, ty - w), (tx + w, ty + w)], BOX_EDGE.stroke_width(2)),
        ])?
        .label(format!("target box (±{w:.2} m)"))
        .legend(|(x, y)| Rectangle::new([(x, y - 7), (x + 20, y + 7)], ShapeStyle::from(BOX_FILL).filled()));

    let arrow_length = 0.05 * span;
    let target_arrow = arrow((tx, ty), forward_angle(picture.target[2]), 1.6 * arrow_length);
    chart
        .draw_series(
            target_arrow
                .into_iter()
                .map(|p| PathElement::new(p, BOX_EDGE.stroke_width(3))),
        )?
        .label("target heading")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BOX_EDGE.stroke_width(3)));

    chart
        .draw_series(LineSeries::new(
            picture.states.iter().map(|s| (s.x, s.y)),
            PATH_COLOR.stroke_width(2),
        ))?
        .label("path")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], PATH_COLOR.stroke_width(2)));

    let every = picture.steps().div_ceil(HEADING_ARROWS).max(1);
    let arrows = picture
        .states
        .iter()
        .step_by(every)
        .flat_map(|s| arrow((s.x, s.y), forward_angle(s.heading), arrow_length))
        .map(|p| PathElement::new(p, ARROW_COLOR.stroke_width(2)));
    chart
        .draw_series(arrows)?
        .label(format!("heading (body +y), every {:.2} s", every as f64 * picture.dt))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], ARROW_COLOR.stroke_width(2)));

    let start = picture.states[0];
    let end = picture.states[picture.states.len() - 1];
    chart
        .draw_series([Circle::new((start.x, start.y), 7, BLACK.filled())])?
        .label("start")
        .legend(|(x, y)| Circle::new((x + 10, y), 6, BLACK.filled()));
    chart
        .draw_series([TriangleMarker::new((end.x, end.y), 9, END_COLOR.filled())])?
        .label(format!("end (t = {:.2} s)", picture.duration()))
        .legend(|(x, y)| TriangleMarker::new((x + 10, y), 7, END_COLOR.filled()));

    draw_legend(&mut chart, emptiest_corner(picture, xs, ys), 10, 16.0)
}

/// The plot corner with the fewest path points nearby, for the legend.
fn emptiest_corner(picture: &TrialPicture, xs: [f64; 2], ys: [f64; 2]) -> SeriesLabelPosition {
    let (wx, wy) = (xs[1] - xs[0], ys[1] - ys[0]);
    let (tx, ty, w) = (picture.target[0], picture.target[1], picture.box_half_width);
    // (position, near the left edge, near the top edge)
    let corners = [
        (SeriesLabelPosition::UpperRight, false, true),
        (SeriesLabelPosition::UpperLeft, true, true),
        (SeriesLabelPosition::LowerRight, false, false),
        (SeriesLabelPosition::LowerLeft, true, false),
    ];
    let inside = |left: bool, top: bool, x: f64, y: f64| {
        let near_x = if left {
            x < xs[0] + 0.5 * wx
        } else {
            x > xs[1] - 0.5 * wx
        };
        let near_y = if top {
            y > ys[1] - 0.4 * wy
        } else {
            y < ys[0] + 0.4 * wy
        };
        near_x && near_y
    };
    corners
        .into_iter()
        .min_by_key(|&(_, left, top)| {
            let path = picture.states.iter().filter(|s| inside(left, top, s.x, s.y)).count();
            let target = [
                (tx - w, ty - w),
                (tx + w, ty - w),
                (tx - w, ty + w),
                (tx + w, ty + w),
                (tx, ty),
            ]
            .iter()
            .filter(|&&(x, y)| inside(left, top, x, y))
            .count();
            path + target * picture.states.len().max(1) / 5
        })
        .map(|(position, _, _)| position)
        .unwrap_or(SeriesLabelPosition::UpperRight)
}

/// Right upper panels: one strip per thruster, sharing the time axis.
fn draw_thruster_panels<DB>(area: &DrawingArea<DB, Shift>, picture: &TrialPicture) -> anyhow::Result<()>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let area = area.titled("thruster outputs", font(20.0))?;
    let (_, height) = area.dim_in_pixel();
    let x_labels = 40;
    let strip = (height.saturating_sub(x_labels) / 4) as i32;
    let strips = area.split_by_breakpoints([] as [i32; 0], [strip, 2 * strip, 3 * strip]);
    let duration = picture.duration();
    for (i, strip_area) in strips.iter().enumerate() {
        let last = i == 3;
        let color = THRUSTER_COLORS[i];
        let mut chart = ChartBuilder::on(strip_area)
            .margin_left(12)
            .margin_right(24)
            .margin_top(22)
            .margin_bottom(4)
            .x_label_area_size(if last { x_labels } else { 0 })
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..duration, -0.05..1.05)?;
        let mut mesh = chart.configure_mesh();
        mesh.y_desc("output")
            .axis_desc_style(font(16.0))
            .label_style(font(14.0))
            .y_labels(3)
            .y_label_formatter(&|v| tick_label(*v, 1))
            .max_light_lines(1)
            .light_line_style(RGBColor(240, 240, 240))
            .bold_line_style(RGBColor(210, 210, 210));
        if last {
            mesh.x_desc("time (s)").x_label_formatter(&|v| tick_label(*v, 1));
        }
        mesh.draw()?;
        // Each output holds for its whole step: draw a staircase.
        let stairs = picture.outputs.iter().enumerate().flat_map(|(step, u)| {
            let t = step as f64 * picture.dt;
            [(t, u[i]), (t + picture.dt, u[i])]
        });
        chart.draw_series(LineSeries::new(stairs, color.stroke_width(2)))?;

        // The strip's legend, above its plotting area.
        let (x0, _) = chart.plotting_area().get_pixel_range();
        let x0 = x0.start - strip_area.get_base_pixel().0 + 4;
        strip_area.draw(&PathElement::new(vec![(x0, 12), (x0 + 24, 12)], color.stroke_width(3)))?;
        strip_area.draw_text(THRUSTER_NAMES[i], &font(16.0), (x0 + 30, 4))?;
    }
    Ok(())
}

/// Right lower panel: heading error and angular velocity over time, with the
/// time spent in the target box shaded.
fn draw_state_panel<DB>(area: &DrawingArea<DB, Shift>, picture: &TrialPicture) -> anyhow::Result<()>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let area = area.titled("heading error and angular velocity", font(20.0))?;
    let duration = picture.duration();
    let errors: Vec<f64> = picture.states.iter().map(|s| picture.heading_error(s)).collect();
    let (lo, hi) = errors
        .iter()
        .chain(picture.states.iter().map(|s| &s.omega))
        .fold((-0.1f64, 0.1f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let pad = 0.08 * (hi - lo);
    let (lo, hi) = (lo - pad, hi + pad);
    let mut chart = ChartBuilder::on(&area)
        .margin_left(12)
        .margin_right(24)
        .margin_top(4)
        .margin_bottom(8)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..duration, lo..hi)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("rad, rad/s")
        .axis_desc_style(font(16.0))
        .label_style(font(14.0))
        .y_labels(5)
        .x_label_formatter(&|v| tick_label(*v, 1))
        .y_label_formatter(&|v| tick_label(*v, 1))
        .max_light_lines(1)
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()?;

    // Shade the steps spent in the box, darker when also on heading.
    let dt = picture.dt;
    let shade = |on_heading: bool| {
        picture.states.iter().enumerate().skip(1).filter_map(move |(step, s)| {
            let wanted = picture.in_box(s) && (!on_heading || picture.heading_error(s).abs() < picture.heading_window);
            let t = step as f64 * dt;
            let fill = if on_heading { ON_HEADING_FILL } else { BOX_FILL };
            wanted.then(|| Rectangle::new([(t - dt, lo), (t, hi)], fill.filled()))
        })
    };
    chart
        .draw_series(shade(false))?
        .label("in target box")
        .legend(|(x, y)| Rectangle::new([(x, y - 7), (x + 20, y + 7)], BOX_FILL.filled()));
    chart
        .draw_series(shade(true))?
        .label(format!("in box, |heading error| < {:.2} rad", picture.heading_window))
        .legend(|(x, y)| Rectangle::new([(x, y - 7), (x + 20, y + 7)], ON_HEADING_FILL.filled()));

    chart.draw_series(LineSeries::new([(0.0, 0.0), (duration, 0.0)], BLACK.mix(0.5)))?;
    let times = (0..picture.states.len()).map(|step| step as f64 * dt);
    // The heading error wraps at ±pi: break its line there instead of drawing a jump.
    let mut segments: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut segment: Vec<(f64, f64)> = Vec::new();
    for (t, e) in times.clone().zip(errors.iter().copied()) {
        if segment.last().is_some_and(|&(_, last)| (e - last).abs() > PI) {
            segments.push(std::mem::take(&mut segment));
        }
        segment.push((t, e));
    }
    segments.push(segment);
    chart
        .draw_series(
            segments
                .into_iter()
                .map(|seg| PathElement::new(seg, HEADING_ERROR_COLOR.stroke_width(2))),
        )?
        .label("heading error (rad)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], HEADING_ERROR_COLOR.stroke_width(2)));
    chart
        .draw_series(LineSeries::new(
            times.zip(picture.states.iter().map(|s| s.omega)),
            OMEGA_COLOR.stroke_width(2),
        ))?
        .label("angular velocity ω (rad/s)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], OMEGA_COLOR.stroke_width(2)));
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 8, 14.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plots::picture::tests::{picture, spiral};
    use psa_sim::physics::BodyState;

    #[test]
    fn writes_all_three_pictures() {
        let (states, outputs) = spiral(200);
        let picture = picture(&states, &outputs);
        let dir = tempfile::tempdir().unwrap();
        let written = write_trial_pictures(&picture, dir.path(), "trial").unwrap();
        let names: Vec<_> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["trial.svg", "trial.png", "trial-animation.svg"]);
        for path in &written {
            assert!(path.is_file(), "{} missing", path.display());
        }

        let png = std::fs::read(&written[1]).unwrap();
        assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
        assert!(png.len() > 10_000, "PNG suspiciously small: {} bytes", png.len());

        let svg = std::fs::read_to_string(&written[0]).unwrap();
        assert!(svg.starts_with("<svg") || svg.starts_with("<?xml"));
        assert!(svg.trim_end().ends_with("</svg>"));
        for text in [
            "x (m)",
            "y (m)",
            "time (s)",
            "output",
            "path",
            "target box",
            "heading",
            "start",
            "end",
        ] {
            assert!(svg.contains(text), "static SVG lacks {text:?}");
        }
        for name in THRUSTER_NAMES {
            assert!(svg.contains(name), "static SVG lacks {name:?}");
        }
        assert!(svg.contains("&lt;&amp;&gt;"), "the title must be escaped");

        let animation = std::fs::read_to_string(&written[2]).unwrap();
        assert!(animation.starts_with("<svg") || animation.starts_with("<?xml"));
        assert!(animation.trim_end().ends_with("</svg>"));
        assert!(animation.contains("<animate"));
        assert!(animation.contains("<animateTransform"));
        assert!(animation.contains("dur=\"10s\""), "200 steps x 0.05 s = 10 s");
        assert!(!animation.contains("<&>"), "the title must be escaped");
        assert!(animation.len() < 2_000_000);
    }

    #[test]
    fn empty_trial_is_an_error() {
        let states = [BodyState::default()];
        let picture = picture(&states, &[]);
        let dir = tempfile::tempdir().unwrap();
        let error = write_trial_pictures(&picture, dir.path(), "empty").unwrap_err();
        assert!(error.to_string().contains("at least one step"), "{error}");
        let picture = TrialPicture { states: &[], ..picture };
        assert!(write_trial_pictures(&picture, dir.path(), "empty").is_err());
        assert!(
            std::fs::read_dir(dir.path()).unwrap().next().is_none(),
            "nothing written"
        );
    }

    #[test]
    fn inconsistent_trials_are_errors() {
        let (states, outputs) = spiral(10);
        let dir = tempfile::tempdir().unwrap();
        let short = picture(&states, &outputs[..9]);
        assert!(write_trial_pictures(&short, dir.path(), "t").is_err());
        let mut bad_states = states.clone();
        bad_states[3].x = f64::NAN;
        assert!(write_trial_pictures(&picture(&bad_states, &outputs), dir.path(), "t").is_err());
        let zero_dt = TrialPicture {
            dt: 0.0,
            ..picture(&states, &outputs)
        };
        assert!(write_trial_pictures(&zero_dt, dir.path(), "t").is_err());
    }

    #[test]
    fn tick_labels_have_no_negative_zero() {
        assert_eq!(tick_label(-0.0001, 2), "0.00");
        assert_eq!(tick_label(-0.5, 1), "-0.5");
        assert_eq!(tick_label(25.0, 1), "25.0");
    }
}
