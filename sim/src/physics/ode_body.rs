//! One PSA body in an ODE world, as both ODE paths build and drive it: the
//! single-body [`super::OdeBackend`] and the many-body
//! [`super::OdeFleet`]. Sharing these functions is what makes the two
//! paths do the same ODE calls with the same values for every body.

use super::{
    BodyState, MassPart, MassProperties, PhysicsError, PlanarState, PlaneConstraint, RigidBodyModel, StepSettings,
};
use crate::ode::{Body, Joint, Mass, World};

/// A thruster's force at full command and its mount relative to the centre of mass.
#[derive(Debug, Clone, Copy)]
pub(super) struct MountedThruster {
    pub(super) force: [f64; 3],
    pub(super) arm: [f64; 3],
}

/// What every body of a model shares: its re-centred ODE mass, its
/// thrusters about the centre of mass, and the mass properties.
#[derive(Debug, Clone)]
pub(super) struct OdeBodyTemplate {
    mass: Mass,
    pub(super) thrusters: Vec<MountedThruster>,
    pub(super) center: [f64; 3],
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

impl OdeBodyTemplate {
    /// The template of a validated `model`.
    pub(super) fn new(model: &RigidBodyModel) -> Result<OdeBodyTemplate, PhysicsError> {
        let mut mass = composite_mass(model)?;
        let center = mass.center();
        // ODE requires the centre of mass at the body origin: shift the mass
        // by -c, and the thruster mounts with it.
        mass.translate([-center[0], -center[1], -center[2]])?;
        let thrusters = model
            .thrusters
            .iter()
            .map(|t| MountedThruster {
                force: [t.direction[0] * model.max_force, t.direction[1] * model.max_force, 0.0],
                arm: [t.mount[0] - center[0], t.mount[1] - center[1], -center[2]],
            })
            .collect::<Vec<_>>();
        // What `push` relies on to skip the wrapper's finiteness checks
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
        Ok(OdeBodyTemplate {
            mass,
            thrusters,
            center,
        })
    }

    /// A body of this template in `world`, at rest at the origin, held by
    /// a Plane2D joint if `settings` ask for one.
    pub(super) fn create(&self, world: &World, settings: &StepSettings) -> Result<(Body, Option<Joint>), PhysicsError> {
        let body = world.create_body()?;
        body.set_mass(&self.mass)?;
        body.set_gyroscopic_mode(settings.ode_gyroscopic);
        let joint = match settings.plane_constraint {
            PlaneConstraint::None => None,
            PlaneConstraint::Plane2dJoint => Some(world.create_plane2d_joint(&body)?),
        };
        Ok((body, joint))
    }

    /// The mass properties as ODE stored them in `body`.
    pub(super) fn properties(&self, body: &Body) -> MassProperties {
        let stored = body.mass();
        MassProperties {
            mass: stored.total(),
            center: self.center,
            inertia: stored.inertia(),
        }
    }

    /// Adds each thruster's force for the command `thrust` to `body`.
    ///
    /// The caller guarantees `thrust` passed
    /// [`validate_thrust`](super::validate_thrust) (one finite value in
    /// [0, 1] per thruster); with the finite forces and arms `new` checked,
    /// every value handed to ODE is finite.
    #[inline]
    pub(super) fn push(&self, body: &Body, thrust: &[f64]) {
        for (t, &u) in self.thrusters.iter().zip(thrust) {
            let force = [t.force[0] * u, t.force[1] * u, t.force[2] * u];
            body.add_rel_force_at_rel_pos_prechecked(force, t.arm);
        }
    }
}

/// Puts `body` in `state` (already validated and guard-checked).
pub(super) fn reset_body(body: &Body, state: &BodyState) -> Result<(), PhysicsError> {
    let half = 0.5 * state.heading;
    body.set_position([state.x, state.y, 0.0])?;
    body.set_quaternion([half.cos(), 0.0, 0.0, half.sin()])?;
    body.set_linear_velocity([state.vx, state.vy, 0.0])?;
    body.set_angular_velocity([0.0, 0.0, state.omega])?;
    Ok(())
}

/// The planar state of `body` as ODE keeps it.
#[inline]
pub(super) fn planar_state(body: &Body) -> PlanarState<f64> {
    let p = body.position();
    let q = body.quaternion();
    let v = body.linear_velocity();
    let w = body.angular_velocity();
    PlanarState {
        position: [p[0], p[1]],
        velocity: [v[0], v[1]],
        quaternion: [q[0], q[3]],
        omega: w[2],
    }
}

/// Removes any out-of-plane motion a Plane2D joint lets creep in: keeps
/// only the z rotation of the quaternion and of the angular velocity, and
/// z = 0, vz = 0. A no-op (bit for bit) when the body is exactly planar
/// already.
pub(super) fn project_onto_plane(body: &Body) -> Result<(), PhysicsError> {
    let q = body.quaternion();
    if q[1] != 0.0 || q[2] != 0.0 {
        let norm = q[0].hypot(q[3]);
        body.set_quaternion([q[0] / norm, 0.0, 0.0, q[3] / norm])?;
    }
    let w = body.angular_velocity();
    if w[0] != 0.0 || w[1] != 0.0 {
        body.set_angular_velocity([0.0, 0.0, w[2]])?;
    }
    let p = body.position();
    if p[2] != 0.0 {
        body.set_position([p[0], p[1], 0.0])?;
    }
    let v = body.linear_velocity();
    if v[2] != 0.0 {
        body.set_linear_velocity([v[0], v[1], 0.0])?;
    }
    Ok(())
}
