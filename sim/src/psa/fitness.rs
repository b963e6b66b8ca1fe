//! The two fitness functions (`docs/specification.md` §4), scored step by step.

use serde::{Deserialize, Serialize};

use crate::numeric::Real;

/// Which fitness function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitnessKind {
    /// Høverstad's incremental fitness: 1 point for position and spin, 3 more for heading. `[paper]` default
    Incremental,
    /// Sit's original fitness: 1 point for position and heading together.
    Original,
}

/// How the incremental fitness reads the paper's "omega_t < omega_t-1".
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SlowingRule {
    /// The spin's magnitude falls: |omega_t| < |omega_t-1|. `[chosen]`
    Magnitude,
    /// The paper's formula as printed, signed: omega_t < omega_t-1.
    Signed,
}

/// What a champion's reported score and its robustness tests are measured
/// with (Tables 1-7), separately from the fitness evolution maximises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Scoring {
    /// The evolution fitness itself.
    Evolution,
    /// Høverstad's incremental fitness, whatever evolution used.
    Incremental,
    /// Sit's original fitness, whatever evolution used. `[fitted]` default
    /// (docs/sweeps/s12-scoring-readings.md, S12; s14-s15-starts-original-scoring.md, S14, S15)
    #[default]
    Original,
}

impl Scoring {
    /// The fitness function a champion is scored with when evolution used `evolution`.
    pub fn kind(self, evolution: FitnessKind) -> FitnessKind {
        match self {
            Scoring::Evolution => evolution,
            Scoring::Incremental => FitnessKind::Incremental,
            Scoring::Original => FitnessKind::Original,
        }
    }
}

/// Which state the fitness reads: the body's true state, or what its
/// sensors read (the network's inputs, noise included, divided by their
/// scales).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum FitnessState {
    /// The true position, heading and spin (`"truth"`).
    #[serde(rename = "truth", alias = "true")]
    True,
    /// The sensed ones: under input noise the fitness sees the noise too.
    /// `[fitted]` default (docs/sweeps/s12-scoring-readings.md, sweep S12)
    #[default]
    Sensed,
}

/// The fitness function and its windows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FitnessSettings {
    /// Which function. `[paper]` incremental
    pub kind: FitnessKind,
    /// Half-width of the target box: |x|, |y| below it (m). `[paper]` 0.2
    pub box_half_width: f64,
    /// Heading window: |heading error| below it (rad). `[paper]` 0.05
    pub heading_window: f64,
    /// Spin window: |omega| below it (rad/s). `[paper]` 0.05
    pub spin_window: f64,
    /// What counts as the spin slowing down. `[chosen]` magnitude
    pub slowing: SlowingRule,
    /// Points for being in the box with the spin under control. `[paper]` 1
    pub position_points: f64,
    /// Extra points for also being on heading. `[paper]` 3
    pub heading_points: f64,
    /// What champions are scored with (Tables 1-7; per task with
    /// `problem.taskN.scoring`). `[fitted]` original
    pub scoring: Scoring,
    /// Which state the fitness reads: `truth` or `sensed`. `[fitted]` sensed
    pub state: FitnessState,
}

impl Default for FitnessSettings {
    fn default() -> Self {
        FitnessSettings {
            kind: FitnessKind::Incremental,
            box_half_width: 0.2,
            heading_window: 0.05,
            spin_window: 0.05,
            slowing: SlowingRule::Magnitude,
            position_points: 1.0,
            heading_points: 3.0,
            scoring: Scoring::Original,
            state: FitnessState::Sensed,
        }
    }
}

/// One step's error relative to the target: position (m), wrapped heading
/// error (rad), angular velocity now and one step before (rad/s). Generic
/// over [`Real`] for the batched path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepError<R = f64> {
    /// x relative to the target.
    pub x: R,
    /// y relative to the target.
    pub y: R,
    /// Heading minus target heading, wrapped to (-pi, pi].
    pub heading: R,
    /// Angular velocity at this step.
    pub omega: R,
    /// Angular velocity at the step before.
    pub previous_omega: R,
}

impl FitnessSettings {
    /// Rejects values outside their [ranges](super::settings::limits).
    pub fn validate(&self) -> Result<(), String> {
        super::settings::limits::check_all(&[
            ("fitness.box_half_width", self.box_half_width),
            ("fitness.heading_window", self.heading_window),
            ("fitness.spin_window", self.spin_window),
            ("fitness.position_points", self.position_points),
            ("fitness.heading_points", self.heading_points),
        ])
    }

    /// The points one step earns.
    #[inline(always)]
    pub fn points<R: Real>(&self, e: &StepError<R>) -> R {
        let window = R::splat(self.box_half_width);
        let in_box = e.x.abs().lt(window) & e.y.abs().lt(window);
        let on_heading = e.heading.abs().lt(R::splat(self.heading_window));
        let zero = R::splat(0.0);
        match self.kind {
            FitnessKind::Original => R::select(in_box & on_heading, R::splat(self.position_points), zero),
            FitnessKind::Incremental => {
                let spin = e.omega.abs();
                let slowing = match self.slowing {
                    SlowingRule::Magnitude => spin.lt(e.previous_omega.abs()),
                    SlowingRule::Signed => e.omega.lt(e.previous_omega),
                };
                let spin_ok = spin.lt(R::splat(self.spin_window)) | slowing;
                let earned = R::select(
                    on_heading,
                    R::splat(self.position_points + self.heading_points),
                    R::splat(self.position_points),
                );
                R::select(in_box & spin_ok, earned, zero)
            }
        }
    }

    /// The theoretical maximum over `steps` steps.
    pub fn maximum(&self, steps: usize) -> f64 {
        let per_step = match self.kind {
            FitnessKind::Original => self.position_points,
            FitnessKind::Incremental => self.position_points + self.heading_points,
        };
        per_step * steps as f64
    }
}
