//! One control step's sensing and scoring, written once for every
//! evaluation path (the scalar trial, the batched kernel, ODE lockstep):
//! what the controller reads of a state, and the points the step that led
//! to it earns, read from the true state or the sensed one
//! ([`FitnessState`]).

use super::fitness::FitnessSettings;
use super::fitness::{FitnessState, StepError};
use super::sensors::INPUT_COUNT;
use super::sensors::{NoiseSettings, NoiseStage, SensorSettings};
use crate::numeric::{wrap_angle, Normals, Real};

/// The settings one step reads: how the sensors read and are perturbed,
/// and how the step is scored.
#[derive(Debug, Clone, Copy)]
pub struct StepSettings<'a> {
    /// Input scaling and the heading input.
    pub sensors: &'a SensorSettings,
    /// Input noise (the output noise is the caller's).
    pub noise: &'a NoiseSettings,
    /// The fitness and the state it reads.
    pub fitness: &'a FitnessSettings,
}

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
    settings: StepSettings<'_>,
    position: [R; 2],
    velocity: [R; 2],
    heading: R,
    omega: R,
    target: [R; 3],
    noise: &mut impl Normals<R>,
) -> Reading<R> {
    let heading_error = wrap_angle(heading - target[2]);
    let offset = [position[0] - target[0], position[1] - target[1]];
    let sensors = settings.sensors;
    let heading_reading = sensors.heading_reading(heading, heading_error);
    let inputs = if NOISY && settings.noise.stage == NoiseStage::Raw {
        let mut measured = SensorSettings::measured(offset, velocity, heading_reading, omega, R::splat(sensors.bias));
        settings.noise.perturb_inputs(&mut measured, noise);
        sensors.scaled(measured)
    } else {
        let mut inputs = sensors.inputs_from(offset, velocity, heading_reading, omega);
        if NOISY {
            settings.noise.perturb_inputs(&mut inputs, noise);
        }
        inputs
    };
    Reading { inputs, heading_error }
}

/// The points of a step that ended in `now` (whose true state is
/// `position`, `omega`) from `before` (whose true spin was
/// `previous_omega`), against `target`.
#[inline(always)]
pub fn score<R: Real>(
    settings: StepSettings<'_>,
    now: &Reading<R>,
    before: &Reading<R>,
    position: [R; 2],
    omega: R,
    previous_omega: R,
    target: [R; 3],
) -> R {
    let error = match settings.fitness.state {
        FitnessState::True => StepError {
            x: position[0] - target[0],
            y: position[1] - target[1],
            heading: now.heading_error,
            omega,
            previous_omega,
        },
        FitnessState::Sensed => sensed_error(settings.sensors, now, before, target[2]),
    };
    settings.fitness.points(&error)
}

