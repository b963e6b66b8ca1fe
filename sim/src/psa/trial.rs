//! One trial of the control problem: a network flies the PSA for a fixed
//! number of steps and earns fitness points step by step.

use multiversion::multiversion;

use super::error::PsaError;
use super::flight::{fly_steps, Lane};
use super::sensors::INPUT_COUNT;
use super::settings::PsaSettings;
use super::task::{Target, Task};
use super::THRUSTER_COUNT;
use crate::numeric::NoiseSource;
use crate::physics::{create_backend, BodyState, PhysicsBackend};
use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::Stream;

/// Everything that happened in one trial, for replay and pictures.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrialRecord {
    /// The target.
    pub target: Target,
    /// The state at the start and after every step.
    pub states: Vec<BodyState>,
    /// The thruster commands of every step (after noise and clamping).
    pub outputs: Vec<[f64; THRUSTER_COUNT]>,
    /// The points every step earned.
    pub points: Vec<f64>,
}

/// Runs trials of one task; owns one physics world, reused between trials.
pub struct TrialRunner {
    settings: PsaSettings,
    task: Task,
    backend: Box<dyn PhysicsBackend>,
}

impl TrialRunner {
    /// A runner for `task`; fails on invalid settings or when random
    /// initialisation is asked of task 2, which has no such variant.
    pub fn new(settings: &PsaSettings, task: Task) -> Result<TrialRunner, PsaError> {
        let settings = settings.for_task(task)?;
        let model = settings.body.model()?;
        let backend = create_backend(settings.backend, &model, &settings.physics)?;
        Ok(TrialRunner {
            settings,
            task,
            backend,
        })
    }

    /// The settings this runner uses (the task's, [`PsaSettings::for_task`]).
    pub fn settings(&self) -> &PsaSettings {
        &self.settings
    }

    /// The task.
    pub fn task(&self) -> Task {
        self.task
    }

    /// The theoretical maximum of one trial, in points.
    pub fn maximum_points(&self) -> f64 {
        self.settings.fitness.maximum(self.settings.steps)
    }

    pub(crate) fn check_network(network: &Network) -> Result<(), PsaError> {
        Self::check_shape(network.inputs(), network.outputs())
    }

    /// Refuses a network shape other than the PSA's.
    pub(crate) fn check_shape(inputs: usize, outputs: usize) -> Result<(), PsaError> {
        if inputs != INPUT_COUNT || outputs != THRUSTER_COUNT {
            return Err(PsaError::Network(format!(
                "it has {inputs} inputs and {outputs} outputs, the PSA needs {INPUT_COUNT} and {THRUSTER_COUNT}"
            )));
        }
        Ok(())
    }

    /// One trial; returns its points. Draws the random start (if any), then
    /// the noise source's seed (if noise is configured), from `rng`. Fills `record` when given.
    pub fn run_trial(
        &mut self,
        network: &Network,
        rng: &mut Stream,
        mut record: Option<&mut TrialRecord>,
    ) -> Result<f64, PsaError> {
        Self::check_network(network)?;
        let s = &self.settings;
        let (start, target) = s.tasks.start_and_target(self.task, s.random_init, rng);
        self.backend.reset(&start)?;
        if let Some(r) = record.as_deref_mut() {
            *r = TrialRecord {
                target,
                states: Vec::with_capacity(s.steps + 1),
                outputs: Vec::with_capacity(s.steps),
                points: Vec::with_capacity(s.steps),
            };
            r.states.push(start);
        }
        let noise = NoiseSource::new(s.noise.draw_seed(rng));
        let mut lanes = [Lane::new(network, &target, noise, self.backend.planar_state())];
        let fly = if s.noise.is_active() { fly_noisy } else { fly_clean };
        fly(s, self.backend.as_mut(), &mut lanes, record)?;
        Ok(lanes[0].points)
    }

    /// The fitness of every trial, in % of the theoretical maximum.
    pub fn evaluate_trials(&mut self, network: &Network, rng: &mut Stream) -> Result<Vec<f64>, PsaError> {
        let maximum = self.maximum_points();
        (0..self.settings.trials)
            .map(|_| Ok(100.0 * self.run_trial(network, rng, None)? / maximum))
            .collect()
    }

    /// The network's fitness: the mean over `trials` trials, in % of the
    /// theoretical maximum.
    pub fn evaluate(&mut self, network: &Network, rng: &mut Stream) -> Result<f64, PsaError> {
        Ok(mean_of_trials(&self.evaluate_trials(network, rng)?))
    }
}

/// Declares `$name`: the steps of one trial from the backend's current
/// state ([`fly_steps`], the lockstep path's too), with noise or without;
/// the points add up in the lane, and `record` (already holding the start)
/// is filled when given.
///
/// The loop is compiled apart with and without noise, so that the noise code
/// costs noiseless trials nothing, and each of those twice, picked at run
/// time: with AVX2 and FMA instructions where the CPU has them, and for the
/// baseline, where each `mul_add` (in the network, the sigmoid and `atan2`)
/// is a call to Rust's `fma` function. Both give the same results; only the
/// speed differs.
macro_rules! trial_loop {
    ($name:ident, $noisy:expr, $avx512:tt, $avx2:tt) => {
        #[multiversion(targets($avx2))]
        fn $name<'n>(
            s: &PsaSettings,
            backend: &mut dyn PhysicsBackend,
            lanes: &mut [Lane<'n>; 1],
            record: Option<&mut TrialRecord>,
        ) -> Result<(), PsaError> {
            fly_steps::<$noisy, _>(s, backend, lanes, record)
        }
    };
}

crate::with_simd_targets!(trial_loop!(fly_clean, false,));
crate::with_simd_targets!(trial_loop!(fly_noisy, true,));

/// An evaluation's fitness from its trials' fitness values: their mean,
/// summed in trial order.
pub fn mean_of_trials(trials: &[f64]) -> f64 {
    trials.iter().sum::<f64>() / trials.len() as f64
}
