//! What a backend simulates: one rigid body built from uniform-density parts,
//! pushed by body-fixed thrusters, moving in the world x-y plane.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::PhysicsError;

/// One solid part of the body, positioned in the body's geometric frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum MassPart {
    /// A solid cylinder with its axis along z, centred at `center` (z = 0).
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Height along z (m).
        height: f64,
        /// Centre in the body's x-y plane (m).
        center: [f64; 2],
    },
    /// A solid box with sides along the body axes, centred at `center` (z = 0).
    Cuboid {
        /// Side lengths along x, y, z (m).
        size: [f64; 3],
        /// Centre in the body's x-y plane (m).
        center: [f64; 2],
    },
}

/// A body-fixed thruster: its force acts at `mount` along `direction`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Thruster {
    /// Where the force acts, in the body's geometric frame (m).
    pub mount: [f64; 2],
    /// Unit direction of the force in the body frame.
    pub direction: [f64; 2],
}

/// A rigid body of uniform density made of parts, with thrusters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigidBodyModel {
    /// Density of every part (kg/m^3).
    pub density: f64,
    /// The solid parts; their union is the mass distribution.
    pub parts: Vec<MassPart>,
    /// The thrusters, indexed as the thrust commands are.
    pub thrusters: Vec<Thruster>,
    /// Force of a thruster at full command u = 1 (N).
    pub max_force: f64,
}

/// Mass, centre of mass and inertia of a body, as a backend computed them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Total mass (kg).
    pub mass: f64,
    /// Centre of mass in the body's geometric frame (m).
    pub center: [f64; 3],
    /// Inertia tensor about the centre of mass (kg m^2).
    pub inertia: [[f64; 3]; 3],
}

fn positive(what: &str, value: f64) -> Result<(), PhysicsError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(PhysicsError::InvalidModel(format!(
            "{what} must be finite and > 0, got {value}"
        )))
    }
}

impl RigidBodyModel {
    /// Checks every number a backend would pass to its engine.
    pub fn validate(&self) -> Result<(), PhysicsError> {
        positive("density", self.density)?;
        positive("maximum thruster force", self.max_force)?;
        if self.parts.is_empty() {
            return Err(PhysicsError::InvalidModel("the body has no mass parts".into()));
        }
        for (i, part) in self.parts.iter().enumerate() {
            let (sizes, center): (&[f64], [f64; 2]) = match part {
                MassPart::Cylinder { radius, height, center } => (&[*radius, *height][..], *center),
                MassPart::Cuboid { size, center } => (&size[..], *center),
            };
            for s in sizes {
                positive(&format!("size of mass part {i}"), *s)?;
            }
            if center.iter().any(|c| !c.is_finite()) {
                return Err(PhysicsError::InvalidModel(format!(
                    "centre of mass part {i} must be finite, got {center:?}"
                )));
            }
        }
        for (i, t) in self.thrusters.iter().enumerate() {
            let finite = t.mount.iter().chain(&t.direction).all(|v| v.is_finite());
            let norm = t.direction[0].hypot(t.direction[1]);
            if !finite || (norm - 1.0).abs() > 1e-12 {
                return Err(PhysicsError::InvalidModel(format!(
                    "thruster {i} needs a finite mount and a unit direction, got mount {:?}, direction {:?}",
                    t.mount, t.direction
                )));
            }
        }
        Ok(())
    }

    /// Mass properties by closed-form formulas and the parallel-axis theorem
    /// (independent of every engine; used by the native backend).
    pub fn mass_properties(&self) -> MassProperties {
        let mut total = 0.0;
        let mut moment = Vector3::zeros();
        let mut inertia_at_origin = Matrix3::zeros();
        for part in &self.parts {
            let (m, local, c) = match *part {
                MassPart::Cylinder { radius, height, center } => {
                    let m = self.density * std::f64::consts::PI * radius * radius * height;
                    let side = m * (0.25 * radius * radius + height * height / 12.0);
                    (
                        m,
                        Matrix3::from_diagonal(&Vector3::new(side, side, 0.5 * m * radius * radius)),
                        center,
                    )
                }
                MassPart::Cuboid {
                    size: [lx, ly, lz],
                    center,
                } => {
                    let m = self.density * lx * ly * lz;
                    let d = Vector3::new(ly * ly + lz * lz, lx * lx + lz * lz, lx * lx + ly * ly) * (m / 12.0);
                    (m, Matrix3::from_diagonal(&d), center)
                }
            };
            let c = Vector3::new(c[0], c[1], 0.0);
            total += m;
            moment += c * m;
            inertia_at_origin += local + parallel_axis(m, &c);
        }
        let center = moment / total;
        let inertia = inertia_at_origin - parallel_axis(total, &center);
        MassProperties {
            mass: total,
            center: [center.x, center.y, center.z],
            inertia: std::array::from_fn(|r| std::array::from_fn(|k| inertia[(r, k)])),
        }
    }
}

/// The inertia a point mass `m` at `c` adds about the origin.
fn parallel_axis(m: f64, c: &Vector3<f64>) -> Matrix3<f64> {
    (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * m
}
