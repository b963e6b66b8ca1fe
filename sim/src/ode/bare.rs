//! The bare sequence of ODE calls of one PSA step, and nothing else: a
//! **benchmark reference only**, never used to simulate.
//!
//! Our ODE path (`OdeBackend::step` then `OdeBackend::state`) is held to
//! cost at most 10 % more than the ODE calls it makes.
//! [`BareOdeLoop::run`] is that floor: per step, one raw
//! `dBodyAddRelForceAtRelPos` per thruster, one raw `dWorldStep` (or
//! `dWorldQuickStep`), and the raw reads `dBodyGetPosition`,
//! `dBodyGetQuaternion`, `dBodyGetLinearVel` and `dBodyGetAngularVel` that
//! `state()` makes, with no validation, no error handling and no Rust-side
//! checks. Everything that could make ODE abort (non-finite forces or arms,
//! a thrust outside [0, 1], `dt <= 0`) is checked once, in
//! [`BareOdeLoop::new`], before any step.

use std::marker::PhantomData;

use super::error::{check_finite, check_positive};
use super::{Body, OdeError};

/// ODE's stepper, for [`BareOdeLoop`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BareStepper {
    /// `dWorldStep`.
    Exact,
    /// `dWorldQuickStep`.
    Quick,
}

/// The body's state as the four raw ODE reads return it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawBodyState {
    /// `dBodyGetPosition`.
    pub position: [f64; 3],
    /// `dBodyGetQuaternion` (w, x, y, z).
    pub quaternion: [f64; 4],
    /// `dBodyGetLinearVel`.
    pub linear_velocity: [f64; 3],
    /// `dBodyGetAngularVel`.
    pub angular_velocity: [f64; 3],
}

impl RawBodyState {
    /// The values a planar state is built from: x, y, qw, qz, vx, vy, omega.
    pub fn planar_values(&self) -> [f64; 7] {
        [
            self.position[0],
            self.position[1],
            self.quaternion[0],
            self.quaternion[3],
            self.linear_velocity[0],
            self.linear_velocity[1],
            self.angular_velocity[2],
        ]
    }
}

/// A validated thrust sequence driving one existing body with raw ODE calls
/// (see the module documentation). Borrows the body, so the body and its
/// world outlive it.
pub struct BareOdeLoop<'a> {
    world: ode_sys::dWorldID,
    body: ode_sys::dBodyID,
    /// Per thruster: the body-frame force at full command, and its
    /// body-frame application point.
    thrusters: Vec<([f64; 3], [f64; 3])>,
    thrust: &'a [Vec<f64>],
    dt: f64,
    stepper: BareStepper,
    _body: PhantomData<&'a Body>,
}

impl<'a> BareOdeLoop<'a> {
    /// Checks everything once: `thrusters` (per thruster the body-frame force
    /// at full command and its application point) finite, `dt` finite and
    /// positive, `thrust` non-empty with one value in [0, 1] per thruster in
    /// each row.
    pub fn new(
        body: &'a Body,
        thrusters: &[([f64; 3], [f64; 3])],
        thrust: &'a [Vec<f64>],
        dt: f64,
        stepper: BareStepper,
    ) -> Result<Self, OdeError> {
        for &(force, point) in thrusters {
            check_finite("force", force)?;
            check_finite("force application point", point)?;
        }
        check_positive("time step dt", dt)?;
        if thrust.is_empty() {
            return Err(OdeError::invalid("thrust sequence", thrust, "must not be empty"));
        }
        for row in thrust {
            if row.len() != thrusters.len() || !row.iter().all(|u| (0.0..=1.0).contains(u)) {
                return Err(OdeError::invalid(
                    "thrust command",
                    row,
                    "must hold one value in [0, 1] per thruster",
                ));
            }
        }
        Ok(BareOdeLoop {
            world: body.raw_world_id(),
            body: body.raw_id(),
            thrusters: thrusters.to_vec(),
            thrust,
            dt,
            stepper,
            _body: PhantomData,
        })
    }

    /// Runs `steps` steps from the body's current state, the commands of the
    /// thrust sequence in turn (cycling), and hands `observe` the raw state
    /// after each step. A failure code of the stepper (ODE out of memory) is
    /// ignored: the bare loop checks nothing.
    pub fn run(&self, steps: usize, observe: impl FnMut(&RawBodyState)) {
        match self.stepper {
            // SAFETY: the world is live (the borrowed body keeps it alive)
            // and dt > 0 (checked in `new`).
            BareStepper::Exact => self.run_with(steps, observe, |w, dt| unsafe { ode_sys::dWorldStep(w, dt) }),
            // SAFETY: as above.
            BareStepper::Quick => self.run_with(steps, observe, |w, dt| unsafe { ode_sys::dWorldQuickStep(w, dt) }),
        }
    }

    #[inline(always)]
    fn run_with(
        &self,
        steps: usize,
        mut observe: impl FnMut(&RawBodyState),
        step: impl Fn(ode_sys::dWorldID, f64) -> std::os::raw::c_int,
    ) {
        for row in self.thrust.iter().cycle().take(steps) {
            for (&(f, [px, py, pz]), &u) in self.thrusters.iter().zip(row) {
                // SAFETY: the body is live (borrowed for 'a); the force at
                // full command and the point are finite and u is in [0, 1]
                // (checked in `new`), so every value is finite.
                unsafe { ode_sys::dBodyAddRelForceAtRelPos(self.body, f[0] * u, f[1] * u, f[2] * u, px, py, pz) };
            }
            step(self.world, self.dt);
            // SAFETY: the body is live; ODE returns pointers to its dVector3
            // (3 dReal) and dQuaternion (4 dReal), valid until the next call
            // that changes the body, and they are read at once.
            let state = unsafe {
                let p = ode_sys::dBodyGetPosition(self.body);
                let q = ode_sys::dBodyGetQuaternion(self.body);
                let v = ode_sys::dBodyGetLinearVel(self.body);
                let w = ode_sys::dBodyGetAngularVel(self.body);
                RawBodyState {
                    position: [*p, *p.add(1), *p.add(2)],
                    quaternion: [*q, *q.add(1), *q.add(2), *q.add(3)],
                    linear_velocity: [*v, *v.add(1), *v.add(2)],
                    angular_velocity: [*w, *w.add(1), *w.add(2)],
                }
            };
            observe(&state);
        }
    }
}
