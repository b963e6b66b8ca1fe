//! Many PSA bodies in one ODE world, stepped in lockstep: the fast way to
//! fly a batch of networks on ODE.
//!
//! The bodies share no joint and no collision geometry, so each is an
//! island of its own, and ODE's `dWorldStep` (or `dWorldQuickStep`) steps
//! the islands one by one, each from its own body's state and forces only.
//! The world's settings that could couple them are left at ODE's defaults,
//! which switch them off: auto-disable (off), damping (zero), the angular
//! speed limit (none), gravity (zero, set). A Plane2D joint ties its body to
//! the static environment, not to another body, so it starts no shared
//! island. One `dWorldStep` over many bodies costs much less per body than
//! one per world: its fixed cost is paid once.
//!
//! The bodies are built, reset, pushed and read by the same functions as
//! [`OdeBackend`](super::OdeBackend)'s single body ([`super::ode_body`]),
//! and [`StepGuard`] checks every body's state before every step, so ODE
//! is never called with a state it could abort on. A test holds every body
//! of a fleet to the single-body backend, bit for bit.

use super::ode_backend::{psa_world, step_world};
use super::ode_body::{planar_state, project_onto_plane, reset_body, OdeBodyTemplate};
use super::{
    validate_thrust, BodyState, MassProperties, PhysicsError, PlanarState, PlaneConstraint, RigidBodyModel, StepGuard,
    StepSettings, Stepper,
};
use crate::ode::{Body, Joint, World};

/// The most bodies one fleet may hold.
pub const MAX_FLEET: usize = 4096;

/// Bodies of one model in one ODE world, stepped together. Not `Send`:
/// build one per thread.
pub struct OdeFleet {
    // Field order is drop order: joints and bodies before the world.
    joints: Vec<Joint>,
    bodies: Vec<Body>,
    world: World,
    template: OdeBodyTemplate,
    properties: MassProperties,
    settings: StepSettings,
    guard: StepGuard,
}

impl OdeFleet {
    /// Whether a fleet steps every body exactly as its own world would.
    /// QuickStep with a Plane2D joint reorders the joint's rows with ODE's
    /// one process-wide random number generator, whose draws then depend on
    /// how many islands were stepped before: that combination is refused.
    pub fn supports(settings: &StepSettings) -> bool {
        !(settings.stepper == Stepper::Quick && settings.plane_constraint == PlaneConstraint::Plane2dJoint)
    }

    /// A fleet of `bodies` bodies of `model`, each at rest at the origin.
    pub fn new(model: &RigidBodyModel, settings: &StepSettings, bodies: usize) -> Result<OdeFleet, PhysicsError> {
        model.validate()?;
        settings.validate()?;
        if !Self::supports(settings) {
            return Err(PhysicsError::InvalidSetting(
                "a fleet of ODE bodies cannot use QuickStep with a Plane2D joint (its constraint order is drawn from ODE's shared random generator); use one world per body".into(),
            ));
        }
        let guard = StepGuard::new(model, settings)?;
        let template = OdeBodyTemplate::new(model)?;
        let world = psa_world(settings)?;
        let (body, joint) = template.create(&world, settings)?;
        let properties = template.properties(&body);
        let mut fleet = OdeFleet {
            joints: joint.into_iter().collect(),
            bodies: vec![body],
            world,
            template,
            properties,
            settings: *settings,
            guard,
        };
        fleet.resize(bodies)?;
        Ok(fleet)
    }

    /// The number of bodies.
    pub fn len(&self) -> usize {
        self.bodies.len()
    }

    /// Whether the fleet has no body.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }

    /// Adds or removes bodies until there are `bodies` (1 to [`MAX_FLEET`]);
    /// new ones start at rest at the origin.
    pub fn resize(&mut self, bodies: usize) -> Result<(), PhysicsError> {
        if !(1..=MAX_FLEET).contains(&bodies) {
            return Err(PhysicsError::InvalidSetting(format!(
                "a fleet holds 1 to {MAX_FLEET} bodies, not {bodies}"
            )));
        }
        while self.bodies.len() > bodies {
            // A joint before its body.
            self.joints.truncate(self.bodies.len() - 1);
            self.bodies.pop();
        }
        while self.bodies.len() < bodies {
            let (body, joint) = self.template.create(&self.world, &self.settings)?;
            self.bodies.push(body);
            self.joints.extend(joint);
        }
        Ok(())
    }

    /// Mass properties as ODE computed them (every body has the same).
    pub fn mass_properties(&self) -> MassProperties {
        self.properties
    }

    /// Puts body `i` in `state`, as [`PhysicsBackend::reset`](super::PhysicsBackend::reset).
    ///
    /// # Panics
    /// If there is no body `i`.
    pub fn reset(&mut self, i: usize, state: &BodyState) -> Result<(), PhysicsError> {
        state.validate()?;
        self.guard.check(&PlanarState::from_body_state(state))?;
        reset_body(&self.bodies[i], state)
    }

    /// Body `i`'s state as ODE keeps it.
    ///
    /// # Panics
    /// If there is no body `i`.
    #[inline]
    pub fn planar_state(&self, i: usize) -> PlanarState<f64> {
        planar_state(&self.bodies[i])
    }

    /// Advances every body one time step, body `i` with the thruster
    /// commands `thrust[i]` (each in [0, 1]), as
    /// [`PhysicsBackend::step`](super::PhysicsBackend::step) advances one.
    /// Every command and every body's state is checked before any force is
    /// added, so a refused step changes nothing; the error names the body.
    pub fn step<T: AsRef<[f64]>>(&mut self, thrust: &[T]) -> Result<(), PhysicsError> {
        if thrust.len() != self.bodies.len() {
            return Err(PhysicsError::InvalidThrust(format!(
                "expected {} commands (one per body), got {}",
                self.bodies.len(),
                thrust.len()
            )));
        }
        let thrusters = self.template.thrusters.len();
        for (i, (body, command)) in self.bodies.iter().zip(thrust).enumerate() {
            let named = |e: PhysicsError| body_error(i, e);
            validate_thrust(command.as_ref(), thrusters).map_err(named)?;
            self.guard.check(&planar_state(body)).map_err(named)?;
        }
        for (body, command) in self.bodies.iter().zip(thrust) {
            self.template.push(body, command.as_ref());
        }
        step_world(&self.world, &self.settings)?;
        if self.settings.plane_constraint == PlaneConstraint::Plane2dJoint {
            for body in &self.bodies {
                project_onto_plane(body)?;
            }
        }
        Ok(())
    }
}

/// `error` with the body it concerns named.
fn body_error(i: usize, error: PhysicsError) -> PhysicsError {
    match error {
        PhysicsError::InvalidThrust(m) => PhysicsError::InvalidThrust(format!("body {i}: {m}")),
        PhysicsError::InvalidState(m) => PhysicsError::InvalidState(format!("body {i}: {m}")),
        other => other,
    }
}
