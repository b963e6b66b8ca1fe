//! The rapier2d-f64 backend: one dynamic rigid body without colliders, its
//! mass built with parry's own `MassProperties`, one world-frame force and
//! torque per thruster, one `PhysicsPipeline` step per control step.
//!
//! Per step, as in rapier 0.36 (`staged_island_solver/worker.rs`), with
//! `s = rapier_solver_iterations` substeps of `h = dt / s` each: the
//! velocities get `h * F / m` and `h * tau / I` (the force and torque are
//! fixed for the whole step, in the world frame of its start); then the
//! position moves by `h * v` with the new velocity and the rotation, a unit
//! complex number, is multiplied by `1 + i w h` and renormalised, which
//! advances the angle by atan(w h) (`integrate_linearized`). With one
//! substep this is ODE's semi-implicit Euler except for the rotation rule:
//! atan(w dt) instead of ODE's 2 atan(w dt / 2), a difference of about
//! (w dt)^3 / 4 per step.
//!
//! Engine limits turned off because they are not physics: the per-substep
//! linear speed cap (`normalized_max_linear_velocity`, default 400 m/s) and
//! the angular speed cap of pi/4 per step (`allow_fast_rotation`; at the
//! default dt 0.05 it would clamp |w| to 15.7 rad/s). Gravity is zero,
//! damping is zero and the body never sleeps.

use rapier2d_f64::dynamics::{
    CCDSolver, ImpulseJointSet, IntegrationParameters, IslandManager, MassProperties as ParryMassProperties,
    MultibodyJointSet, RigidBodyBuilder, RigidBodyHandle, RigidBodySet, SoftBodySet,
};
use rapier2d_f64::geometry::{ColliderSet, DefaultBroadPhase, NarrowPhase};
use rapier2d_f64::math::{Pose, Real, Vector};
use rapier2d_f64::pipeline::PhysicsPipeline;

use super::{
    validate_thrust, BackendKind, BodyState, MassPart, MassProperties, PhysicsBackend, PhysicsError, PlanarState,
    RigidBodyModel, StepGuard, StepSettings,
};

/// A thruster's force at full command and its mount relative to the centre
/// of mass, both in the body frame.
#[derive(Debug, Clone, Copy)]
struct MountedThruster {
    force: Vector,
    arm: Vector,
}

/// Everything rapier needs to step a world (rapier splits its state over
/// many structs so that they can be borrowed separately).
struct World {
    pipeline: PhysicsPipeline,
    parameters: IntegrationParameters,
    islands: IslandManager,
    broad_phase: DefaultBroadPhase,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd_solver: CCDSolver,
}

impl World {
    /// Advances the world by one `parameters.dt`, without gravity.
    fn step(&mut self) {
        self.pipeline.step(
            Vector::ZERO,
            &self.parameters,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.soft_bodies,
            &mut self.ccd_solver,
            &(),
            &(),
        );
    }
}

/// The rapier2d-f64 backend.
pub struct RapierBackend {
    world: World,
    body: RigidBodyHandle,
    thrusters: Vec<MountedThruster>,
    /// The closed-form properties of the model, for the x and y rows of the
    /// inertia tensor, which a 2-D engine does not have.
    model_properties: MassProperties,
    /// The centre of mass in the body's geometric frame, as parry summed it.
    center: [f64; 2],
    guard: StepGuard,
}

/// The planar mass properties of `model` built with parry's own functions,
/// before re-centring: each part's mass translated to its place, then summed.
///
/// A planar part has the full 3-D mass of the solid (density x volume), so
/// parry's areal density is `density` times the part's height along z. A
/// cylinder about z is then a disk (mass m, inertia m r^2 / 2) and a box a
/// rectangle (mass m, inertia m (lx^2 + ly^2) / 12), exactly the z rows of
/// the solids.
fn composite_mass(model: &RigidBodyModel) -> ParryMassProperties {
    model
        .parts
        .iter()
        .map(|part| {
            let (mass, center) = match *part {
                MassPart::Cylinder { radius, height, center } => {
                    (ParryMassProperties::from_ball(model.density * height, radius), center)
                }
                MassPart::Cuboid {
                    size: [lx, ly, lz],
                    center,
                } => (
                    ParryMassProperties::from_cuboid(model.density * lz, Vector::new(0.5 * lx, 0.5 * ly)),
                    center,
                ),
            };
            mass.transform_by(&Pose::from_translation(Vector::new(center[0], center[1])))
        })
        .sum()
}

