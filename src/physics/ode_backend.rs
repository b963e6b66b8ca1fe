//! The faithful default backend: one ODE body with a composite mass, one
//! body-relative force per thruster, `dWorldStep` (or QuickStep).

use super::{
    validate_thrust, wrap_angle, BackendKind, BodyState, MassPart, MassProperties, PhysicsBackend, PhysicsError,
    PlaneConstraint, RigidBodyModel, StepSettings, Stepper,
};
use crate::ode::{Body, Joint, Mass, World};

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
            .collect();
        Ok(OdeBackend {
            _plane_joint: plane_joint,
            body,
            world,
            thrusters,
            properties,
            settings: *settings,
        })
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
        let half = 0.5 * state.heading;
        self.body.set_position([state.x, state.y, 0.0])?;
        self.body.set_quaternion([half.cos(), 0.0, 0.0, half.sin()])?;
        self.body.set_linear_velocity([state.vx, state.vy, 0.0])?;
        self.body.set_angular_velocity([0.0, 0.0, state.omega])?;
        Ok(())
    }

    fn state(&self) -> BodyState {
        let p = self.body.position();
        let q = self.body.quaternion();
        let v = self.body.linear_velocity();
        let w = self.body.angular_velocity();
        BodyState {
            x: p[0],
            y: p[1],
            heading: wrap_angle(2.0 * q[3].atan2(q[0])),
            vx: v[0],
            vy: v[1],
            omega: w[2],
        }
    }

    fn step(&mut self, thrust: &[f64]) -> Result<(), PhysicsError> {
        validate_thrust(thrust, self.thrusters.len())?;
        for (t, &u) in self.thrusters.iter().zip(thrust) {
            let force = [t.force[0] * u, t.force[1] * u, t.force[2] * u];
            self.body.add_rel_force_at_rel_pos(force, t.arm)?;
        }
        match self.settings.stepper {
            Stepper::Exact => self.world.step(self.settings.dt)?,
            Stepper::Quick => self.world.quick_step(self.settings.dt)?,
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
