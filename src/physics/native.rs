//! Pure-Rust backend: the exact update ODE's `dWorldStep` performs for one
//! unconstrained body whose forces all lie in the x-y plane.
//!
//! Per step, as in ODE 0.16 (`step.cpp`, `dxStepBody`): forces are rotated
//! into the world frame with the rotation matrix of the current quaternion,
//! torques are (R p) x (R f); the velocities get `dt * F / m` and
//! `invI * (dt * tau)` (semi-implicit Euler); the position moves by
//! `dt * v` with the new velocity; the quaternion moves by `dt * dq/dt`,
//! `dq/dt = 0.5 (0, w) q`, and is renormalised, which advances the angle
//! by 2 atan(w dt / 2). The gyroscopic term w x (I w) is exactly zero for a
//! planar spin about a principal axis, as here.

use super::{
    validate_thrust, BackendKind, BodyState, MassProperties, PhysicsBackend, PhysicsError, RigidBodyModel, StepSettings,
};
use crate::numeric::{atan2, wrap_angle, Real};

/// How the heading advances in one step of angular velocity w.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RotationRule {
    /// ODE's default infinitesimal quaternion update: 2 atan(w dt / 2).
    OdeQuaternion,
    /// rapier's linearised rotation with one substep: atan(w dt).
    Linearized,
}

/// A thruster's force at full command and its mount, relative to the centre of mass.
#[derive(Debug, Clone, Copy)]
struct MountedThruster {
    force: [f64; 2],
    arm: [f64; 2],
}

/// The constants of the planar update: thrusters, inverse mass and inertia, step.
#[derive(Debug, Clone)]
pub struct PlanarBody {
    thrusters: Vec<MountedThruster>,
    inv_mass: f64,
    inv_inertia_z: f64,
    dt: f64,
}

/// The planar state as ODE keeps it: position and velocity of the centre of
/// mass, the w and z components of the orientation quaternion (x and y stay
/// exactly 0 for planar motion) and the angular velocity. Generic over
/// [`Real`] so that the batched path steps many bodies in lockstep with the
/// very same arithmetic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarState<R> {
    /// Position (m).
    pub position: [R; 2],
    /// Velocity (m/s).
    pub velocity: [R; 2],
    /// Quaternion (w, z).
    pub quaternion: [R; 2],
    /// Angular velocity about z (rad/s).
    pub omega: R,
}

impl PlanarState<f64> {
    /// The state of `state`: the quaternion of its heading, (cos h/2, sin h/2).
    pub fn from_body_state(state: &BodyState) -> Self {
        let half = 0.5 * state.heading;
        PlanarState {
            position: [state.x, state.y],
            velocity: [state.vx, state.vy],
            quaternion: [half.cos(), half.sin()],
            omega: state.omega,
        }
    }
}

impl PlanarState<f64> {
    /// The state with its heading, 2 atan2(qz, qw) wrapped to (-pi, pi].
    pub fn to_body_state(&self) -> BodyState {
        BodyState {
            x: self.position[0],
            y: self.position[1],
            heading: self.heading(),
            vx: self.velocity[0],
            vy: self.velocity[1],
            omega: self.omega,
        }
    }
}

impl<R: Real> PlanarState<R> {
    /// The heading, wrapped to (-pi, pi]: 2 atan2(qz, qw).
    #[inline(always)]
    pub fn heading(&self) -> R {
        let [qw, qz] = self.quaternion;
        wrap_angle(R::splat(2.0) * atan2(qz, qw))
    }
}

impl PlanarBody {
    /// The constants for `model` stepped with `settings`.
    pub fn new(model: &RigidBodyModel, settings: &StepSettings) -> Result<Self, PhysicsError> {
        model.validate()?;
        settings.validate()?;
        let properties = model.mass_properties();
        let c = properties.center;
        let thrusters = model
            .thrusters
            .iter()
            .map(|t| MountedThruster {
                force: [t.direction[0] * model.max_force, t.direction[1] * model.max_force],
                arm: [t.mount[0] - c[0], t.mount[1] - c[1]],
            })
            .collect();
        Ok(PlanarBody {
            thrusters,
            inv_mass: 1.0 / properties.mass,
            inv_inertia_z: 1.0 / properties.inertia[2][2],
            dt: settings.dt,
        })
    }

    /// Number of thrusters.
    pub fn thruster_count(&self) -> usize {
        self.thrusters.len()
    }

