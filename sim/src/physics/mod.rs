//! Physics backends behind one trait: `ode` (the faithful default), `native`
//! (pure Rust, ODE's `dWorldStep` rule for this body) and `rapier`
//! (rapier2d-f64). Each simulates a [`RigidBodyModel`] in the x-y plane.

mod crosscheck;
mod guard;
mod model;
mod native;
mod ode_backend;
mod ode_body;
mod ode_fleet;
#[cfg(feature = "rapier")]
mod rapier_backend;

use serde::{Deserialize, Serialize};
use strum::VariantArray;
use thiserror::Error;

pub use crosscheck::{
    crosscheck, for_each_state, random_thrust_sequence, tolerance, trajectory, BackendComparison, CrosscheckReport,
    Deviation, Tolerance,
};
pub use guard::{StepGuard, ENGINE_LIMIT};
pub use model::{MassPart, MassProperties, RigidBodyModel, Thruster};
pub use native::{NativeBackend, PlanarBody, PlanarState, RotationRule, StepConstants, ThrusterConstants};
pub use ode_backend::OdeBackend;
pub use ode_fleet::{OdeFleet, MAX_FLEET};
#[cfg(feature = "rapier")]
pub use rapier_backend::RapierBackend;

use crate::named::Named;
use crate::ode::OdeError;

/// Errors of the physics layer.
#[derive(Debug, Error)]
pub enum PhysicsError {
    /// The body model has an impossible value.
    #[error("invalid body model: {0}")]
    InvalidModel(String),
    /// A simulation setting has an impossible value.
    #[error("invalid physics setting: {0}")]
    InvalidSetting(String),
    /// A thrust command outside [0, 1], NaN, or of the wrong length.
    #[error("invalid thrust command: {0}")]
    InvalidThrust(String),
    /// A state with a non-finite component.
    #[error("invalid body state: {0}")]
    InvalidState(String),
    /// The requested backend was not compiled in.
    #[error("backend {0} is not available in this build (enable its cargo feature)")]
    Unavailable(BackendKind),
    /// ODE refused an argument or failed.
    #[error(transparent)]
    Ode(#[from] OdeError),
}

/// The planar state of the body: the centre of mass' position and velocity,
/// the heading (rotation about z, anticlockwise, wrapped to (-pi, pi]) and
/// the angular velocity.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct BodyState {
    /// x position (m).
    pub x: f64,
    /// y position (m).
    pub y: f64,
    /// Heading (rad), wrapped to (-pi, pi].
    pub heading: f64,
    /// x velocity (m/s).
    pub vx: f64,
    /// y velocity (m/s).
    pub vy: f64,
    /// Angular velocity about z (rad/s, anticlockwise positive).
    pub omega: f64,
}

impl BodyState {
    /// Checks that every component is finite.
    pub fn validate(&self) -> Result<(), PhysicsError> {
        let values = [self.x, self.y, self.heading, self.vx, self.vy, self.omega];
        if values.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(PhysicsError::InvalidState(format!(
                "every component must be finite, got {self:?}"
            )))
        }
    }
}

/// Wraps an angle to (-pi, pi] (exactly as `angle % TAU` and one correction).
pub fn wrap_angle(angle: f64) -> f64 {
    crate::numeric::wrap_angle(angle)
}

/// ODE's stepper (read and written by name: [`Named`]).
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Serialize,
    Deserialize,
    strum::VariantArray,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum Stepper {
    /// `dWorldStep`, the exact (direct LCP) stepper. `[chosen, spec]`
    Exact,
    /// `dWorldQuickStep`, the iterative stepper.
    Quick,
}

/// How the ODE body is held in the plane (read and written by name:
/// [`Named`]).
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Serialize,
    Deserialize,
    strum::VariantArray,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum PlaneConstraint {
    /// No joint: exact for this body, whose forces and thrusters all lie in
    /// the mid-plane, and about twice as fast. Default: the test
    /// `plane2d_joint_and_no_joint_give_identical_trajectories` shows both
    /// give identical trajectories.
    None,
    /// A Plane2D joint; any out-of-plane rotation is projected away each step.
    Plane2dJoint,
}

/// Simulation settings shared by every backend (`[chosen]` values, spec §1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StepSettings {
    /// Physics (and control) time step (s). `[chosen]` 0.05
    pub dt: f64,
    /// ODE stepper. `[chosen]` exact
    pub stepper: Stepper,
    /// Iterations of ODE's QuickStep, when selected. `[chosen]` 20
    pub quick_step_iterations: u32,
    /// How ODE keeps the body in the plane. `[chosen]` none (see [`PlaneConstraint`])
    pub plane_constraint: PlaneConstraint,
    /// ODE's gyroscopic term. For a planar spin about a principal axis, as
    /// here, w x (I w) is exactly zero, and the explicit form of the ODE the
    /// paper used added exactly nothing; ODE 0.16's implicit form still
    /// rounds omega by an ulp now and then, enough to trip the fitness'
    /// "spin is slowing" test. Off reproduces the exact planar motion.
    /// `[chosen]` false
    pub ode_gyroscopic: bool,
    /// Solver iterations (substeps) of rapier's integrator. `[chosen]` 1
    pub rapier_solver_iterations: u32,
    /// How `native` (and the batched and cuda paths on its physics) turns a
    /// start heading into its quaternion. `[chosen]` normalised, as ODE
    /// does (see [`StartQuaternion`])
    pub start_quaternion: StartQuaternion,
}

