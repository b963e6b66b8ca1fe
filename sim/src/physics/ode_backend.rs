//! The faithful default backend: one ODE body with a composite mass, one
//! body-relative force per thruster, `dWorldStep` (or QuickStep).

use std::hint::black_box;
use std::time::{Duration, Instant};

use super::ode_body::{planar_state, project_onto_plane, reset_body, OdeBodyTemplate};
use super::{
    validate_thrust, BackendKind, BodyState, MassProperties, PhysicsBackend, PhysicsError, PlanarState,
    PlaneConstraint, RigidBodyModel, StepGuard, StepSettings, Stepper,
};
use crate::ode::{BareOdeLoop, BareStepper, Body, Joint, World};

/// The ODE backend. Not `Send`: build one per thread.
pub struct OdeBackend {
    // Field order is drop order: joint and body before the world.
    _plane_joint: Option<Joint>,
    body: Body,
    world: World,
    template: OdeBodyTemplate,
    properties: MassProperties,
    settings: StepSettings,
    guard: StepGuard,
}

/// A world for PSA bodies stepped with `settings` (already validated):
/// zero gravity, ODE's QuickStep iterations set.
pub(super) fn psa_world(settings: &StepSettings) -> Result<World, PhysicsError> {
    let world = World::new()?;
    world.set_gravity([0.0, 0.0, 0.0])?;
    world.set_quick_step_iterations(settings.quick_step_iterations)?;
    Ok(world)
}

/// Advances `world` by one step of `settings` (validated at construction:
/// dt > 0, never changed since).
#[inline]
pub(super) fn step_world(world: &World, settings: &StepSettings) -> Result<(), PhysicsError> {
    match settings.stepper {
        Stepper::Exact => world.step_prechecked(settings.dt)?,
        Stepper::Quick => world.quick_step_prechecked(settings.dt)?,
    }
    Ok(())
}

impl OdeBackend {
    /// Builds the body of `model` at rest at the origin.
    pub fn new(model: &RigidBodyModel, settings: &StepSettings) -> Result<Self, PhysicsError> {
        model.validate()?;
        settings.validate()?;
        let guard = StepGuard::new(model, settings)?;
        let template = OdeBodyTemplate::new(model)?;
        let world = psa_world(settings)?;
        let (body, plane_joint) = template.create(&world, settings)?;
        Ok(OdeBackend {
            _plane_joint: plane_joint,
            properties: template.properties(&body),
            body,
            world,
            template,
            settings: *settings,
            guard,
        })
    }

    /// The bare sequence of ODE calls of [`PhysicsBackend::step`] and
    /// [`PhysicsBackend::state`] on this backend's own body, driven by
    /// `thrust` (a benchmark reference: see [`BareOdeLoop`]). It starts from
    /// the body's current state and skips the plane projection of
    /// [`PlaneConstraint::Plane2dJoint`].
    pub fn bare_loop<'a>(&'a self, thrust: &'a [Vec<f64>]) -> Result<BareOdeLoop<'a>, PhysicsError> {
        let thrusters: Vec<_> = self.template.thrusters.iter().map(|t| (t.force, t.arm)).collect();
        let stepper = match self.settings.stepper {
            Stepper::Exact => BareStepper::Exact,
            Stepper::Quick => BareStepper::Quick,
        };
        Ok(BareOdeLoop::new(
            &self.body,
            &thrusters,
            thrust,
            self.settings.dt,
            stepper,
        )?)
    }

    /// Times our ODE path against the bare ODE calls it makes (our
    /// overhead must stay <= 10 %). Returns the (ours, bare) time of
    /// `steps` steps, each the minimum over `rounds` rounds (the least
    /// disturbed run on a noisy machine).
    ///
    /// Both sides run on the same body, from rest at the origin, through the
    /// commands of `thrust` in turn (cycling), and do the same per step:
    /// ours is `step` then `planar_state` through `&mut dyn PhysicsBackend`, as a
    /// PSA trial calls them; bare is [`BareOdeLoop::run`], reading the raw
    /// values `state` is built from. Each round runs both sides, alternating
    /// which goes first, so that slow phases of the machine hit both.
    pub fn overhead_sample(
        model: &RigidBodyModel,
        settings: &StepSettings,
        thrust: &[Vec<f64>],
        steps: usize,
        rounds: usize,
    ) -> Result<(Duration, Duration), PhysicsError> {
        let mut backend = OdeBackend::new(model, settings)?;
        for row in thrust {
            validate_thrust(row, backend.template.thrusters.len())?;
        }
        let start = BodyState::default();
        let mut ours = Duration::MAX;
        let mut bare = Duration::MAX;
        for round in 0..rounds.max(1) {
            for side in [round % 2, 1 - round % 2] {
                backend.reset(&start)?;
                if side == 0 {
                    let dynamic: &mut dyn PhysicsBackend = black_box(&mut backend);
                    let clock = Instant::now();
                    for row in thrust.iter().cycle().take(steps) {
                        dynamic.step(row)?;
                        black_box(dynamic.planar_state());
                    }
                    ours = ours.min(clock.elapsed());
                } else {
                    let reference = backend.bare_loop(thrust)?;
                    let clock = Instant::now();
                    reference.run(steps, |s| {
                        // The values `state` is built from.
                        black_box(s.planar_values());
                    });
                    bare = bare.min(clock.elapsed());
                }
            }
        }
        Ok((ours, bare))
    }
}

