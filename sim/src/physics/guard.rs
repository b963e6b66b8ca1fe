//! What the engines can integrate, checked before every step of every
//! backend: ODE aborts the process when its quaternion update overflows (at
//! |omega| dt of about 1e154), and every engine turns an overflowing state
//! into inf or NaN. So each backend refuses, with the same error, a state
//! from which one more step could leave the finite numbers, and ODE is
//! never called with one.
//!
//! The envelope is far beyond anything the ranges of `psa::settings::limits` let a
//! trial reach (a test flies the most violent body they allow at full
//! thrust for the longest trial): it only stops input that was never
//! validated.

use super::{PhysicsError, PlanarState, RigidBodyModel, StepSettings};

/// The largest magnitude of every quantity one step may start from or
/// reach, in SI units: a position (m), a velocity (m/s) or an angular
/// velocity (rad/s), and what a step moves by, |v| dt (m) and |omega| dt
/// (rad). 1e100 leaves 54 orders of magnitude below ODE's overflow.
pub const ENGINE_LIMIT: f64 = 1e100;

/// The envelope check of one body: what one step at full thrust can add
/// to its velocities, and the step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepGuard {
    dt: f64,
    /// The largest change of speed one step can make (m/s).
    max_dv: f64,
    /// The largest change of angular velocity one step can make (rad/s).
    max_domega: f64,
}

impl StepGuard {
    /// The guard of `model` stepped with `settings`; fails when one step at
    /// full thrust from rest would already leave the envelope.
    pub fn new(model: &RigidBodyModel, settings: &StepSettings) -> Result<StepGuard, PhysicsError> {
        let properties = model.mass_properties();
        let [cx, cy, _] = properties.center;
        let (mut force, mut torque) = (0.0, 0.0);
        for t in &model.thrusters {
            force += model.max_force;
            torque += model.max_force * (t.mount[0] - cx).hypot(t.mount[1] - cy);
        }
        let guard = StepGuard {
            dt: settings.dt,
            max_dv: settings.dt * force / properties.mass,
            max_domega: settings.dt * torque / properties.inertia[2][2],
        };
        let at_rest = PlanarState {
            position: [0.0; 2],
            velocity: [0.0; 2],
            quaternion: [1.0, 0.0],
            omega: 0.0,
        };
        guard.check(&at_rest).map_err(|_| {
            PhysicsError::InvalidSetting(format!(
                "one step of dt = {:?} s at full thrust would change the speed by {:e} m/s and the spin by {:e} rad/s, beyond what the engines integrate (|v| dt and |omega| dt up to {ENGINE_LIMIT:e})",
                settings.dt, guard.max_dv, guard.max_domega
            ))
        })?;
        Ok(guard)
    }

    /// Refuses a state with a non-finite component, or from which one step
    /// at full thrust could leave the envelope ([`ENGINE_LIMIT`]).
    #[inline]
    pub fn check(&self, state: &PlanarState<f64>) -> Result<(), PhysicsError> {
        // Each comparison is false for NaN.
        let within = |v: f64| v <= ENGINE_LIMIT;
        let reach = |v: f64, change: f64| within(v.abs() + change) && within((v.abs() + change) * self.dt);
        if within(state.position[0].abs())
            && within(state.position[1].abs())
            && reach(state.velocity[0], self.max_dv)
            && reach(state.velocity[1], self.max_dv)
            && reach(state.omega, self.max_domega)
            && state.quaternion.iter().all(|q| q.is_finite())
        {
            Ok(())
        } else {
            Err(PhysicsError::InvalidState(format!(
                "position {:?} m, velocity {:?} m/s, angular velocity {:?} rad/s at dt = {:?} s: not finite, or beyond what the engines integrate (magnitudes and their change per step up to {ENGINE_LIMIT:e}); the step is refused",
                state.position, state.velocity, state.omega, self.dt
            )))
        }
    }
}
