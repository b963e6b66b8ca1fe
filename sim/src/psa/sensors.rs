//! What the controller sees and how its outputs reach the thrusters
//! (`docs/specification.md` §2): inputs relative to the target in the world frame,
//! scaled, with Gaussian noise on inputs and outputs.

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::task::Target;
use crate::numeric::{Normals, Real};
use crate::physics::{wrap_angle, BodyState};

/// Number of network inputs: x, y, vx, vy, the heading input, omega, bias.
pub const INPUT_COUNT: usize = 7;

/// What the heading input measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum HeadingInput {
    /// The heading minus the target heading: the default from sweep S13
    /// to S50, fitted by D but not told apart from `Absolute` beyond seed
    /// noise on seeds the fit never saw
    /// (docs/sweeps/s50-confirmation-symmetric.md).
    Error,
    /// The heading itself. `[chosen]` default, the text's reading: the
    /// paper's input is "heading" (§2).
    #[default]
    Absolute,
}

/// The range the heading input is wrapped to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum HeadingWrap {
    /// (-pi, pi]: the input is continuous where the heading crosses its
    /// target. `[chosen]` default, the simpler range: the fitted [0, 2 pi)
    /// was not told apart from it beyond seed noise on seeds the fit never
    /// saw (docs/sweeps/s49-task-settings-confirmation.md)
    #[default]
    Symmetric,
    /// [0, 2 pi): the input jumps by 2 pi where the heading crosses its
    /// target; the default from sweep S22 to S49
    /// (docs/sweeps/s16-s21-s23-heading-range.md).
    Positive,
}

impl HeadingWrap {
    /// `angle` (already wrapped to (-pi, pi]) in this range.
    #[inline(always)]
    pub fn apply<R: Real>(self, angle: R) -> R {
        match self {
            HeadingWrap::Symmetric => angle,
            HeadingWrap::Positive => R::select(angle.lt(R::splat(0.0)), angle + R::splat(std::f64::consts::TAU), angle),
        }
    }
}

/// Where the input noise enters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum NoiseStage {
    /// On the inputs as the network reads them, after scaling: an sd of
    /// 0.05 input units on every input. `[chosen]` default
    #[default]
    Scaled,
    /// On the quantities the sensors measure, before scaling: an sd of
    /// 0.05 m, m/s, rad and rad/s, which the scales then enlarge (ten-fold
    /// on positions and velocities at the default scales); the bias, which
    /// measures nothing, gets its noise (with `on_bias`) as it is.
    Raw,
}

/// Input scaling: `[chosen]` 10 per m, 10 per m/s, 1 per rad and 1 per
/// rad/s, the text's reading of §5.1's noise (sd 0.05) "about two orders
/// of magnitude less than the sensory input levels": the inputs then lie
/// about 1.5 to 4 (the box's 0.2 m, 0.4 m/s, a heading of up to pi,
/// 1.5 rad/s), 30 to 80 times the noise. D had halved them
/// (docs/sweeps/s41-s44-one-factor-and-task2-start.md); on fresh seeds the
/// halved scales were not told apart from these
/// (docs/sweeps/s52-scales-back-to-the-text.md; configs/halved-scales.toml).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorSettings {
    /// Input units per metre of position relative to the target.
    /// `[chosen]` 10, the text's reading: the input noise (sd 0.05) "about
    /// two orders of magnitude less than the sensory input levels" (§5.1).
    /// The halved scales fitted by D were not told apart from it on fresh
    /// seeds (docs/sweeps/s52-scales-back-to-the-text.md)
    pub position_scale: f64,
    /// Input units per m/s of velocity. `[chosen]` 10, as `position_scale`
    pub velocity_scale: f64,
    /// Input units per radian of the heading input. `[chosen]` 1, as
    /// `position_scale`
    pub heading_scale: f64,
    /// Input units per rad/s of angular velocity. `[chosen]` 1, as
    /// `position_scale`
    pub angular_velocity_scale: f64,
    /// The constant bias input. `[chosen]` 1
    pub bias: f64,
    /// What the heading input measures. `[chosen]` absolute, the text's
    /// reading (docs/sweeps/s51-heading-itself.md)
    pub heading_input: HeadingInput,
    /// The range the heading input is wrapped to. `[chosen]` symmetric,
    /// (-pi, pi] (docs/sweeps/s49-task-settings-confirmation.md)
    pub heading_wrap: HeadingWrap,
}

impl Default for SensorSettings {
    fn default() -> Self {
        SensorSettings {
            position_scale: 10.0,
            velocity_scale: 10.0,
            heading_scale: 1.0,
            angular_velocity_scale: 1.0,
            bias: 1.0,
            heading_input: HeadingInput::default(),
            heading_wrap: HeadingWrap::default(),
        }
    }
}

impl SensorSettings {
    /// The network inputs for `state` relative to `target`, without noise:
    /// x, y, vx, vy, the heading input, omega, bias.
    pub fn inputs(&self, state: &BodyState, target: &Target) -> [f64; INPUT_COUNT] {
        let heading_error = wrap_angle(state.heading - target.heading);
        self.inputs_from(
            [state.x - target.x, state.y - target.y],
            [state.vx, state.vy],
            self.heading_reading(state.heading, heading_error),
            state.omega,
        )
    }