/// How a start heading h becomes the quaternion (cos h/2, 0, 0, sin h/2)
/// of a backend that keeps its own state. ODE's `dBodySetQuaternion`
/// always scales the quaternion it is given to unit length; for about a
/// fifth of headings drawn at random that moves the last bit, and from
/// there some trajectories part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StartQuaternion {
    /// Scaled by 1 / sqrt(w w + z z) as ODE does: `native` starts where
    /// `ode` does, bit for bit. Default.
    Normalised,
    /// (cos h/2, sin h/2) as computed: the `native` starts of builds before
    /// 2026-11-26, which part from `ode`'s on some random starts.
    Raw,
}

impl Default for StepSettings {
    fn default() -> Self {
        StepSettings {
            dt: 0.05,
            stepper: Stepper::Exact,
            quick_step_iterations: 20,
            plane_constraint: PlaneConstraint::None,
            ode_gyroscopic: false,
            rapier_solver_iterations: 1,
            start_quaternion: StartQuaternion::Normalised,
        }
    }
}

impl StepSettings {
    /// Rejects values no backend can run with.
    pub fn validate(&self) -> Result<(), PhysicsError> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(PhysicsError::InvalidSetting(format!(
                "time step dt must be finite and > 0, got {}",
                self.dt
            )));
        }
        if self.quick_step_iterations == 0 {
            return Err(PhysicsError::InvalidSetting(
                "quick_step_iterations must be >= 1, got 0".into(),
            ));
        }
        if self.rapier_solver_iterations == 0 {
            return Err(PhysicsError::InvalidSetting(
                "rapier_solver_iterations must be >= 1, got 0".into(),
            ));
        }
        Ok(())
    }
}

/// Which physics engine simulates the body.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    strum::VariantArray,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum BackendKind {
    /// The Open Dynamics Engine through `ode-sys` (the faithful default).
    Ode,
    /// Pure Rust, the same integrator as ODE's `dWorldStep` for this body.
    Native,
    /// rapier2d-f64.
    Rapier,
}

impl BackendKind {
    /// Whether this build includes the backend.
    pub fn is_available(self) -> bool {
        self != BackendKind::Rapier || cfg!(feature = "rapier")
    }

    /// The backends this build includes.
    pub fn available() -> Vec<BackendKind> {
        Self::VARIANTS.iter().copied().filter(|k| k.is_available()).collect()
    }
}

impl Named for BackendKind {
    const WHAT: &'static str = "backend";
}

impl Named for Stepper {
    const WHAT: &'static str = "stepper";
}

impl Named for PlaneConstraint {
    const WHAT: &'static str = "plane constraint";
}

/// One simulated body: reset it to a state, push it, read its state back.
pub trait PhysicsBackend {
    /// Which engine this is.
    fn kind(&self) -> BackendKind;
    /// Puts the body in `state` (forgetting any pending force).
    fn reset(&mut self, state: &BodyState) -> Result<(), PhysicsError>;
    /// The current state as the engine keeps it (quaternion, no heading
    /// angle): what a controller step reads.
    fn planar_state(&self) -> PlanarState<f64>;
    /// The current state, its heading computed from the quaternion.
    fn state(&self) -> BodyState {
        self.planar_state().to_body_state()
    }
    /// Advances one time step with thruster commands `thrust` (one per
    /// thruster, each in [0, 1]; thruster i pushes with `thrust[i] * max_force`).
    fn step(&mut self, thrust: &[f64]) -> Result<(), PhysicsError>;
    /// Mass properties as this engine computed them.
    fn mass_properties(&self) -> MassProperties;
}

/// Checks a thrust command: one value per thruster, each finite in [0, 1].
pub fn validate_thrust(thrust: &[f64], thrusters: usize) -> Result<(), PhysicsError> {
    if thrust.len() != thrusters {
        return Err(PhysicsError::InvalidThrust(format!(
            "expected {thrusters} values (one per thruster), got {}",
            thrust.len()
        )));
    }
    for (i, &u) in thrust.iter().enumerate() {
        if !(0.0..=1.0).contains(&u) {
            return Err(PhysicsError::InvalidThrust(format!(
                "thruster {i}: {u} is not a number in [0, 1]"
            )));
        }
    }
    Ok(())
}

/// Builds a backend of the given kind for `model`.
pub fn create_backend(
    kind: BackendKind,
    model: &RigidBodyModel,
    settings: &StepSettings,
) -> Result<Box<dyn PhysicsBackend>, PhysicsError> {
    Ok(match kind {
        BackendKind::Ode => Box::new(OdeBackend::new(model, settings)?),
        BackendKind::Native => Box::new(NativeBackend::new(model, settings)?),
        #[cfg(feature = "rapier")]
        BackendKind::Rapier => Box::new(RapierBackend::new(model, settings)?),
        #[cfg(not(feature = "rapier"))]
        BackendKind::Rapier => return Err(PhysicsError::Unavailable(kind)),
    })
}
