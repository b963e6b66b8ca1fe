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
    validate_thrust, BackendKind, BodyState, MassProperties, PhysicsBackend, PhysicsError, RigidBodyModel,
    StartQuaternion, StepGuard, StepSettings,
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
    /// Which components of `force` are non-zero.
    force_support: Support,
    /// Which components of `arm` are non-zero.
    arm_support: Support,
}

/// Which components of a constant body-frame vector are non-zero. Rotating
/// it skips the products with its zero components: such a product is a
/// signed zero, which leaves every sum it joins unchanged but for the sign
/// of a zero sum, and the step's sums of forces and torques start at +0, to
/// which adding a zero of either sign gives +0 again. So the step's
/// velocities and positions are the same, bit for bit, with or without
/// those products, and skipping them spares the axis-aligned thrusters of
/// the PSA almost half of their arithmetic.
///
/// A zero vector (a force that underflowed, a mount at the centre of mass)
/// keeps both products, so that a NaN command always turns the force, and
/// with it the velocity, NaN: callers may find NaN thrust from the state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Support {
    /// Only x is non-zero.
    X,
    /// Only y is non-zero.
    Y,
    /// Both components are kept.
    Both,
}

/// What [`PlanarBody::step`] computes with: see [`PlanarBody::constants`].
#[derive(Debug, Clone, PartialEq)]
pub struct StepConstants {
    /// The thrusters, in command order.
    pub thrusters: Vec<ThrusterConstants>,
    /// 1 / mass (1/kg).
    pub inv_mass: f64,
    /// 1 / the moment of inertia about z (1/(kg m^2)).
    pub inv_inertia_z: f64,
    /// The step (s).
    pub dt: f64,
}

/// One thruster of [`StepConstants`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThrusterConstants {
    /// Body-frame force at full command (N).
    pub force: [f64; 2],
    /// Mount relative to the centre of mass (m).
    pub arm: [f64; 2],
    /// Which components of `force` the rotation multiplies: 0 x only, 1 y
    /// only, 2 both (a step skips the products with a zero component).
    pub force_support: i32,
    /// The same for `arm`.
    pub arm_support: i32,
}

impl Support {
    /// The code of [`ThrusterConstants`]: 0 x, 1 y, 2 both.
    fn code(self) -> i32 {
        match self {
            Support::X => 0,
            Support::Y => 1,
            Support::Both => 2,
        }
    }

    fn of(v: [f64; 2]) -> Support {
        match (v[0] != 0.0, v[1] != 0.0) {
            (true, false) => Support::X,
            (false, true) => Support::Y,
            _ => Support::Both,
        }
    }

    /// The rotation `r` (row-major 2x2) of the vector (`x()`, `y()`) that
    /// has this support; only the components it needs are computed.
    #[inline(always)]
    fn rotate<R: Real>(self, r: [[R; 2]; 2], x: impl Fn() -> R, y: impl Fn() -> R) -> [R; 2] {
        match self {
            Support::X => {
                let x = x();
                [r[0][0] * x, r[1][0] * x]
            }
            Support::Y => {
                let y = y();
                [r[0][1] * y, r[1][1] * y]
            }
            Support::Both => {
                let (x, y) = (x(), y());
                [r[0][0] * x + r[0][1] * y, r[1][0] * x + r[1][1] * y]
            }
        }
    }
}

/// The constants of the planar update: thrusters, inverse mass and inertia, step.
#[derive(Debug, Clone)]
pub struct PlanarBody {
    thrusters: Vec<MountedThruster>,
    inv_mass: f64,
    inv_inertia_z: f64,
    dt: f64,
    start_quaternion: StartQuaternion,
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
    /// The state of `state` as ODE sets it: the quaternion of its heading,
    /// (cos h/2, sin h/2), scaled to unit length as `dBodySetQuaternion`
    /// scales it.
    pub fn from_body_state(state: &BodyState) -> Self {
        Self::start(state, StartQuaternion::Normalised)
    }

    /// The state of `state` with its heading's quaternion made by `rule`.
    pub fn start(state: &BodyState, rule: StartQuaternion) -> Self {
        let half = 0.5 * state.heading;
        let (w, z) = (half.cos(), half.sin());
        let quaternion = match rule {
            // dxSafeNormalize4: the squares summed in order (x and y are 0),
            // one division of 1 by the square root, four products.
            StartQuaternion::Normalised => {
                let scale = 1.0 / (w * w + z * z).sqrt();
                [w * scale, z * scale]
            }
            StartQuaternion::Raw => [w, z],
        };
        PlanarState {
            position: [state.x, state.y],
            velocity: [state.vx, state.vy],
            quaternion,
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
            .map(|t| {
                let force = [t.direction[0] * model.max_force, t.direction[1] * model.max_force];
                let arm = [t.mount[0] - c[0], t.mount[1] - c[1]];
                MountedThruster {
                    force,
                    arm,
                    force_support: Support::of(force),
                    arm_support: Support::of(arm),
                }
            })
            .collect();
        Ok(PlanarBody {
            thrusters,
            inv_mass: 1.0 / properties.mass,
            inv_inertia_z: 1.0 / properties.inertia[2][2],
            dt: settings.dt,
            start_quaternion: settings.start_quaternion,
        })
    }

    /// The state a trial from `state` starts in, its quaternion made as the
    /// settings say ([`StartQuaternion`]).
    pub fn start_state(&self, state: &BodyState) -> PlanarState<f64> {
        PlanarState::start(state, self.start_quaternion)
    }

    /// Number of thrusters.
    pub fn thruster_count(&self) -> usize {
        self.thrusters.len()
    }

    /// The constants [`PlanarBody::step`] uses, for a kernel that repeats
    /// it elsewhere (the `cuda` path's `trial.cu`).
    pub fn constants(&self) -> StepConstants {
        StepConstants {
            thrusters: self
                .thrusters
                .iter()
                .map(|t| ThrusterConstants {
                    force: t.force,
                    arm: t.arm,
                    force_support: t.force_support.code(),
                    arm_support: t.arm_support.code(),
                })
                .collect(),
            inv_mass: self.inv_mass,
            inv_inertia_z: self.inv_inertia_z,
            dt: self.dt,
        }
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
        let rotation = [[one_minus, two * -(qw * qz)], [two * (qw * qz), one_minus]];
        let zero = R::splat(0.0);
        let (mut fx, mut fy, mut tau) = (zero, zero, zero);
        for (t, &u) in self.thrusters.iter().zip(thrust) {
            // World-frame force and lever arm: R (f u) and R p.
            let [wfx, wfy] = t
                .force_support
                .rotate(rotation, || R::splat(t.force[0]) * u, || R::splat(t.force[1]) * u);
            let [px, py] = t
                .arm_support
                .rotate(rotation, || R::splat(t.arm[0]), || R::splat(t.arm[1]));
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
    guard: StepGuard,
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
            guard: StepGuard::new(model, settings)?,
        })
    }
}

