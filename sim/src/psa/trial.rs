//! One trial of the control problem: a network flies the PSA for a fixed
//! number of steps and earns fitness points step by step.

use multiversion::multiversion;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::fitness::{FitnessKind, FitnessSettings, Scoring};
use super::readings::{Describe, READINGS};
use super::sensors::{NoiseSettings, SensorSettings, INPUT_COUNT};
use super::step::{score, sense};
use super::task::{Target, Task, TaskSettings};
use super::{BodySettings, THRUSTER_COUNT};
use crate::numeric::{clamp_unit, Exponential, NoiseSource};
use crate::physics::{create_backend, BackendKind, BodyState, PhysicsBackend, PhysicsError, StepSettings};
use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::Stream;

/// Errors of the PSA problem.
#[derive(Debug, Error)]
pub enum PsaError {
    /// A setting has an impossible value.
    #[error("invalid setting: {0}")]
    Setting(String),
    /// The network does not fit the PSA (7 inputs, 4 outputs).
    #[error("network does not fit the PSA: {0}")]
    Network(String),
    /// The physics layer refused or failed.
    #[error(transparent)]
    Physics(#[from] PhysicsError),
}

/// Everything that defines the PSA control problem; every `[chosen]` value of
/// the spec is one of these settings, recorded in every result file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PsaSettings {
    /// Physics backend. `[chosen]` ode
    pub backend: BackendKind,
    /// Steps per trial. `[chosen]` 500 (25 s at dt 0.05 s)
    pub steps: usize,
    /// Trials per evaluation; the fitness is their mean. `[paper]` 1, 3 under noise or random initialisation
    pub trials: usize,
    /// Random initial conditions (tasks 1 and 3). `[paper]` false
    pub random_init: bool,
    /// The polynomial of the logistic units' exponential: `fast` (relative
    /// error 2.2e-10) or `accurate` (within two ulps; the definition of
    /// builds before 2026-11-26, which repeats their results bit for bit).
    /// `[chosen]` fast
    pub exponential: Exponential,
    /// The body.
    pub body: BodySettings,
    /// The simulation.
    pub physics: StepSettings,
    /// Input scaling.
    pub sensors: SensorSettings,
    /// Input and output noise.
    pub noise: NoiseSettings,
    /// Task constants.
    pub tasks: TaskSettings,
    /// The fitness function.
    pub fitness: FitnessSettings,
    /// Task 1's own trial length, fitness and scoring, where they differ.
    #[serde(skip_serializing_if = "TaskOverrides::is_empty")]
    pub task1: TaskOverrides,
    /// Task 2's own trial length, fitness and scoring, where they differ.
    #[serde(skip_serializing_if = "TaskOverrides::is_empty")]
    pub task2: TaskOverrides,
    /// Task 3's own trial length, fitness and scoring, where they differ.
    #[serde(skip_serializing_if = "TaskOverrides::is_empty")]
    pub task3: TaskOverrides,
}

/// The settings of one task that replace the problem-wide ones
/// (`[problem.task3] steps = 2000`, `--vary problem.task3.scoring=original`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TaskOverrides {
    /// Steps per trial (else `steps`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub steps: Option<usize>,
    /// The fitness evolution maximises (else `fitness.kind`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fitness: Option<FitnessKind>,
    /// What champions are scored with (else `fitness.scoring`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scoring: Option<Scoring>,
}

impl TaskOverrides {
    /// Whether it replaces nothing.
    pub fn is_empty(&self) -> bool {
        *self == TaskOverrides::default()
    }
}

impl Default for PsaSettings {
    fn default() -> Self {
        PsaSettings {
            backend: BackendKind::Ode,
            steps: 500,
            trials: 1,
            random_init: false,
            exponential: Exponential::default(),
            body: BodySettings::default(),
            physics: StepSettings::default(),
            sensors: SensorSettings::default(),
            noise: NoiseSettings::default(),
            tasks: TaskSettings::default(),
            fitness: FitnessSettings::default(),
            task1: TaskOverrides::default(),
            task2: TaskOverrides::default(),
            task3: TaskOverrides::default(),
        }
    }
}

impl PsaSettings {
    /// Rejects values outside their [ranges](super::limits) and impossible
    /// combinations, naming the setting.
    pub fn validate(&self) -> Result<(), PsaError> {
        super::limits::check_all(&[
            ("steps", self.steps as f64),
            ("trials", self.trials as f64),
            ("physics.dt", self.physics.dt),
            (
                "physics.quick_step_iterations",
                self.physics.quick_step_iterations.into(),
            ),
            (
                "physics.rapier_solver_iterations",
                self.physics.rapier_solver_iterations.into(),
            ),
        ])
        .map_err(PsaError::Setting)?;
        for task in Task::ALL {
            if let Some(steps) = self.overrides(task).steps {
                super::limits::check_as("steps", &format!("task{task}.steps"), steps as f64)
                    .map_err(PsaError::Setting)?;
            }
        }
        self.sensors.validate().map_err(PsaError::Setting)?;
        self.noise.validate().map_err(PsaError::Setting)?;
        self.tasks.validate().map_err(PsaError::Setting)?;
        self.fitness.validate().map_err(PsaError::Setting)?;
        self.physics.validate()?;
        self.body.model()?;
        if !self.backend.is_available() {
            return Err(PhysicsError::Unavailable(self.backend).into());
        }
        Ok(())
    }

    /// As [`PsaSettings::validate`], and refuses random initialisation for
    /// task 2, which has no such variant.
    pub fn validate_for(&self, task: Task) -> Result<(), PsaError> {
        self.validate()?;
        if self.random_init && !task.has_random_init() {
            return Err(PsaError::Setting(format!(
                "task {task} has no random-initialisation variant"
            )));
        }
        Ok(())
    }