/// The error the sensors read: each input divided by its scale, the
/// heading turned into an error against `target_heading` and wrapped to
/// (-pi, pi].
#[inline(always)]
fn sensed_error<R: Real>(
    sensors: &SensorSettings,
    now: &Reading<R>,
    before: &Reading<R>,
    target_heading: R,
) -> StepError<R> {
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

#[cfg(test)]
mod tests {
    use std::f64::consts::{PI, TAU};

    use super::*;
    use crate::numeric::NoiseSource;
    use crate::psa::sensors::{HeadingInput, HeadingWrap};

    /// The settings a step reads, at their defaults.
    #[derive(Default)]
    struct Settings {
        sensors: SensorSettings,
        noise: NoiseSettings,
        fitness: FitnessSettings,
    }

    impl Settings {
        fn step(&self) -> StepSettings<'_> {
            StepSettings {
                sensors: &self.sensors,
                noise: &self.noise,
                fitness: &self.fitness,
            }
        }
    }

    fn clean_reading(s: &Settings, heading: f64, target: [f64; 3]) -> Reading<f64> {
        sense::<f64, false>(
            s.step(),
            [0.01, -0.02],
            [0.1, 0.0],
            heading,
            0.5,
            target,
            &mut NoiseSource::new(0),
        )
    }

    #[test]
    fn the_heading_input_is_the_error_or_the_heading_in_its_wrap_range() {
        let mut s = Settings::default();
        s.sensors.heading_scale = 1.0;
        s.sensors.heading_wrap = HeadingWrap::Symmetric;
        s.sensors.heading_input = HeadingInput::Error;
        let target = [0.0, 0.0, 1.0];
        // The error: heading -3 against target 1 is -4, wrapped to 2 pi - 4.
        assert_eq!(clean_reading(&s, -3.0, target).inputs[4], TAU - 4.0);
        s.sensors.heading_input = HeadingInput::Absolute;
        assert_eq!(clean_reading(&s, -3.0, target).inputs[4], -3.0);
        s.sensors.heading_wrap = HeadingWrap::Positive;
        assert_eq!(clean_reading(&s, -3.0, target).inputs[4], TAU - 3.0);
        assert_eq!(clean_reading(&s, 0.5, target).inputs[4], 0.5);
        s.sensors.heading_input = HeadingInput::Error;
        // -0.5 - 1 = -1.5 lies in (-pi, 0): moved up by 2 pi.
        assert_eq!(clean_reading(&s, -0.5, target).inputs[4], TAU - 1.5);
        // The true heading error the fitness reads is the same in every case.
        assert_eq!(clean_reading(&s, -0.5, target).heading_error, -1.5);
        s.sensors.heading_scale = 2.0;
        assert_eq!(clean_reading(&s, PI, target).inputs[4], 2.0 * (PI - 1.0));
    }

    #[test]
    fn input_noise_reaches_the_bias_only_when_asked() {
        let mut s = Settings::default();
        s.noise.input_sd = 0.05;
        s.noise.on_bias = false;
        let read = |s: &Settings| {
            sense::<f64, true>(
                s.step(),
                [0.0; 2],
                [0.0; 2],
                0.0,
                0.0,
                [0.0; 3],
                &mut NoiseSource::new(7),
            )
            .inputs
        };
        let without = read(&s);
        assert_eq!(without[6], s.sensors.bias);
        s.noise.on_bias = true;
        let with = read(&s);
        assert_ne!(with[6], s.sensors.bias);
        // The other inputs draw the same numbers either way.
        assert_eq!(without[..6], with[..6]);
        assert!(without[..6].iter().all(|&v| v != 0.0));
    }

    #[test]
    fn raw_input_noise_is_added_before_scaling_and_scaled_noise_after() {
        let mut s = Settings::default();
        s.noise.input_sd = 0.05;
        s.noise.on_bias = true;
        s.sensors.heading_scale = 2.0;
        let (offset, velocity, heading, omega) = ([0.03, -0.2], [0.1, -0.05], 0.7, -1.5);
        let read = |s: &Settings| {
            sense::<f64, true>(
                s.step(),
                offset,
                velocity,
                heading,
                omega,
                [0.0; 3],
                &mut NoiseSource::new(11),
            )
            .inputs
        };
        // The normal numbers the source draws, in the inputs' order.
        let mut draws = [0.0; INPUT_COUNT];
        NoiseSource::new(11).add_scaled(&mut draws, 1.0);
        let sensors = s.sensors;
        let (p, v) = (sensors.position_scale, sensors.velocity_scale);
        let scales = [p, p, v, v, 2.0, sensors.angular_velocity_scale];
        let measured = [offset[0], offset[1], velocity[0], velocity[1], heading, omega];
        let scaled = read(&s);
        s.noise.stage = NoiseStage::Raw;
        let raw = read(&s);
        for i in 0..6 {
            assert_eq!(
                scaled[i],
                measured[i] * scales[i] + 0.05 * draws[i],
                "input {i}, scaled"
            );
            assert_eq!(raw[i], (measured[i] + 0.05 * draws[i]) * scales[i], "input {i}, raw");
        }
        // The bias measures nothing: its noise is the same at either stage.
        assert_eq!(raw[6], scaled[6]);
        assert_eq!(raw[6], s.sensors.bias + 0.05 * draws[6]);
        // Without noise the stage changes nothing.
        s.noise.input_sd = 0.0;
        let clean = read(&s);
        s.noise.stage = NoiseStage::Scaled;
        assert_eq!(read(&s), clean);
    }

    #[test]
    fn the_sensed_fitness_reads_the_inputs_over_their_scales() {
        let mut s = Settings::default();
        s.sensors.position_scale = 10.0;
        s.sensors.heading_scale = 1.0;
        s.sensors.angular_velocity_scale = 1.0;
        s.fitness.state = FitnessState::True;
        let target = [0.0, 0.0, 0.0];
        let before = clean_reading(&s, 0.0, target);
        // Truly on heading, in the box and spinning slower than before.
        let mut now = clean_reading(&s, 0.0, target);
        now.inputs[5] = 0.4;
        let truth = score(s.step(), &now, &before, [0.01, -0.02], 0.4, 0.5, target);
        assert_eq!(truth, 4.0);
        // The sensors read 0.1 rad off heading and a spin of 0.6: under
        // the true reading nothing changes.
        now.inputs[4] = 0.1;
        now.inputs[5] = 0.6;
        assert_eq!(score(s.step(), &now, &before, [0.01, -0.02], 0.4, 0.5, target), 4.0);
        s.fitness.state = FitnessState::Sensed;
        // Sensed: off heading, and the spin (0.6 against 0.5 read before) rises.
        assert_eq!(score(s.step(), &now, &before, [0.01, -0.02], 0.4, 0.5, target), 0.0);
        now.inputs[5] = 0.3;
        assert_eq!(score(s.step(), &now, &before, [0.01, -0.02], 0.4, 0.5, target), 1.0);
        // Position: 10 input units a metre, so 2.5 reads 0.25 m, out of the box.
        now.inputs[0] = 2.5;
        assert_eq!(score(s.step(), &now, &before, [0.01, -0.02], 0.4, 0.5, target), 0.0);
        // An absolute heading input is read against the target heading.
        s.sensors.heading_input = HeadingInput::Absolute;
        let target = [0.0, 0.0, 3.0];
        now.inputs[0] = 0.1;
        now.inputs[4] = 3.01;
        assert_eq!(score(s.step(), &now, &before, [0.01, -0.02], 0.4, 0.5, target), 4.0);
    }
}