impl RapierBackend {
    /// Builds the body of `model` at rest at the origin.
    pub fn new(model: &RigidBodyModel, settings: &StepSettings) -> Result<Self, PhysicsError> {
        model.validate()?;
        settings.validate()?;
        let guard = StepGuard::new(model, settings)?;
        let composite = composite_mass(model);
        let com = composite.local_com;
        // As in the ODE backend, the body origin is the centre of mass: shift
        // the mass by -c (its local centre becomes exactly 0), and the
        // thruster mounts with it.
        let centred = composite.transform_by(&Pose::from_translation(-com));
        let rigid_body = RigidBodyBuilder::dynamic()
            .additional_mass_properties(centred)
            .linear_damping(0.0)
            .angular_damping(0.0)
            .can_sleep(false)
            .allow_fast_rotation(true)
            .build();
        let mut bodies = RigidBodySet::new();
        let body = bodies.insert(rigid_body);
        let colliders = ColliderSet::new();
        // Make the mass effective now, not at the first step, so that
        // `mass_properties` reports what the engine will use.
        bodies[body].recompute_mass_properties_from_colliders(&colliders);
        let parameters = IntegrationParameters {
            dt: settings.dt,
            num_solver_iterations: settings.rapier_solver_iterations as usize,
            normalized_max_linear_velocity: Real::MAX,
            ..IntegrationParameters::default()
        };
        let thrusters = model
            .thrusters
            .iter()
            .map(|t| MountedThruster {
                force: Vector::new(t.direction[0], t.direction[1]) * model.max_force,
                arm: Vector::new(t.mount[0] - com.x, t.mount[1] - com.y),
            })
            .collect();
        Ok(RapierBackend {
            world: World {
                pipeline: PhysicsPipeline::new(),
                parameters,
                islands: IslandManager::new(),
                broad_phase: DefaultBroadPhase::default(),
                narrow_phase: NarrowPhase::new(),
                bodies,
                colliders,
                impulse_joints: ImpulseJointSet::new(),
                multibody_joints: MultibodyJointSet::new(),
                soft_bodies: SoftBodySet::new(),
                ccd_solver: CCDSolver::new(),
            },
            body,
            thrusters,
            model_properties: model.mass_properties(),
            center: [com.x, com.y],
            guard,
        })
    }
}