    /// The heading input's angle before scaling: the wrapped heading error
    /// `heading_error` (the heading minus the target's, wrapped to (-pi,
    /// pi]) or the wrapped `heading`, in the wrap range.
    #[inline(always)]
    pub fn heading_reading<R: Real>(&self, heading: R, heading_error: R) -> R {
        let angle = match self.heading_input {
            HeadingInput::Error => heading_error,
            HeadingInput::Absolute => crate::numeric::wrap_angle(heading),
        };
        self.heading_wrap.apply(angle)
    }

    /// The inputs from the position relative to the target, the velocity,
    /// the heading reading ([`SensorSettings::heading_reading`]) and omega:
    /// the arithmetic every evaluation path shares.
    #[inline(always)]
    pub fn inputs_from<R: Real>(
        &self,
        offset: [R; 2],
        velocity: [R; 2],
        heading_reading: R,
        omega: R,
    ) -> [R; INPUT_COUNT] {
        self.scaled(Self::measured(
            offset,
            velocity,
            heading_reading,
            omega,
            R::splat(self.bias),
        ))
    }

    /// What the sensors measure, in the inputs' order, before scaling:
    /// the position relative to the target, the velocity, the heading
    /// reading, omega, and the bias as it is.
    #[inline(always)]
    pub fn measured<R: Real>(
        offset: [R; 2],
        velocity: [R; 2],
        heading_reading: R,
        omega: R,
        bias: R,
    ) -> [R; INPUT_COUNT] {
        [
            offset[0],
            offset[1],
            velocity[0],
            velocity[1],
            heading_reading,
            omega,
            bias,
        ]
    }

    /// The inputs from what the sensors measure ([`SensorSettings::measured`]):
    /// each quantity times its scale, the bias as it is.
    #[inline(always)]
    pub fn scaled<R: Real>(&self, measured: [R; INPUT_COUNT]) -> [R; INPUT_COUNT] {
        [
            measured[0] * R::splat(self.position_scale),
            measured[1] * R::splat(self.position_scale),
            measured[2] * R::splat(self.velocity_scale),
            measured[3] * R::splat(self.velocity_scale),
            measured[4] * R::splat(self.heading_scale),
            measured[5] * R::splat(self.angular_velocity_scale),
            measured[6],
        ]
    }

    /// Rejects values outside their [ranges](super::settings::limits).
    pub fn validate(&self) -> Result<(), String> {
        super::settings::limits::check_all(&[
            ("sensors.position_scale", self.position_scale),
            ("sensors.velocity_scale", self.velocity_scale),
            ("sensors.heading_scale", self.heading_scale),
            ("sensors.angular_velocity_scale", self.angular_velocity_scale),
            ("sensors.bias", self.bias),
        ])
    }
}

/// Gaussian white noise on the network's inputs (the bias too, if
/// `on_bias`) and outputs, drawn from a [`NoiseSource`](crate::numeric::NoiseSource) per trial.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseSettings {
    /// Standard deviation of the noise on every input (the bias too with
    /// `on_bias`). `[paper]` 0 (0.05 in robustness tests)
    pub input_sd: f64,
    /// Standard deviation of the noise on every output, before clamping to [0, 1]. `[paper]` 0
    pub output_sd: f64,
    /// Whether the input noise reaches the bias unit too ("added to each
    /// input neuron", §5.1; the bias is one of the "7 input units", §2).
    /// `[paper]` true
    pub on_bias: bool,
    /// Where the input noise enters: on the scaled inputs or on what the
    /// sensors measure, before scaling. `[chosen]` scaled
    pub stage: NoiseStage,
}

impl Default for NoiseSettings {
    fn default() -> Self {
        NoiseSettings {
            input_sd: 0.0,
            output_sd: 0.0,
            on_bias: true,
            stage: NoiseStage::default(),
        }
    }
}

impl NoiseSettings {
    /// Rejects deviations outside their [ranges](super::settings::limits).
    pub fn validate(&self) -> Result<(), String> {
        super::settings::limits::check_all(&[("noise.input_sd", self.input_sd), ("noise.output_sd", self.output_sd)])
    }

    /// Whether any noise is configured.
    pub fn is_active(&self) -> bool {
        self.input_sd > 0.0 || self.output_sd > 0.0
    }

    /// The seed of a trial's [`NoiseSource`](crate::numeric::NoiseSource): one word drawn from `rng` when
    /// noise is configured. Without noise nothing is drawn (the source then
    /// goes unused), so noiseless runs consume their streams as before.
    pub fn draw_seed(&self, rng: &mut impl Rng) -> u64 {
        if self.is_active() {
            rng.next_u64()
        } else {
            0
        }
    }

    /// Adds input noise to every input but the last (the bias), or to
    /// every one with `on_bias`.
    #[inline(always)]
    pub fn perturb_inputs<R: Real>(&self, inputs: &mut [R], source: &mut impl Normals<R>) {
        if self.input_sd > 0.0 {
            let n = if self.on_bias { inputs.len() } else { inputs.len() - 1 };
            source.add_scaled(&mut inputs[..n], self.input_sd);
        }
    }

    /// Adds output noise; the caller then clamps every output to [0, 1]
    /// ([`clamp_unit`](crate::numeric::clamp_unit)).
    #[inline(always)]
    pub fn perturb_outputs<R: Real>(&self, outputs: &mut [R], source: &mut impl Normals<R>) {
        if self.output_sd > 0.0 {
            source.add_scaled(outputs, self.output_sd);
        }
    }
}