    /// The settings one control step reads ([`super::step`]).
    pub fn step(&self) -> super::step::StepSettings<'_> {
        super::step::StepSettings {
            sensors: &self.sensors,
            noise: &self.noise,
            fitness: &self.fitness,
        }
    }

    /// The overrides of `task`.
    pub fn overrides(&self, task: Task) -> &TaskOverrides {
        match task {
            Task::StopRotation => &self.task1,
            Task::Turn => &self.task2,
            Task::StopAtPosition => &self.task3,
        }
    }

    /// The settings a trial of `task` flies: checked, with the task's
    /// overrides in place of the problem-wide values (and none left).
    pub fn for_task(&self, task: Task) -> Result<PsaSettings, PsaError> {
        self.validate_for(task)?;
        // Every override by name, with no `..`: a new one is a compile
        // error here until it is resolved.
        let TaskOverrides {
            steps,
            fitness,
            scoring,
        } = *self.overrides(task);
        let mut resolved = PsaSettings {
            task1: TaskOverrides::default(),
            task2: TaskOverrides::default(),
            task3: TaskOverrides::default(),
            ..self.clone()
        };
        resolved.steps = steps.unwrap_or(self.steps);
        resolved.fitness.kind = fitness.unwrap_or(self.fitness.kind);
        resolved.fitness.scoring = scoring.unwrap_or(self.fitness.scoring);
        Ok(resolved)
    }

    /// The settings a champion of `task` is scored with (its reported
    /// fitness and robustness tests): [`PsaSettings::for_task`] with the
    /// scoring fitness as the fitness.
    pub fn scoring_for(&self, task: Task) -> Result<PsaSettings, PsaError> {
        let mut scored = self.for_task(task)?;
        scored.fitness.kind = scored.fitness.scoring.kind(scored.fitness.kind);
        scored.fitness.scoring = Scoring::Evolution;
        Ok(scored)
    }

    /// The readings of the inputs and the fitness these settings fly, in
    /// words, for reports: the lines of every row of [`READINGS`] in order
    /// (per task the fitness evolved on, the trial's length and the fitness
    /// champions are scored on under `scoring`, these settings or the ones
    /// a re-scored grid tests with; the heading input; the noise on the
    /// bias; the state the fitness reads).
    pub fn describe_readings(&self, scoring: &PsaSettings) -> Vec<String> {
        READINGS
            .iter()
            .flat_map(|row| match row.describe {
                Describe::Lines(lines) => lines(self, scoring),
                Describe::With(_) => Vec::new(),
            })
            .collect()
    }

    /// Whether a champion of `task` is scored with another fitness than it
    /// was evolved with.
    pub fn rescored(&self, task: Task) -> bool {
        let resolved_kind = self.overrides(task).fitness.unwrap_or(self.fitness.kind);
        let scoring = self.overrides(task).scoring.unwrap_or(self.fitness.scoring);
        scoring.kind(resolved_kind) != resolved_kind
    }
}

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
        let mut noise = NoiseSource::new(s.noise.draw_seed(rng));
        let fly = if s.noise.is_active() { fly_noisy } else { fly_clean };
        fly(s, self.backend.as_mut(), network, &target, &mut noise, record)
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
/// state, with noise or without ([`fly_steps`]); it returns the points and
/// fills `record` (already holding the start) when given.
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
        fn $name(
            s: &PsaSettings,
            backend: &mut dyn PhysicsBackend,
            network: &Network,
            target: &Target,
            noise: &mut NoiseSource<u64>,
            record: Option<&mut TrialRecord>,
        ) -> Result<f64, PsaError> {
            fly_steps::<$noisy>(s, backend, network, target, noise, record)
        }
    };
}

crate::with_simd_targets!(trial_loop!(fly_clean, false,));
crate::with_simd_targets!(trial_loop!(fly_noisy, true,));

/// The loop of `fly_clean` and `fly_noisy`, with noise if `NOISY`.
#[inline(always)]
fn fly_steps<const NOISY: bool>(
    s: &PsaSettings,
    backend: &mut dyn PhysicsBackend,
    network: &Network,
    target: &Target,
    noise: &mut NoiseSource<u64>,
    mut record: Option<&mut TrialRecord>,
) -> Result<f64, PsaError> {
    let mut outputs = [0.0; THRUSTER_COUNT];
    let mut state = backend.planar_state();
    let target = [target.x, target.y, target.heading];
    let read = |state: &crate::physics::PlanarState<f64>, noise: &mut NoiseSource<u64>| {
        sense::<f64, NOISY>(
            s.step(),
            state.position,
            state.velocity,
            state.heading(),
            state.omega,
            target,
            noise,
        )
    };
    let mut reading = read(&state, noise);
    let mut points = 0.0;
    for _ in 0..s.steps {
        network.activate_with(s.exponential, &reading.inputs, &mut outputs);
        if NOISY {
            s.noise.perturb_outputs(&mut outputs, noise);
        }
        for u in &mut outputs {
            *u = clamp_unit(*u);
        }
        backend.step(&outputs)?;
        let previous_omega = state.omega;
        state = backend.planar_state();
        let next = read(&state, noise);
        let step_points = score(
            s.step(),
            &next,
            &reading,
            state.position,
            state.omega,
            previous_omega,
            target,
        );
        reading = next;
        points += step_points;
        if let Some(r) = record.as_deref_mut() {
            r.states.push(state.to_body_state());
            r.outputs.push(outputs);
            r.points.push(step_points);
        }
    }
    Ok(points)
}

/// An evaluation's fitness from its trials' fitness values: their mean,
/// summed in trial order.
pub fn mean_of_trials(trials: &[f64]) -> f64 {
    trials.iter().sum::<f64>() / trials.len() as f64
}