    /// The velocities after one step of `thrust` (one command per thruster,
    /// already validated): semi-implicit Euler, as ODE's `dxStepBody`.
    #[inline(always)]
    fn accelerate<R: Real>(&self, state: &mut PlanarState<R>, thrust: &[R]) {
        let [qw, qz] = state.quaternion;
        // ODE's dQtoR for q = (qw, 0, 0, qz): the top-left 2x2 block.
        let two = R::splat(2.0);
        let qq3 = two * qz * qz;
        let one_minus = R::splat(1.0) - qq3;
        let (r00, r01, r10, r11) = (one_minus, two * -(qw * qz), two * (qw * qz), one_minus);
        let zero = R::splat(0.0);
        let (mut fx, mut fy, mut tau) = (zero, zero, zero);
        for (t, &u) in self.thrusters.iter().zip(thrust) {
            let (bx, by) = (R::splat(t.force[0]) * u, R::splat(t.force[1]) * u);
            let (wfx, wfy) = (r00 * bx + r01 * by, r10 * bx + r11 * by);
            let (ax, ay) = (R::splat(t.arm[0]), R::splat(t.arm[1]));
            let (px, py) = (r00 * ax + r01 * ay, r10 * ax + r11 * ay);
            fx = fx + wfx;
            fy = fy + wfy;
            tau = tau + (px * wfy - py * wfx);
        }
        let h = R::splat(self.dt);
        let h_inv_mass = h * R::splat(self.inv_mass);
        state.velocity[0] = state.velocity[0] + h_inv_mass * fx;
        state.velocity[1] = state.velocity[1] + h_inv_mass * fy;
        state.omega = state.omega + R::splat(self.inv_inertia_z) * (tau * h);
        state.position[0] = state.position[0] + h * state.velocity[0];
        state.position[1] = state.position[1] + h * state.velocity[1];
    }

    /// One step of ODE's `dWorldStep` for this body: the velocities, the
    /// position, then the quaternion by `dt * dq/dt`, renormalised.
    #[inline(always)]
    pub fn step<R: Real>(&self, state: &mut PlanarState<R>, thrust: &[R]) {
        let [qw, qz] = state.quaternion;
        self.accelerate(state, thrust);
        let h = R::splat(self.dt);
        let half_w = R::splat(0.5) * state.omega;
        let (w, z) = (qw + h * (-half_w * qz), qz + h * (half_w * qw));
        let inv_norm = R::splat(1.0) / (w * w + z * z).sqrt();
        state.quaternion = [w * inv_norm, z * inv_norm];
    }

    /// As [`PlanarBody::step`] with rapier's linearised rotation rule.
    fn step_linearized(&self, state: &mut PlanarState<f64>, thrust: &[f64]) {
        let [qw, qz] = state.quaternion;
        self.accelerate(state, thrust);
        let angle = 2.0 * qz.atan2(qw) + (state.omega * self.dt).atan();
        state.quaternion = [(0.5 * angle).cos(), (0.5 * angle).sin()];
    }
}

/// The pure-Rust backend.
#[derive(Debug, Clone)]
pub struct NativeBackend {
    body: PlanarBody,
    properties: MassProperties,
    rule: RotationRule,
    state: PlanarState<f64>,
}

impl NativeBackend {
    /// Builds the body of `model` at rest at the origin, ODE's rotation rule.
    pub fn new(model: &RigidBodyModel, settings: &StepSettings) -> Result<Self, PhysicsError> {
        Self::with_rotation_rule(model, settings, RotationRule::OdeQuaternion)
    }

    /// As [`NativeBackend::new`] with a chosen rotation rule.
    pub fn with_rotation_rule(
        model: &RigidBodyModel,
        settings: &StepSettings,
        rule: RotationRule,
    ) -> Result<Self, PhysicsError> {
        Ok(NativeBackend {
            body: PlanarBody::new(model, settings)?,
            properties: model.mass_properties(),
            rule,
            state: PlanarState::from_body_state(&BodyState::default()),
        })
    }
}

impl PhysicsBackend for NativeBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Native
    }

    fn reset(&mut self, state: &BodyState) -> Result<(), PhysicsError> {
        state.validate()?;
        self.state = PlanarState::from_body_state(state);
        Ok(())
    }

    fn planar_state(&self) -> PlanarState<f64> {
        self.state
    }

    fn step(&mut self, thrust: &[f64]) -> Result<(), PhysicsError> {
        validate_thrust(thrust, self.body.thruster_count())?;
        match self.rule {
            RotationRule::OdeQuaternion => self.body.step(&mut self.state, thrust),
            RotationRule::Linearized => self.body.step_linearized(&mut self.state, thrust),
        }
        Ok(())
    }

    fn mass_properties(&self) -> MassProperties {
        self.properties
    }
}