impl PhysicsBackend for NativeBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Native
    }

    fn reset(&mut self, state: &BodyState) -> Result<(), PhysicsError> {
        state.validate()?;
        let state = self.body.start_state(state);
        self.guard.check(&state)?;
        self.state = state;
        Ok(())
    }

    fn planar_state(&self) -> PlanarState<f64> {
        self.state
    }

    fn step(&mut self, thrust: &[f64]) -> Result<(), PhysicsError> {
        validate_thrust(thrust, self.body.thruster_count())?;
        self.guard.check(&self.state)?;
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

#[cfg(test)]
mod tests {
    use super::super::crosscheck::random_thrust_sequence;
    use super::*;

    /// A hull with the PSA's four axis-aligned thrusters, a diagonal one and
    /// one pushing through the centre of mass (a zero arm): every kind of support.
    fn model() -> RigidBodyModel {
        let thruster = |mount, direction| super::super::Thruster { mount, direction };
        let diagonal = std::f64::consts::FRAC_1_SQRT_2;
        RigidBodyModel {
            density: 1000.0,
            parts: vec![super::super::MassPart::Cylinder {
                radius: 0.1,
                height: 0.1,
                center: [0.0, 0.0],
            }],
            thrusters: vec![
                thruster([0.0, -0.12], [1.0, 0.0]),
                thruster([0.12, 0.0], [0.0, 1.0]),
                thruster([0.0, 0.12], [1.0, 0.0]),
                thruster([-0.12, 0.0], [0.0, 1.0]),
                thruster([0.05, 0.07], [diagonal, -diagonal]),
                thruster([0.0, 0.0], [0.0, -1.0]),
            ],
            max_force: 1.0,
        }
    }

    #[test]
    fn skipping_the_zero_components_changes_no_bit_of_the_state() {
        let model = model();
        let skipping = PlanarBody::new(&model, &StepSettings::default()).unwrap();
        let supports: Vec<_> = skipping
            .thrusters
            .iter()
            .map(|t| (t.force_support, t.arm_support))
            .collect();
        assert_eq!(supports[0], (Support::X, Support::Y));
        assert_eq!(supports[1], (Support::Y, Support::X));
        assert_eq!(supports[4], (Support::Both, Support::Both));
        assert_eq!(supports[5], (Support::Y, Support::Both));
        let mut full = skipping.clone();
        for t in &mut full.thrusters {
            (t.force_support, t.arm_support) = (Support::Both, Support::Both);
        }
        // Starts at rest with a heading of 0 (a rotation with zero entries)
        // and with signed zeros, commands with exact zeros: the cases where
        // a skipped product could have decided the sign of a sum.
        let starts = [
            BodyState::default(),
            BodyState {
                vx: -0.0,
                vy: -0.0,
                omega: -0.0,
                ..BodyState::default()
            },
            BodyState {
                heading: 2.5,
                omega: 0.7,
                vx: 0.1,
                ..BodyState::default()
            },
        ];
        for (index, start) in starts.iter().enumerate() {
            let mut commands = random_thrust_sequence(5, index as u64, 400, model.thrusters.len());
            for (step, command) in commands.iter_mut().enumerate() {
                for (i, u) in command.iter_mut().enumerate() {
                    if (step + i) % 3 != 0 {
                        *u = 0.0;
                    }
                }
            }
            commands[..20].iter_mut().for_each(|c| c.fill(0.0));
            let (mut a, mut b) = (PlanarState::from_body_state(start), PlanarState::from_body_state(start));
            for command in &commands {
                skipping.step(&mut a, command);
                full.step(&mut b, command);
                let bits = |s: &PlanarState<f64>| {
                    [s.position, s.velocity, s.quaternion, [s.omega, 0.0]].map(|v| v.map(f64::to_bits))
                };
                assert_eq!(bits(&a), bits(&b), "start {index}");
            }
            assert!(a.omega.abs() > 0.01 && a.velocity[0] != 0.0, "the body moved: {a:?}");
        }
    }
}
