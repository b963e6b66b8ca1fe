//! One recorded trial as the pictures see it ([`TrialPicture`]), and what
//! the static figure ([`super::trial`]) and the animation
//! (`animation.rs`) share: the thrusters' names and colours, and the
//! equal-aspect view of the x-y plane.

use anyhow::{bail, ensure};
use plotters::style::RGBColor;

use psa_sim::physics::{wrap_angle, BodyState};

/// Legend text of each thruster, in thruster order.
pub const THRUSTER_NAMES: [&str; 4] = [
    "thruster 0 (+x, anticlockwise)",
    "thruster 1 (+y, anticlockwise)",
    "thruster 2 (+x, clockwise)",
    "thruster 3 (+y, clockwise)",
];

/// Line colour of each thruster, in thruster order (the static figure and
/// the animation's legend use the same colours).
pub const THRUSTER_COLORS: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
];

/// Everything needed to draw one trial.
#[derive(Debug, Clone)]
pub struct TrialPicture<'a> {
    /// Title on top of the pictures, e.g. "task 1, ode backend, fitness 63.2 %".
    pub title: String,
    /// Seconds per step.
    pub dt: f64,
    /// `states[0]` is the start, then one state per step (SI units; heading in
    /// rad, anticlockwise, 0 = initial orientation).
    pub states: &'a [BodyState],
    /// Thruster commands u0..u3 in [0, 1], one per step (`states.len() - 1` of them).
    pub outputs: &'a [[f64; 4]],
    /// Target x, y (m) and heading (rad).
    pub target: [f64; 3],
    /// The target box is |x - tx| < w, |y - ty| < w (m).
    pub box_half_width: f64,
    /// |heading error| below this (rad) counts as "on heading".
    pub heading_window: f64,
    /// Robot radius (m) for the animation.
    pub hull_radius: f64,
}

impl TrialPicture<'_> {
    /// Number of steps (one fewer than the number of states).
    pub fn steps(&self) -> usize {
        self.states.len().saturating_sub(1)
    }

    /// Trial duration in seconds: steps x dt.
    pub fn duration(&self) -> f64 {
        self.steps() as f64 * self.dt
    }

    /// Heading error of a state: heading minus target heading, wrapped to (-pi, pi].
    pub fn heading_error(&self, state: &BodyState) -> f64 {
        wrap_angle(state.heading - self.target[2])
    }

    /// Whether a state lies inside the target box.
    pub fn in_box(&self, state: &BodyState) -> bool {
        (state.x - self.target[0]).abs() < self.box_half_width && (state.y - self.target[1]).abs() < self.box_half_width
    }

    /// Checks that the picture can be drawn: at least one step, one output per
    /// step, finite values and positive sizes.
    pub fn validate(&self) -> anyhow::Result<()> {
        ensure!(
            self.states.len() >= 2,
            "a trial picture needs at least one step, got {} states",
            self.states.len()
        );
        ensure!(
            self.outputs.len() == self.steps(),
            "a trial of {} steps needs {} thruster outputs, got {}",
            self.steps(),
            self.steps(),
            self.outputs.len()
        );
        ensure!(
            self.dt.is_finite() && self.dt > 0.0,
            "dt must be positive, got {}",
            self.dt
        );
        ensure!(
            self.hull_radius.is_finite() && self.hull_radius > 0.0,
            "hull_radius must be positive, got {}",
            self.hull_radius
        );
        ensure!(
            self.box_half_width.is_finite() && self.box_half_width >= 0.0,
            "box_half_width must be non-negative, got {}",
            self.box_half_width
        );
        ensure!(
            self.heading_window.is_finite() && self.heading_window >= 0.0,
            "heading_window must be non-negative, got {}",
            self.heading_window
        );
        ensure!(
            self.target.iter().all(|v| v.is_finite()),
            "the target must be finite, got {:?}",
            self.target
        );
        for (step, state) in self.states.iter().enumerate() {
            let values = [state.x, state.y, state.heading, state.vx, state.vy, state.omega];
            if !values.iter().all(|v| v.is_finite()) {
                bail!("state {step} is not finite: {state:?}");
            }
        }
        for (step, output) in self.outputs.iter().enumerate() {
            if !output.iter().all(|v| v.is_finite()) {
                bail!("thruster output {step} is not finite: {output:?}");
            }
        }
        Ok(())
    }

    /// The smallest x-y rectangle ([x0, x1], [y0, y1]) holding the path and the target box.
    pub(crate) fn world_bounds(&self) -> ([f64; 2], [f64; 2]) {
        let (tx, ty, w) = (self.target[0], self.target[1], self.box_half_width);
        let mut xs = [tx - w, tx + w];
        let mut ys = [ty - w, ty + w];
        for s in self.states {
            xs = [xs[0].min(s.x), xs[1].max(s.x)];
            ys = [ys[0].min(s.y), ys[1].max(s.y)];
        }
        (xs, ys)
    }
}