impl PhysicsBackend for OdeBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Ode
    }

    fn reset(&mut self, state: &BodyState) -> Result<(), PhysicsError> {
        state.validate()?;
        self.guard.check(&PlanarState::from_body_state(state))?;
        reset_body(&self.body, state)
    }

    fn planar_state(&self) -> PlanarState<f64> {
        planar_state(&self.body)
    }

    /// The hot path: no allocation, and no check beyond
    /// `validate_thrust` and the [`StepGuard`]. Their guarantees (one finite
    /// value in [0, 1] per thruster; a state from which this step stays
    /// finite, far from overflowing ODE's quaternion update) and those of
    /// `new` (a validated model, so finite forces at full command and finite
    /// arms; validated settings, so dt > 0, never changed since) are what the
    /// prechecked ODE calls require, so the wrapper does not check them
    /// again.
    fn step(&mut self, thrust: &[f64]) -> Result<(), PhysicsError> {
        validate_thrust(thrust, self.template.thrusters.len())?;
        self.guard.check(&self.planar_state())?;
        self.template.push(&self.body, thrust);
        step_world(&self.world, &self.settings)?;
        if self.settings.plane_constraint == PlaneConstraint::Plane2dJoint {
            project_onto_plane(&self.body)?;
        }
        Ok(())
    }

    fn mass_properties(&self) -> MassProperties {
        self.properties
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::random_thrust_sequence;
    use crate::psa::BodySettings;

    fn model() -> RigidBodyModel {
        BodySettings::default().model().expect("default body is valid")
    }

    #[test]
    fn bare_loop_and_backend_give_bit_identical_states() {
        for stepper in [Stepper::Exact, Stepper::Quick] {
            let settings = StepSettings {
                stepper,
                ..StepSettings::default()
            };
            bare_loop_matches_backend(&settings);
        }
    }

    fn bare_loop_matches_backend(settings: &StepSettings) {
        let model = model();
        let thrust = random_thrust_sequence(7, 3, 500, model.thrusters.len());
        let start = BodyState {
            x: 0.1,
            y: -0.2,
            heading: 1.0,
            vx: 0.01,
            vy: 0.02,
            omega: 0.3,
        };
        let mut ours = OdeBackend::new(&model, settings).unwrap();
        ours.reset(&start).unwrap();
        let mut expected = Vec::new();
        for row in &thrust {
            ours.step(row).unwrap();
            expected.push(ours.planar_state());
        }
        let mut reference = OdeBackend::new(&model, settings).unwrap();
        reference.reset(&start).unwrap();
        let mut raw = Vec::new();
        reference
            .bare_loop(&thrust)
            .unwrap()
            .run(thrust.len(), |s| raw.push(*s));
        assert_eq!(raw.len(), 500);
        for (i, (e, s)) in expected.iter().zip(&raw).enumerate() {
            let q = s.quaternion;
            let bare = PlanarState {
                position: [s.position[0], s.position[1]],
                velocity: [s.linear_velocity[0], s.linear_velocity[1]],
                quaternion: [q[0], q[3]],
                omega: s.angular_velocity[2],
            };
            let bits = |b: &PlanarState<f64>| {
                [b.position, b.velocity, b.quaternion, [b.omega; 2]].map(|pair| pair.map(f64::to_bits))
            };
            assert_eq!(bits(e), bits(&bare), "{:?} step {i}", settings.stepper);
            assert_eq!((s.position[2], q[1], q[2]), (0.0, 0.0, 0.0), "step {i}: left the plane");
        }
        // The bare loop moved the reference's body exactly as `step` moved ours.
        assert_eq!(ours.state(), reference.state());
    }

    #[test]
    fn bare_loop_rejects_bad_thrust() {
        let model = model();
        let backend = OdeBackend::new(&model, &StepSettings::default()).unwrap();
        for bad in [
            vec![],
            vec![vec![0.5; 3]],
            vec![vec![0.5, 0.5, f64::NAN, 0.5]],
            vec![vec![0.5, 1.5, 0.5, 0.5]],
        ] {
            assert!(backend.bare_loop(&bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn overhead_sample_times_both_sides() {
        let model = model();
        let thrust = random_thrust_sequence(1, 0, 50, model.thrusters.len());
        let (ours, bare) = OdeBackend::overhead_sample(&model, &StepSettings::default(), &thrust, 100, 2).unwrap();
        assert!(ours > Duration::ZERO && bare > Duration::ZERO);
        let bad = vec![vec![2.0; 4]];
        assert!(OdeBackend::overhead_sample(&model, &StepSettings::default(), &bad, 10, 1).is_err());
    }
}