impl PhysicsBackend for RapierBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Rapier
    }

    fn reset(&mut self, state: &BodyState) -> Result<(), PhysicsError> {
        state.validate()?;
        self.guard.check(&PlanarState::from_body_state(state))?;
        let body = &mut self.world.bodies[self.body];
        body.set_position(Pose::new(Vector::new(state.x, state.y), state.heading), true);
        body.set_linvel(Vector::new(state.vx, state.vy), true);
        body.set_angvel(state.omega, true);
        body.reset_forces(true);
        body.reset_torques(true);
        Ok(())
    }

    fn planar_state(&self) -> PlanarState<f64> {
        let body = &self.world.bodies[self.body];
        let p = body.translation();
        let v = body.linvel();
        let half = 0.5 * body.rotation().angle();
        PlanarState {
            position: [p.x, p.y],
            velocity: [v.x, v.y],
            quaternion: [half.cos(), half.sin()],
            omega: body.angvel(),
        }
    }

    fn step(&mut self, thrust: &[f64]) -> Result<(), PhysicsError> {
        validate_thrust(thrust, self.thrusters.len())?;
        self.guard.check(&self.planar_state())?;
        let body = &mut self.world.bodies[self.body];
        // User forces persist across steps in rapier: start from zero.
        body.reset_forces(true);
        body.reset_torques(true);
        let rotation = *body.rotation();
        for (t, &u) in self.thrusters.iter().zip(thrust) {
            let force = rotation * (t.force * u);
            let arm = rotation * t.arm;
            // The same as `add_force_at_point(force, com + arm)`, without
            // the rounding of adding and subtracting the centre of mass.
            body.add_force(force, true);
            body.add_torque(arm.perp_dot(force), true);
        }
        self.world.step();
        Ok(())
    }

    /// The mass, centre and z inertia as rapier stores them for the body
    /// (about its centre of mass). rapier 2-D has a single scalar angular
    /// inertia: `inertia[2][2]` holds it, and the x and y rows (which no
    /// planar motion uses) are copied from [`RigidBodyModel::mass_properties`].
    fn mass_properties(&self) -> MassProperties {
        let stored = &self.world.bodies[self.body].mass_properties().local_mprops;
        let mut inertia = self.model_properties.inertia;
        inertia[2][2] = stored.principal_inertia();
        MassProperties {
            mass: stored.mass(),
            center: [self.center[0], self.center[1], 0.0],
            inertia,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{wrap_angle, NativeBackend, OdeBackend, RotationRule};
    use crate::psa::BodySettings;

    fn model() -> RigidBodyModel {
        BodySettings::default().model().unwrap()
    }

    /// `steps` thrust commands, each thruster uniform in [0, 1].
    fn random_commands(seed: u64, steps: usize, thrusters: usize) -> Vec<Vec<f64>> {
        crate::physics::random_thrust_sequence(seed, 0, steps, thrusters)
    }

    /// Largest position and wrapped heading difference of two backends run
    /// from rest with the same commands, and the largest |omega| seen.
    fn max_difference(a: &mut dyn PhysicsBackend, b: &mut dyn PhysicsBackend, commands: &[Vec<f64>]) -> [f64; 3] {
        a.reset(&BodyState::default()).unwrap();
        b.reset(&BodyState::default()).unwrap();
        let mut worst = [0.0f64; 3];
        for thrust in commands {
            a.step(thrust).unwrap();
            b.step(thrust).unwrap();
            let (sa, sb) = (a.state(), b.state());
            worst[0] = worst[0].max((sa.x - sb.x).hypot(sa.y - sb.y));
            worst[1] = worst[1].max(wrap_angle(sa.heading - sb.heading).abs());
            worst[2] = worst[2].max(sa.omega.abs());
        }
        worst
    }

    fn relative(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn rapier_mass_properties_match_the_model() {
        let model = model();
        let expected = model.mass_properties();
        let native = NativeBackend::new(&model, &StepSettings::default())
            .unwrap()
            .mass_properties();
        let got = RapierBackend::new(&model, &StepSettings::default())
            .unwrap()
            .mass_properties();
        for reference in [expected, native] {
            assert!(relative(got.mass, reference.mass) <= 1e-12, "{got:?} vs {reference:?}");
            assert!(
                relative(got.inertia[2][2], reference.inertia[2][2]) <= 1e-12,
                "{got:?} vs {reference:?}"
            );
            for k in 0..3 {
                assert!(
                    (got.center[k] - reference.center[k]).abs() <= 1e-12,
                    "{got:?} vs {reference:?}"
                );
            }
        }
    }

    #[test]
    fn rapier_mass_properties_of_an_off_centre_body() {
        // A lopsided body: the centre of mass is off the origin, so the
        // parallel-axis terms matter.
        let mut model = model();
        model.parts.push(MassPart::Cuboid {
            size: [0.05, 0.03, 0.07],
            center: [0.2, -0.1],
        });
        let expected = model.mass_properties();
        let got = RapierBackend::new(&model, &StepSettings::default())
            .unwrap()
            .mass_properties();
        assert!(relative(got.mass, expected.mass) <= 1e-12, "{got:?} vs {expected:?}");
        assert!(
            relative(got.inertia[2][2], expected.inertia[2][2]) <= 1e-12,
            "{got:?} vs {expected:?}"
        );
        for k in 0..2 {
            assert!(
                relative(got.center[k], expected.center[k]) <= 1e-12,
                "{got:?} vs {expected:?}"
            );
        }
    }

    #[test]
    fn rapier_matches_native_with_the_linearized_rotation_rule() {
        let model = model();
        let settings = StepSettings::default();
        let mut rapier = RapierBackend::new(&model, &settings).unwrap();
        let mut native = NativeBackend::with_rotation_rule(&model, &settings, RotationRule::Linearized).unwrap();
        let mut worst = [0.0f64; 3];
        for seed in 0..20 {
            let commands = random_commands(seed, 500, model.thrusters.len());
            let d = max_difference(&mut rapier, &mut native, &commands);
            worst = [worst[0].max(d[0]), worst[1].max(d[1]), worst[2].max(d[2])];
        }
        assert!(worst[0] <= 1e-9, "position difference {}", worst[0]);
        assert!(worst[1] <= 1e-9, "heading difference {}", worst[1]);
    }

    #[test]
    fn rapier_constant_forward_thrust_is_pure_x_acceleration() {
        let model = model();
        let settings = StepSettings::default();
        let mut rapier = RapierBackend::new(&model, &settings).unwrap();
        let m = model.mass_properties().mass;
        let steps = 100;
        for _ in 0..steps {
            rapier.step(&[1.0, 0.0, 1.0, 0.0]).unwrap();
            let s = rapier.state();
            assert_eq!(s.omega, 0.0);
            assert_eq!(s.heading, 0.0);
            assert_eq!(s.vy, 0.0);
            assert_eq!(s.y, 0.0);
        }
        // Semi-implicit Euler: v_n = n a dt, x_n = a dt^2 n (n + 1) / 2.
        let (a, dt, n) = (2.0 * model.max_force / m, settings.dt, steps as f64);
        let s = rapier.state();
        assert!(relative(s.vx, a * dt * n) <= 1e-12, "{s:?}");
        assert!(relative(s.x, a * dt * dt * n * (n + 1.0) / 2.0) <= 1e-12, "{s:?}");
    }

    #[test]
    fn rapier_reset_restores_a_state_and_clears_forces() {
        let model = model();
        let mut rapier = RapierBackend::new(&model, &StepSettings::default()).unwrap();
        rapier.step(&[1.0, 1.0, 0.0, 0.0]).unwrap();
        let start = BodyState {
            x: 1.0,
            y: -2.0,
            heading: 3.0,
            vx: 0.5,
            vy: -0.25,
            omega: 0.75,
        };
        rapier.reset(&start).unwrap();
        let s = rapier.state();
        assert!((s.heading - start.heading).abs() <= 1e-15, "{s:?}");
        assert_eq!(
            [s.x, s.y, s.vx, s.vy, s.omega],
            [start.x, start.y, start.vx, start.vy, start.omega]
        );
        rapier.step(&[0.0; 4]).unwrap();
        let s = rapier.state();
        assert_eq!([s.vx, s.vy, s.omega], [start.vx, start.vy, start.omega]);
        assert!(rapier.step(&[0.0; 3]).is_err());
        assert!(rapier.step(&[0.0, 1.5, 0.0, 0.0]).is_err());
        assert!(rapier.step(&[f64::NAN, 0.0, 0.0, 0.0]).is_err());
        assert!(rapier
            .reset(&BodyState {
                x: f64::INFINITY,
                ..start
            })
            .is_err());
        assert_eq!(rapier.kind(), BackendKind::Rapier);
    }

    #[test]
    fn rapier_rejects_invalid_settings() {
        let model = model();
        let settings = StepSettings {
            rapier_solver_iterations: 0,
            ..StepSettings::default()
        };
        assert!(RapierBackend::new(&model, &settings).is_err());
        let bad_model = RigidBodyModel { density: -1.0, ..model };
        assert!(RapierBackend::new(&bad_model, &StepSettings::default()).is_err());
    }

    /// How much further ODE's rotation rule turns than rapier's in one step
    /// of angular velocity `omega`: 2 atan(w dt / 2) - atan(w dt), about
    /// (w dt)^3 / 4.
    fn rotation_rule_gap(omega: f64, dt: f64) -> f64 {
        let x = omega * dt;
        2.0 * (0.5 * x).atan() - x.atan()
    }

    /// rapier and ODE differ only by the rotation rule: the angular velocity
    /// agrees (the torque of body-fixed thrusters does not depend on the
    /// heading), the heading differs by the sum of the per-step gaps, and
    /// the position by at most what that heading error does to the thrust:
    /// |dv_k| <= sum_i dt |F_i| / m min(|dtheta_i|, 2), |dx_k| <= sum dt |dv|.
    #[test]
    fn rapier_differs_from_ode_only_by_the_rotation_rule() {
        let model = model();
        let settings = StepSettings::default();
        let dt = settings.dt;
        let inv_mass = 1.0 / model.mass_properties().mass;
        let mut rapier = RapierBackend::new(&model, &settings).unwrap();
        let mut ode = OdeBackend::new(&model, &settings).unwrap();
        let forces: Vec<_> = model.thrusters.iter().map(|t| t.direction).collect();
        for seed in 0..20 {
            let commands = random_commands(seed, 500, model.thrusters.len());
            rapier.reset(&BodyState::default()).unwrap();
            ode.reset(&BodyState::default()).unwrap();
            let (mut gap, mut velocity_bound, mut position_bound) = (0.0f64, 0.0f64, 0.0f64);
            for thrust in &commands {
                let (fx, fy) = forces
                    .iter()
                    .zip(thrust)
                    .fold((0.0, 0.0), |(x, y), (d, u)| (x + d[0] * u, y + d[1] * u));
                let force = fx.hypot(fy) * model.max_force;
                velocity_bound += dt * force * inv_mass * (gap.abs() + 1e-9).min(2.0);
                position_bound += dt * velocity_bound;
                rapier.step(thrust).unwrap();
                ode.step(thrust).unwrap();
                let (r, o) = (rapier.state(), ode.state());
                gap += rotation_rule_gap(o.omega, dt);
                assert!((r.omega - o.omega).abs() <= 1e-9, "seed {seed}: {r:?} vs {o:?}");
                let heading = wrap_angle(o.heading - r.heading - gap).abs();
                assert!(heading <= 1e-9, "seed {seed}: heading off the rule by {heading}");
                let velocity = (r.vx - o.vx).hypot(r.vy - o.vy);
                assert!(
                    velocity <= velocity_bound + 1e-9,
                    "seed {seed}: {velocity} > {velocity_bound}"
                );
                let position = (r.x - o.x).hypot(r.y - o.y);
                assert!(
                    position <= position_bound + 1e-9,
                    "seed {seed}: {position} > {position_bound}"
                );
            }
        }
    }
}
