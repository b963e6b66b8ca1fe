//! The faithful default backend: one ODE body with a composite mass, one
//! body-relative force per thruster, `dWorldStep` (or QuickStep).

use std::hint::black_box;
use std::time::{Duration, Instant};

use super::{
    validate_thrust, BackendKind, BodyState, MassPart, MassProperties, PhysicsBackend, PhysicsError, PlanarState,
    PlaneConstraint, RigidBodyModel, StepGuard, StepSettings, Stepper,
};
use crate::ode::{BareOdeLoop, BareStepper, Body, Joint, Mass, World};

/// A thruster's force at full command and its mount relative to the centre of mass.
#[derive(Debug, Clone, Copy)]
struct MountedThruster {
    force: [f64; 3],
    arm: [f64; 3],
}

/// The ODE backend. Not `Send`: build one per thread.
pub struct OdeBackend {
    // Field order is drop order: joint and body before the world.
    _plane_joint: Option<Joint>,
    body: Body,
    world: World,
    thrusters: Vec<MountedThruster>,
    properties: MassProperties,
    settings: StepSettings,
    guard: StepGuard,
}

/// The composite mass of `model` built with ODE's own mass functions, before
/// re-centring: each part's mass translated to its place, then added.
fn composite_mass(model: &RigidBodyModel) -> Result<Mass, PhysicsError> {
    let mut total: Option<Mass> = None;
    for part in &model.parts {
        let (mut mass, center) = match *part {
            MassPart::Cylinder { radius, height, center } => (Mass::cylinder_z(model.density, radius, height)?, center),
            MassPart::Cuboid { size, center } => (Mass::cuboid(model.density, size)?, center),
        };
        mass.translate([center[0], center[1], 0.0])?;
        match &mut total {
            Some(sum) => sum.add(&mass),
            None => total = Some(mass),
        }
    }
    total.ok_or_else(|| PhysicsError::InvalidModel("the body has no mass parts".into()))
}

impl OdeBackend {
    /// Builds the body of `model` at rest at the origin.
    pub fn new(model: &RigidBodyModel, settings: &StepSettings) -> Result<Self, PhysicsError> {
        model.validate()?;
        settings.validate()?;
        let guard = StepGuard::new(model, settings)?;
        let world = World::new()?;
        world.set_gravity([0.0, 0.0, 0.0])?;
        world.set_quick_step_iterations(settings.quick_step_iterations)?;
        let mut mass = composite_mass(model)?;
        let center = mass.center();
        // ODE requires the centre of mass at the body origin: shift the mass
        // by -c, and the thruster mounts with it.
        mass.translate([-center[0], -center[1], -center[2]])?;
        let body = world.create_body()?;
        body.set_mass(&mass)?;
        body.set_gyroscopic_mode(settings.ode_gyroscopic);
        let stored = body.mass();
        let properties = MassProperties {
            mass: stored.total(),
            center,
            inertia: stored.inertia(),
        };
        let plane_joint = match settings.plane_constraint {
            PlaneConstraint::None => None,
            PlaneConstraint::Plane2dJoint => Some(world.create_plane2d_joint(&body)?),
        };
        let thrusters = model
            .thrusters
            .iter()
            .map(|t| MountedThruster {
                force: [t.direction[0] * model.max_force, t.direction[1] * model.max_force, 0.0],
                arm: [t.mount[0] - center[0], t.mount[1] - center[1], -center[2]],
            })
            .collect::<Vec<_>>();
        // What `step` relies on to skip the wrapper's finiteness checks
        // (already implied by a valid model, checked once to be sure).
        if let Some(i) = thrusters
            .iter()
            .position(|t| !t.force.iter().chain(&t.arm).all(|v| v.is_finite()))
        {
            return Err(PhysicsError::InvalidModel(format!(
                "thruster {i}: force {:?} or arm {:?} about the centre of mass is not finite",
                thrusters[i].force, thrusters[i].arm
            )));
        }
        Ok(OdeBackend {
            _plane_joint: plane_joint,
            body,
            world,
            thrusters,
            properties,
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
        let thrusters: Vec<_> = self.thrusters.iter().map(|t| (t.force, t.arm)).collect();
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

    /// Times our ODE path against the bare ODE calls it makes (issue 6: our
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
            validate_thrust(row, backend.thrusters.len())?;
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

    /// Removes any out-of-plane motion the Plane2D joint lets creep in:
    /// keeps only the z rotation of the quaternion and of the angular
    /// velocity, and z = 0, vz = 0. A no-op (bit for bit) when the body is
    /// exactly planar already.
    fn project_onto_plane(&self) -> Result<(), PhysicsError> {
        let q = self.body.quaternion();
        if q[1] != 0.0 || q[2] != 0.0 {
            let norm = q[0].hypot(q[3]);
            self.body.set_quaternion([q[0] / norm, 0.0, 0.0, q[3] / norm])?;
        }
        let w = self.body.angular_velocity();
        if w[0] != 0.0 || w[1] != 0.0 {
            self.body.set_angular_velocity([0.0, 0.0, w[2]])?;
        }
        let p = self.body.position();
        if p[2] != 0.0 {
            self.body.set_position([p[0], p[1], 0.0])?;
        }
        let v = self.body.linear_velocity();
        if v[2] != 0.0 {
            self.body.set_linear_velocity([v[0], v[1], 0.0])?;
        }
        Ok(())
    }
}

impl PhysicsBackend for OdeBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Ode
    }

    fn reset(&mut self, state: &BodyState) -> Result<(), PhysicsError> {
        state.validate()?;
        self.guard.check(&PlanarState::from_body_state(state))?;
        let half = 0.5 * state.heading;
        self.body.set_position([state.x, state.y, 0.0])?;
        self.body.set_quaternion([half.cos(), 0.0, 0.0, half.sin()])?;
        self.body.set_linear_velocity([state.vx, state.vy, 0.0])?;
        self.body.set_angular_velocity([0.0, 0.0, state.omega])?;
        Ok(())
    }

    fn planar_state(&self) -> PlanarState<f64> {
        let p = self.body.position();
        let q = self.body.quaternion();
        let v = self.body.linear_velocity();
        let w = self.body.angular_velocity();
        PlanarState {
            position: [p[0], p[1]],
            velocity: [v[0], v[1]],
            quaternion: [q[0], q[3]],
            omega: w[2],
        }
    }

    /// The hot path (issue 6): no allocation, and no check beyond
    /// `validate_thrust` and the [`StepGuard`]. Their guarantees (one finite
    /// value in [0, 1] per thruster; a state from which this step stays
    /// finite, far from overflowing ODE's quaternion update) and those of
    /// `new` (a validated model, so finite forces at full command and finite
    /// arms; validated settings, so dt > 0, never changed since) are what the
    /// prechecked ODE calls require, so the wrapper does not check them
    /// again.
    fn step(&mut self, thrust: &[f64]) -> Result<(), PhysicsError> {
        validate_thrust(thrust, self.thrusters.len())?;
        self.guard.check(&self.planar_state())?;
        for (t, &u) in self.thrusters.iter().zip(thrust) {
            let force = [t.force[0] * u, t.force[1] * u, t.force[2] * u];
            self.body.add_rel_force_at_rel_pos_prechecked(force, t.arm);
        }
        match self.settings.stepper {
            Stepper::Exact => self.world.step_prechecked(self.settings.dt)?,
            Stepper::Quick => self.world.quick_step_prechecked(self.settings.dt)?,
        }
        if self.settings.plane_constraint == PlaneConstraint::Plane2dJoint {
            self.project_onto_plane()?;
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
