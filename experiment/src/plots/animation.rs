//! A hand-written animated SVG (SMIL, no script) that replays one trial in
//! real time: the robot's hull, heading and thrusters with flames whose
//! opacity follows each thruster's output, over the target box and the path.

use std::fmt::Write;

use super::picture::{equal_aspect, TrialPicture, THRUSTER_COLORS, THRUSTER_NAMES};

/// At most this many key frames are written; longer trials are sub-sampled.
pub const MAX_FRAMES: usize = 1000;

/// Canvas width (px).
const WIDTH: f64 = 1180.0;
/// Canvas height (px).
const HEIGHT: f64 = 800.0;
/// The plot of the x-y plane: left, top, width, height (px).
const VIEW: [f64; 4] = [80.0, 60.0, 680.0, 680.0];
/// Left edge of the legend column (px).
const LEGEND_X: f64 = 800.0;

/// Thruster mounts and thrust directions in the body frame, for a mount radius of 1.
const THRUSTERS: [([f64; 2], [f64; 2]); 4] = [
    ([0.0, -1.0], [1.0, 0.0]),
    ([1.0, 0.0], [0.0, 1.0]),
    ([0.0, 1.0], [1.0, 0.0]),
    ([-1.0, 0.0], [0.0, 1.0]),
];

/// Escapes text for XML content and attribute values.
pub(crate) fn xml_escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// A number with at most `decimals` decimals and no trailing zeros.
fn num(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    if text == "-0" {
        "0".to_string()
    } else {
        text.to_string()
    }
}

/// A number with exactly `decimals` decimals, never "-0".
fn fixed(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    match text.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => text,
    }
}

/// A "nice" tick spacing (1, 2 or 5 times a power of ten) giving about `count` ticks over `span`.
fn tick_step(span: f64, count: f64) -> f64 {
    let raw = (span / count).max(1e-9);
    let magnitude = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * magnitude)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * magnitude)
}

/// Decimals needed to print multiples of `step`.
fn decimals_for(step: f64) -> usize {
    (-step.log10().floor()).max(0.0) as usize
}

/// State indices of the key frames: 0, then every `stride` steps, always ending at the last step.
fn frame_indices(steps: usize) -> Vec<usize> {
    let stride = steps.div_ceil(MAX_FRAMES).max(1);
    let mut frames: Vec<usize> = (0..steps).step_by(stride).collect();
    frames.push(steps);
    frames
}

/// Headings made continuous (no jumps of 2 pi), so that rotations interpolate the short way.
fn unwrapped_headings(picture: &TrialPicture) -> Vec<f64> {
    let mut out = Vec::with_capacity(picture.states.len());
    let mut previous: Option<f64> = None;
    for state in picture.states {
        let heading = match previous {
            None => state.heading,
            Some(p) => p + psa_sim::physics::wrap_angle(state.heading - p),
        };
        out.push(heading);
        previous = Some(heading);
    }
    out
}

