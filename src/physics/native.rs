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
    validate_thrust, wrap_angle, BackendKind, BodyState, MassProperties, PhysicsBackend, PhysicsError, RigidBodyModel,
    StepSettings,
};

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

/// The pure-Rust backend.
#[derive(Debug, Clone)]
pub struct NativeBackend {
    thrusters: Vec<MountedThruster>,
    properties: MassProperties,
    inv_mass: f64,
    inv_inertia_z: f64,
    dt: f64,
    rule: RotationRule,
    position: [f64; 2],
    velocity: [f64; 2],
    /// The w and z components of ODE's orientation quaternion
    /// (x and y stay exactly 0 for planar motion).
    quaternion: [f64; 2],
    omega: f64,
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
        Ok(NativeBackend {
            thrusters,
            inv_mass: 1.0 / properties.mass,
            inv_inertia_z: 1.0 / properties.inertia[2][2],
            properties,
            dt: settings.dt,
            rule,
            position: [0.0; 2],
            velocity: [0.0; 2],
            quaternion: [1.0, 0.0],
            omega: 0.0,
        })
    }
}

impl PhysicsBackend for NativeBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Native
    }

    fn reset(&mut self, state: &BodyState) -> Result<(), PhysicsError> {
        state.validate()?;
        self.position = [state.x, state.y];
        self.velocity = [state.vx, state.vy];
        let half = 0.5 * state.heading;
        self.quaternion = [half.cos(), half.sin()];
        self.omega = state.omega;
        Ok(())
    }

    fn state(&self) -> BodyState {
        let [qw, qz] = self.quaternion;
        BodyState {
            x: self.position[0],
            y: self.position[1],
            heading: wrap_angle(2.0 * qz.atan2(qw)),
            vx: self.velocity[0],
            vy: self.velocity[1],
            omega: self.omega,
        }
    }

    fn step(&mut self, thrust: &[f64]) -> Result<(), PhysicsError> {
        validate_thrust(thrust, self.thrusters.len())?;
        let [qw, qz] = self.quaternion;
        // ODE's dQtoR for q = (qw, 0, 0, qz): the top-left 2x2 block.
        let qq3 = 2.0 * qz * qz;
        let (r00, r01, r10, r11) = (1.0 - qq3, 2.0 * -(qw * qz), 2.0 * (qw * qz), 1.0 - qq3);
        let (mut fx, mut fy, mut tau) = (0.0, 0.0, 0.0);
        for (t, &u) in self.thrusters.iter().zip(thrust) {
            let (bx, by) = (t.force[0] * u, t.force[1] * u);
            let (wfx, wfy) = (r00 * bx + r01 * by, r10 * bx + r11 * by);
            let (px, py) = (r00 * t.arm[0] + r01 * t.arm[1], r10 * t.arm[0] + r11 * t.arm[1]);
            fx += wfx;
            fy += wfy;
            tau += px * wfy - py * wfx;
        }
        let h = self.dt;
        let h_inv_mass = h * self.inv_mass;
        self.velocity[0] += h_inv_mass * fx;
        self.velocity[1] += h_inv_mass * fy;
        self.omega += self.inv_inertia_z * (tau * h);
        self.position[0] += h * self.velocity[0];
        self.position[1] += h * self.velocity[1];
        self.quaternion = match self.rule {
            RotationRule::OdeQuaternion => {
                let half_w = 0.5 * self.omega;
                let (w, z) = (qw + h * (-half_w * qz), qz + h * (half_w * qw));
                let inv_norm = 1.0 / (w * w + z * z).sqrt();
                [w * inv_norm, z * inv_norm]
            }
            RotationRule::Linearized => {
                let angle = 2.0 * qz.atan2(qw) + (self.omega * h).atan();
                [(0.5 * angle).cos(), (0.5 * angle).sin()]
            }
        };
        Ok(())
    }

    fn mass_properties(&self) -> MassProperties {
        self.properties
    }
}
