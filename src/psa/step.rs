//! One control step's sensing and scoring, written once for every
//! evaluation path (the scalar trial, the batched kernel, ODE lockstep):
//! what the controller reads of a state, and the points the step that led
//! to it earns, read from the true state or the sensed one
//! ([`FitnessState`]).

use super::fitness::{FitnessState, StepError};
use super::sensors::INPUT_COUNT;
use super::trial::PsaSettings;
use crate::numeric::{wrap_angle, NoiseSource, Real};

/// One state as the controller reads it, and its true error against the target.
#[derive(Debug, Clone, Copy)]
pub struct Reading<R> {
    /// The network's inputs, input noise included when the step is noisy.
    pub inputs: [R; INPUT_COUNT],
    /// The true heading minus the target heading, wrapped to (-pi, pi].
    pub heading_error: R,
}

/// What the controller reads of the state `position`, `velocity`,
/// `heading`, `omega` against `target` (x, y, heading); with input noise
/// when `NOISY`.
#[inline(always)]
pub fn sense<R: Real, const NOISY: bool>(
    s: &PsaSettings,
    position: [R; 2],
    velocity: [R; 2],
    heading: R,
    omega: R,
    target: [R; 3],
    noise: &mut NoiseSource<R::Word>,
) -> Reading<R> {
    let heading_error = wrap_angle(heading - target[2]);
    let offset = [position[0] - target[0], position[1] - target[1]];
    let mut inputs = s.sensors.inputs_from(
        offset,
        velocity,
        s.sensors.heading_reading(heading, heading_error),
        omega,
    );
    if NOISY {
        s.noise.perturb_inputs(&mut inputs, noise);
    }
    Reading { inputs, heading_error }
}

/// The points of a step that ended in `now` (whose true state is
/// `position`, `omega`) from `before` (whose true spin was
/// `previous_omega`), against `target`.
#[inline(always)]
pub fn score<R: Real>(
    s: &PsaSettings,
    now: &Reading<R>,
    before: &Reading<R>,
    position: [R; 2],
    omega: R,
    previous_omega: R,
    target: [R; 3],
) -> R {
    let error = match s.fitness.state {
        FitnessState::True => StepError {
            x: position[0] - target[0],
            y: position[1] - target[1],
            heading: now.heading_error,
            omega,
            previous_omega,
        },
        FitnessState::Sensed => sensed_error(s, now, before, target[2]),
    };
    s.fitness.points(&error)
}

/// The error the sensors read: each input divided by its scale, the
/// heading turned into an error against `target_heading` and wrapped to
/// (-pi, pi].
#[inline(always)]
fn sensed_error<R: Real>(s: &PsaSettings, now: &Reading<R>, before: &Reading<R>, target_heading: R) -> StepError<R> {
    let sensors = &s.sensors;
    let heading = now.inputs[4] / R::splat(sensors.heading_scale);
    let heading = match sensors.heading_input {
        super::sensors::HeadingInput::Error => wrap_angle(heading),
        super::sensors::HeadingInput::Absolute => wrap_angle(heading - target_heading),
    };
    let spin = |r: &Reading<R>| r.inputs[5] / R::splat(sensors.angular_velocity_scale);
    StepError {
        x: now.inputs[0] / R::splat(sensors.position_scale),
        y: now.inputs[1] / R::splat(sensors.position_scale),
        heading,
        omega: spin(now),
        previous_omega: spin(before),
    }
}
