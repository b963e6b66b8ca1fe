//! The two fitness functions (`psa-model.md` §4), scored step by step.

use serde::{Deserialize, Serialize};

/// Which fitness function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitnessKind {
    /// Høverstad's incremental fitness: 1 point for position and spin, 3 more for heading. [paper] default
    Incremental,
    /// Sit's original fitness: 1 point for position and heading together.
    Original,
}

/// The fitness function and its windows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FitnessSettings {
    /// Which function. [paper] incremental
    pub kind: FitnessKind,
    /// Half-width of the target box: |x|, |y| below it (m). [paper] 0.2
    pub box_half_width: f64,
    /// Heading window: |heading error| below it (rad). [paper] 0.05
    pub heading_window: f64,
    /// Spin window: |omega| below it (rad/s). [paper] 0.05
    pub spin_window: f64,
    /// Points for being in the box with the spin under control. [paper] 1
    pub position_points: f64,
    /// Extra points for also being on heading. [paper] 3
    pub heading_points: f64,
}

impl Default for FitnessSettings {
    fn default() -> Self {
        FitnessSettings {
            kind: FitnessKind::Incremental,
            box_half_width: 0.2,
            heading_window: 0.05,
            spin_window: 0.05,
            position_points: 1.0,
            heading_points: 3.0,
        }
    }
}

/// One step's error relative to the target: position (m), wrapped heading
/// error (rad), angular velocity now and one step before (rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepError {
    /// x relative to the target.
    pub x: f64,
    /// y relative to the target.
    pub y: f64,
    /// Heading minus target heading, wrapped to (-pi, pi].
    pub heading: f64,
    /// Angular velocity at this step.
    pub omega: f64,
    /// Angular velocity at the step before.
    pub previous_omega: f64,
}

impl FitnessSettings {
    /// Rejects non-finite or negative values.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("box_half_width", self.box_half_width),
            ("heading_window", self.heading_window),
            ("spin_window", self.spin_window),
            ("position_points", self.position_points),
            ("heading_points", self.heading_points),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("fitness.{name} must be finite and >= 0, got {v}"));
            }
        }
        Ok(())
    }

    /// The points one step earns.
    pub fn points(&self, e: &StepError) -> f64 {
        let in_box = e.x.abs() < self.box_half_width && e.y.abs() < self.box_half_width;
        let on_heading = e.heading.abs() < self.heading_window;
        match self.kind {
            FitnessKind::Original => {
                if in_box && on_heading {
                    self.position_points
                } else {
                    0.0
                }
            }
            FitnessKind::Incremental => {
                // [chosen] reading of the paper's "omega_t < omega_t-1": the spin's magnitude falls.
                let spin_ok = e.omega.abs() < self.spin_window || e.omega.abs() < e.previous_omega.abs();
                match (in_box && spin_ok, on_heading) {
                    (true, true) => self.position_points + self.heading_points,
                    (true, false) => self.position_points,
                    (false, _) => 0.0,
                }
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
