//! The settings wing: [`PsaSettings`], everything that defines the control
//! problem, with the machinery around it: the model's readings of the
//! paper's text ([`readings`]), the range of every numeric setting
//! ([`limits`]) and the table of when each default changed ([`defaults`]).

pub mod defaults;
pub mod limits;
pub mod readings;

use serde::{Deserialize, Serialize};
use strum::VariantArray;

use super::error::PsaError;
use super::fitness::{FitnessKind, FitnessSettings, Scoring};
use super::sensors::{NoiseSettings, SensorSettings};
use super::task::{Task, TaskSettings};
use super::BodySettings;
use crate::numeric::Exponential;
use crate::physics::{BackendKind, PhysicsError, StepSettings};

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
    /// Rejects values outside their [ranges](limits) and impossible
    /// combinations, naming the setting.
    pub fn validate(&self) -> Result<(), PsaError> {
        limits::check_all(&[
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
        for &task in Task::VARIANTS {
            if let Some(steps) = self.overrides(task).steps {
                limits::check_as("steps", &format!("task{task}.steps"), steps as f64).map_err(PsaError::Setting)?;
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

    /// The settings one control step reads ([`crate::psa::step`]).
    pub fn step(&self) -> crate::psa::step::StepSettings<'_> {
        crate::psa::step::StepSettings {
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

    /// Whether a champion of `task` is scored with another fitness than it
    /// was evolved with.
    pub fn rescored(&self, task: Task) -> bool {
        let resolved_kind = self.overrides(task).fitness.unwrap_or(self.fitness.kind);
        let scoring = self.overrides(task).scoring.unwrap_or(self.fitness.scoring);
        scoring.kind(resolved_kind) != resolved_kind
    }
}