/// Widens the shorter of two ranges about its centre so that one metre takes
/// the same number of pixels on both axes.
pub fn equal_aspect(xs: [f64; 2], ys: [f64; 2], pixels: (u32, u32)) -> ([f64; 2], [f64; 2]) {
    let (px, py) = (f64::from(pixels.0.max(1)), f64::from(pixels.1.max(1)));
    let (wx, wy) = (xs[1] - xs[0], ys[1] - ys[0]);
    let metres_per_pixel = (wx / px).max(wy / py);
    let (cx, cy) = ((xs[0] + xs[1]) / 2.0, (ys[0] + ys[1]) / 2.0);
    let (hx, hy) = (metres_per_pixel * px / 2.0, metres_per_pixel * py / 2.0);
    ([cx - hx, cx + hx], [cy - hy, cy + hy])
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A synthetic trial: `steps` steps spiralling into the target (0, 0.4)
    /// while turning to heading pi, with varying outputs.
    pub(crate) fn spiral(steps: usize) -> (Vec<BodyState>, Vec<[f64; 4]>) {
        let target = (0.0, 0.4);
        let states = (0..=steps)
            .map(|k| {
                let f = k as f64 / steps.max(1) as f64;
                let radius = 0.6 * (1.0 - f).powi(2);
                let angle = 5.0 * std::f64::consts::PI * f;
                BodyState {
                    x: target.0 + radius * angle.cos(),
                    y: target.1 + radius * angle.sin(),
                    heading: wrap_angle(std::f64::consts::PI * f.sqrt()),
                    vx: -radius * angle.sin(),
                    vy: radius * angle.cos(),
                    omega: (1.0 - f) * (3.0 * angle).cos(),
                }
            })
            .collect::<Vec<_>>();
        let outputs = (0..steps)
            .map(|k| {
                let t = k as f64 * 0.05;
                [
                    0.5 + 0.5 * (0.7 * t).sin(),
                    if (k / 20) % 2 == 0 { 1.0 } else { 0.0 },
                    (0.3 * t).cos().abs(),
                    (k as f64 / steps as f64).clamp(0.0, 1.0),
                ]
            })
            .collect::<Vec<_>>();
        (states, outputs)
    }

    pub(crate) fn picture<'a>(states: &'a [BodyState], outputs: &'a [[f64; 4]]) -> TrialPicture<'a> {
        TrialPicture {
            title: "task 3, synthetic spiral, fitness 42.0 % <&>".to_string(),
            dt: 0.05,
            states,
            outputs,
            target: [0.0, 0.4, std::f64::consts::PI],
            box_half_width: 0.2,
            heading_window: 0.05,
            hull_radius: 0.10,
        }
    }

    #[test]
    fn equal_aspect_keeps_metres_square() {
        let (xs, ys) = equal_aspect([0.0, 1.0], [0.0, 0.2], (400, 400));
        assert!(((xs[1] - xs[0]) - (ys[1] - ys[0])).abs() < 1e-12);
        assert!((ys[0] + ys[1] - 0.2).abs() < 1e-12, "centred");
        let (xs, ys) = equal_aspect([0.0, 1.0], [0.0, 1.0], (800, 400));
        assert!(((xs[1] - xs[0]) / 800.0 - (ys[1] - ys[0]) / 400.0).abs() < 1e-12);
        assert!(xs[1] - xs[0] >= 1.0 && ys[1] - ys[0] >= 1.0);
    }
}