/// Returns the animation of `picture` as an SVG document. `picture` must be
/// valid (see [`TrialPicture::validate`]).
pub(crate) fn animation_svg(picture: &TrialPicture) -> String {
    let steps = picture.steps();
    let duration = picture.duration();
    let dur = format!("{}s", num(duration, 3));
    let hull = picture.hull_radius;
    let mount = 1.2 * hull;
    let flame_length = 1.3 * hull;

    // World window: path, target box and the robot's reach, in metres, equal aspect.
    let (xs, ys) = picture.world_bounds();
    let reach = mount + 0.2 * hull + flame_length;
    let span = (xs[1] - xs[0]).max(ys[1] - ys[0]);
    let pad = reach + 0.04 * span;
    let (xs, ys) = equal_aspect(
        [xs[0] - pad, xs[1] + pad],
        [ys[0] - pad, ys[1] + pad],
        (VIEW[2] as u32, VIEW[3] as u32),
    );
    let scale = VIEW[2] / (xs[1] - xs[0]); // px per metre
    let px = |metres: f64| num(metres * scale, 2);
    let to_px_x = |x: f64| VIEW[0] + (x - xs[0]) * scale;
    let to_px_y = |y: f64| VIEW[1] + (ys[1] - y) * scale;
    // Stroke widths inside the world group are in metres.
    let sw = |pixels: f64| num(pixels / scale, 6);

    let mut svg = String::with_capacity(256 * 1024);
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="DejaVu Sans, Verdana, Arial, sans-serif">"#,
        w = WIDTH,
        h = HEIGHT
    );
    let _ = writeln!(svg, "<title>{}</title>", xml_escape(&picture.title));
    let _ = writeln!(
        svg,
        r##"<rect x="0" y="0" width="{WIDTH}" height="{HEIGHT}" fill="#ffffff"/>"##
    );
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="34" font-size="24" text-anchor="middle">{}</text>"#,
        WIDTH / 2.0,
        xml_escape(&picture.title)
    );

    // Axes: grid, frame, ticks and labels in pixels.
    let step = tick_step(xs[1] - xs[0], 10.0);
    let decimals = decimals_for(step);
    let _ = writeln!(svg, r##"<g stroke="#e4e4e4" stroke-width="1">"##);
    let mut ticks = String::new();
    let mut k = (xs[0] / step).ceil() as i64;
    while (k as f64) * step <= xs[1] {
        let x = to_px_x(k as f64 * step);
        let _ = writeln!(
            svg,
            r#"<line x1="{0:.2}" y1="{1}" x2="{0:.2}" y2="{2}"/>"#,
            x,
            VIEW[1],
            VIEW[1] + VIEW[3]
        );
        let _ = writeln!(
            ticks,
            r##"<line x1="{0:.2}" y1="{1}" x2="{0:.2}" y2="{2}" stroke="#000"/><text x="{0:.2}" y="{3}" font-size="14" text-anchor="middle">{4}</text>"##,
            x,
            VIEW[1] + VIEW[3],
            VIEW[1] + VIEW[3] + 6.0,
            VIEW[1] + VIEW[3] + 22.0,
            fixed(k as f64 * step, decimals)
        );
        k += 1;
    }
    let mut k = (ys[0] / step).ceil() as i64;
    while (k as f64) * step <= ys[1] {
        let y = to_px_y(k as f64 * step);
        let _ = writeln!(
            svg,
            r#"<line x1="{1}" y1="{0:.2}" x2="{2}" y2="{0:.2}"/>"#,
            y,
            VIEW[0],
            VIEW[0] + VIEW[2]
        );
        let _ = writeln!(
            ticks,
            r##"<line x1="{1}" y1="{0:.2}" x2="{2}" y2="{0:.2}" stroke="#000"/><text x="{3}" y="{4:.2}" font-size="14" text-anchor="end">{5}</text>"##,
            y,
            VIEW[0] - 6.0,
            VIEW[0],
            VIEW[0] - 9.0,
            y + 5.0,
            fixed(k as f64 * step, decimals)
        );
        k += 1;
    }
    let _ = writeln!(svg, "</g>");
    svg.push_str(&ticks);
    let _ = writeln!(
        svg,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#000" stroke-width="1"/>"##,
        VIEW[0], VIEW[1], VIEW[2], VIEW[3]
    );
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" font-size="16" text-anchor="middle">x (m)</text>"#,
        VIEW[0] + VIEW[2] / 2.0,
        VIEW[1] + VIEW[3] + 46.0
    );
    let _ = writeln!(
        svg,
        r#"<text x="0" y="0" font-size="16" text-anchor="middle" transform="translate({} {}) rotate(-90)">y (m)</text>"#,
        VIEW[0] - 58.0,
        VIEW[1] + VIEW[3] / 2.0
    );

    // The world group: metres, y up.
    let _ = writeln!(
        svg,
        r#"<g transform="translate({:.4} {:.4}) scale({:.4} {:.4})">"#,
        VIEW[0] - xs[0] * scale,
        VIEW[1] + ys[1] * scale,
        scale,
        -scale
    );
    let (tx, ty, th) = (picture.target[0], picture.target[1], picture.target[2]);
    let w = picture.box_half_width;
    let _ = writeln!(
        svg,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="#c6efc6" fill-opacity="0.8" stroke="#007800" stroke-width="{}"/>"##,
        num(tx - w, 6),
        num(ty - w, 6),
        num(2.0 * w, 6),
        num(2.0 * w, 6),
        sw(2.0)
    );
    // The target pose: a dashed ghost of the hull with the target heading.
    let _ = writeln!(
        svg,
        r##"<g transform="translate({} {}) rotate({})" fill="none" stroke="#007800" stroke-width="{}" stroke-dasharray="{} {}"><circle cx="0" cy="0" r="{}"/><line x1="0" y1="0" x2="0" y2="{}"/></g>"##,
        num(tx, 6),
        num(ty, 6),
        num(th.to_degrees(), 3),
        sw(2.0),
        sw(6.0),
        sw(4.0),
        num(hull, 6),
        num(2.2 * hull, 6)
    );
    // The path, faint, and the start.
    let stride = steps.div_ceil(4 * MAX_FRAMES).max(1);
    let mut points = String::new();
    for s in picture.states.iter().step_by(stride).chain(picture.states.last()) {
        let _ = write!(points, "{},{} ", num(s.x, 5), num(s.y, 5));
    }
    let _ = writeln!(
        svg,
        r##"<polyline points="{}" fill="none" stroke="#1f77b4" stroke-opacity="0.45" stroke-width="{}" stroke-linejoin="round"/>"##,
        points.trim_end(),
        sw(2.0)
    );
    let start = picture.states[0];
    let _ = writeln!(
        svg,
        r##"<circle cx="{}" cy="{}" r="{}" fill="#000"/>"##,
        num(start.x, 6),
        num(start.y, 6),
        sw(4.0)
    );

    // The robot.
    let frames = frame_indices(steps);
    let key_times = frames
        .iter()
        .map(|&i| {
            if i == steps {
                "1".to_string()
            } else {
                num(i as f64 / steps as f64, 6)
            }
        })
        .collect::<Vec<_>>();
    let headings = unwrapped_headings(picture);
    let translate = frames
        .iter()
        .map(|&i| format!("{} {}", num(picture.states[i].x, 5), num(picture.states[i].y, 5)))
        .collect::<Vec<_>>()
        .join(";");
    let rotate = frames
        .iter()
        .map(|&i| num(headings[i].to_degrees(), 2))
        .collect::<Vec<_>>()
        .join(";");
    let key_times_all = key_times.join(";");
    // The first frame's pose as the static transform, for viewers without SMIL.
    let _ = writeln!(
        svg,
        r#"<g transform="translate({} {})">"#,
        num(start.x, 5),
        num(start.y, 5)
    );
    let _ = writeln!(
        svg,
        r#"<animateTransform attributeName="transform" type="translate" values="{translate}" keyTimes="{key_times_all}" calcMode="linear" dur="{dur}" repeatCount="indefinite"/>"#
    );
    let _ = writeln!(svg, r#"<g transform="rotate({})">"#, num(headings[0].to_degrees(), 2));
    let _ = writeln!(
        svg,
        r#"<animateTransform attributeName="transform" type="rotate" values="{rotate}" keyTimes="{key_times_all}" calcMode="linear" dur="{dur}" repeatCount="indefinite"/>"#
    );
    // Thruster outputs: the mean over each key frame's steps, held until the next key frame.
    let output_frames = &frames[..frames.len() - 1];
    let output_times = key_times[..key_times.len() - 1].join(";");
    let mean_outputs: Vec<[f64; 4]> = frames
        .windows(2)
        .map(|pair| {
            let window = &picture.outputs[pair[0]..pair[1]];
            let mut mean = [0.0; 4];
            for u in window {
                for (m, v) in mean.iter_mut().zip(u) {
                    *m += v.clamp(0.0, 1.0) / window.len() as f64;
                }
            }
            mean
        })
        .collect();
    debug_assert_eq!(mean_outputs.len(), output_frames.len());
    let (thruster_length, thruster_width) = (0.4 * hull, 0.2 * hull);
    for (i, (m, d)) in THRUSTERS.iter().enumerate() {
        let (mx, my) = (m[0] * mount, m[1] * mount);
        // Flame: from the thruster's rear end, pointing against the thrust.
        let rear = (mx - d[0] * thruster_length / 2.0, my - d[1] * thruster_length / 2.0);
        let side = (-d[1], d[0]);
        let half = 0.45 * thruster_width;
        let tip = (rear.0 - d[0] * flame_length, rear.1 - d[1] * flame_length);
        let values = mean_outputs.iter().map(|u| num(u[i], 3)).collect::<Vec<_>>().join(";");
        let _ = writeln!(
            svg,
            r##"<polygon points="{},{} {},{} {},{}" fill="#ff8c00" stroke="#d62728" stroke-width="{}" opacity="{}"><animate attributeName="opacity" values="{values}" keyTimes="{output_times}" calcMode="discrete" dur="{dur}" repeatCount="indefinite"/></polygon>"##,
            num(rear.0 + side.0 * half, 6),
            num(rear.1 + side.1 * half, 6),
            num(tip.0, 6),
            num(tip.1, 6),
            num(rear.0 - side.0 * half, 6),
            num(rear.1 - side.1 * half, 6),
            sw(1.0),
            num(mean_outputs[0][i], 3)
        );
        // Thruster body: a small rectangle along its thrust axis.
        let (rw, rh) = if d[0] != 0.0 {
            (thruster_length, thruster_width)
        } else {
            (thruster_width, thruster_length)
        };
        let _ = writeln!(
            svg,
            r##"<rect x="{}" y="{}" width="{}" height="{}" fill="{}" stroke="#333" stroke-width="{}"/>"##,
            num(mx - rw / 2.0, 6),
            num(my - rh / 2.0, 6),
            num(rw, 6),
            num(rh, 6),
            hex(THRUSTER_COLORS[i]),
            sw(1.0)
        );
    }
    // Hull and heading (body +y).
    let _ = writeln!(
        svg,
        r##"<circle cx="0" cy="0" r="{}" fill="#dddddd" fill-opacity="0.9" stroke="#333" stroke-width="{}"/>"##,
        num(hull, 6),
        sw(2.0)
    );
    let _ = writeln!(
        svg,
        r##"<line x1="0" y1="0" x2="0" y2="{}" stroke="#b00000" stroke-width="{}" stroke-linecap="round"/>"##,
        num(1.5 * hull, 6),
        sw(3.0)
    );
    let _ = writeln!(svg, r##"<circle cx="0" cy="0" r="{}" fill="#333"/>"##, sw(3.0));
    let _ = writeln!(svg, "</g>\n</g>");
    let _ = writeln!(svg, "</g>");

    write_legend(&mut svg, picture, &dur, &mean_outputs, &output_times, px(0.1));
    let _ = writeln!(svg, "</svg>");
    svg
}

fn hex(color: plotters::style::RGBColor) -> String {
    format!("#{:02x}{:02x}{:02x}", color.0, color.1, color.2)
}

/// The right-hand column: clock, progress bar, live thruster bars and the legend.
fn write_legend(
    svg: &mut String,
    picture: &TrialPicture,
    dur: &str,
    mean_outputs: &[[f64; 4]],
    output_times: &str,
    ten_cm_px: String,
) {
    let x = LEGEND_X;
    let duration = picture.duration();
    let total = format!("{duration:.1}");

    // Clock: one label per tick, each visible during its own interval.
    let label_step = [0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 60.0]
        .into_iter()
        .find(|s| duration / s <= 300.0)
        .unwrap_or(duration / 300.0);
    let decimals = decimals_for(label_step).max(1);
    let labels = (duration / label_step).ceil().max(1.0) as usize;
    let _ = writeln!(svg, r#"<g font-size="22">"#);
    for k in 0..labels {
        let (a, b) = (k as f64 * label_step / duration, (k + 1) as f64 * label_step / duration);
        let text = format!("t = {:.decimals$} s / {total} s", k as f64 * label_step);
        let _ = write!(svg, r#"<text x="{x}" y="96""#);
        if labels == 1 {
            let _ = writeln!(svg, ">{text}</text>");
            continue;
        }
        let (values, times) = if k == 0 {
            ("visible;hidden".to_string(), format!("0;{}", num(b, 6)))
        } else if b >= 1.0 || k + 1 == labels {
            ("hidden;visible".to_string(), format!("0;{}", num(a, 6)))
        } else {
            (
                "hidden;visible;hidden".to_string(),
                format!("0;{};{}", num(a, 6), num(b, 6)),
            )
        };
        let initial = if k == 0 { "visible" } else { "hidden" };
        let _ = writeln!(
            svg,
            r#" visibility="{initial}">{text}<animate attributeName="visibility" values="{values}" keyTimes="{times}" calcMode="discrete" dur="{dur}" repeatCount="indefinite"/></text>"#
        );
    }
    let _ = writeln!(svg, "</g>");
    let bar_width = WIDTH - x - 30.0;
    let _ = writeln!(
        svg,
        r##"<rect x="{x}" y="108" width="{bar_width}" height="8" fill="#eeeeee" stroke="#999"/><rect x="{x}" y="108" width="0" height="8" fill="#555"><animate attributeName="width" values="0;{bar_width}" dur="{dur}" repeatCount="indefinite"/></rect>"##
    );
    let _ = writeln!(
        svg,
        r##"<text x="{x}" y="136" font-size="13" fill="#555">real time, {} steps of {} s, repeating</text>"##,
        picture.steps(),
        num(picture.dt, 4)
    );

    // Live thruster outputs as bars.
    let (bar_top, bar_height, bar_w, gap) = (180.0, 100.0, 44.0, 22.0);
    let base = bar_top + bar_height;
    let _ = writeln!(
        svg,
        r#"<text x="{x}" y="{}" font-size="15">thruster outputs u0..u3</text>"#,
        bar_top - 8.0
    );
    for i in 0..4 {
        let bx = x + 10.0 + i as f64 * (bar_w + gap);
        let values = mean_outputs
            .iter()
            .map(|u| num(u[i] * bar_height, 2))
            .collect::<Vec<_>>()
            .join(";");
        let _ = writeln!(
            svg,
            r##"<rect x="{bx}" y="{bar_top}" width="{bar_w}" height="{bar_height}" fill="none" stroke="#999"/><g transform="translate(0 {base}) scale(1 -1)"><rect x="{bx}" y="0" width="{bar_w}" height="{}" fill="{}"><animate attributeName="height" values="{values}" keyTimes="{output_times}" calcMode="discrete" dur="{dur}" repeatCount="indefinite"/></rect></g><text x="{}" y="{}" font-size="14" text-anchor="middle">u{i}</text>"##,
            num(mean_outputs[0][i] * bar_height, 2),
            hex(THRUSTER_COLORS[i]),
            bx + bar_w / 2.0,
            base + 18.0
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" font-size="12" text-anchor="end">1</text>"#,
        x + 6.0,
        bar_top + 10.0
    );
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" font-size="12" text-anchor="end">0</text>"#,
        x + 6.0,
        base
    );

    // Legend entries: a symbol and a line of text each.
    let mut y = base + 52.0;
    let row = 26.0;
    let text_x = x + 40.0;
    let mut entry = |svg: &mut String, symbol: String, text: &str| {
        let _ = writeln!(
            svg,
            r#"<g transform="translate({} {})">{symbol}</g>"#,
            x + 15.0,
            y - 5.0
        );
        let _ = writeln!(
            svg,
            r#"<text x="{text_x}" y="{y}" font-size="14">{}</text>"#,
            xml_escape(text)
        );
        y += row;
    };
    entry(
        svg,
        r##"<rect x="-10" y="-9" width="20" height="18" fill="#c6efc6" stroke="#007800" stroke-width="2"/>"##.into(),
        &format!("target box (±{} m)", num(picture.box_half_width, 3)),
    );
    entry(
        svg,
        r##"<circle r="9" fill="none" stroke="#007800" stroke-width="2" stroke-dasharray="4 3"/><line x1="0" y1="0" x2="0" y2="-14" stroke="#007800" stroke-width="2" stroke-dasharray="4 3"/>"##.into(),
        &format!("target pose (heading {} rad)", num(picture.target[2], 3)),
    );
    entry(
        svg,
        r##"<line x1="-12" y1="0" x2="12" y2="0" stroke="#1f77b4" stroke-opacity="0.45" stroke-width="3"/>"##.into(),
        "path",
    );
    entry(svg, r##"<circle r="4" fill="#000"/>"##.into(), "start");
    entry(
        svg,
        r##"<circle r="9" fill="#dddddd" stroke="#333" stroke-width="2"/><line x1="0" y1="0" x2="0" y2="-13" stroke="#b00000" stroke-width="3"/>"##.into(),
        &format!("robot (radius {} m)", num(picture.hull_radius, 3)),
    );
    entry(
        svg,
        r##"<line x1="0" y1="8" x2="0" y2="-10" stroke="#b00000" stroke-width="3"/>"##.into(),
        "red line: heading (body +y, forward)",
    );
    entry(
        svg,
        r##"<polygon points="-12,-4 12,0 -12,4" fill="#ff8c00" stroke="#d62728"/>"##.into(),
        "flame: opacity = thruster output",
    );
    for i in 0..4 {
        entry(
            svg,
            format!(
                r##"<rect x="-8" y="-5" width="16" height="10" fill="{}" stroke="#333"/>"##,
                hex(THRUSTER_COLORS[i])
            ),
            THRUSTER_NAMES[i],
        );
    }
    // Scale bar: 10 cm.
    let _ = writeln!(
        svg,
        r##"<g transform="translate({x} {})"><line x1="0" y1="0" x2="{ten_cm_px}" y2="0" stroke="#000" stroke-width="3"/><line x1="0" y1="-5" x2="0" y2="5" stroke="#000"/><line x1="{ten_cm_px}" y1="-5" x2="{ten_cm_px}" y2="5" stroke="#000"/><text x="0" y="20" font-size="14">10 cm</text></g>"##,
        y + 6.0
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plots::picture::tests::{picture, spiral};

    #[test]
    fn frames_cover_the_whole_trial() {
        assert_eq!(frame_indices(1), vec![0, 1]);
        assert_eq!(frame_indices(3), vec![0, 1, 2, 3]);
        let long = frame_indices(2500);
        assert_eq!(*long.last().unwrap(), 2500);
        assert!(long.len() <= MAX_FRAMES + 1);
        assert!(long.windows(2).all(|p| p[0] < p[1]));
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(num(10.000000000000002, 3), "10");
        assert_eq!(num(0.5, 3), "0.5");
        assert_eq!(num(-0.0001, 2), "0");
        assert_eq!(num(12.0, 0), "12");
        assert_eq!(fixed(-0.0001, 1), "0.0");
        assert_eq!(fixed(0.4, 2), "0.40");
        assert_eq!(tick_step(1.0, 7.0), 0.2);
        assert_eq!(decimals_for(0.2), 1);
    }

    #[test]
    fn headings_unwrap_across_pi() {
        let (mut states, outputs) = spiral(4);
        for (s, h) in states.iter_mut().zip([3.0, 3.1, -3.1, -3.0, 3.1]) {
            s.heading = h;
        }
        let p = picture(&states, &outputs);
        let unwrapped = unwrapped_headings(&p);
        assert!(unwrapped.windows(2).all(|w| (w[1] - w[0]).abs() < 0.3), "{unwrapped:?}");
    }

    #[test]
    fn animation_is_consistent_and_small() {
        let (states, outputs) = spiral(3000);
        let p = picture(&states, &outputs);
        let svg = animation_svg(&p);
        assert!(svg.contains(r#"dur="150s""#));
        assert!(svg.len() < 2_000_000, "{} bytes", svg.len());
        // Every animation's values and keyTimes have the same length.
        for element in svg.split("<animate").skip(1) {
            let attr = |name: &str| {
                element
                    .split(&format!(" {name}=\""))
                    .nth(1)
                    .map(|rest| rest.split('"').next().unwrap().to_string())
            };
            if let (Some(values), Some(times)) = (attr("values"), attr("keyTimes")) {
                assert_eq!(values.split(';').count(), times.split(';').count(), "{element:.200}");
                assert!(times.starts_with('0'));
            }
        }
        assert!(xml_escape("a<b&c>\"'") == "a&lt;b&amp;c&gt;&quot;&apos;");
    }
}
