//! The PSA's body: a round hull and four thrusters of one density, and the
//! thruster table of the spec (`docs/specification.md` §1).
//!
//! | thruster | mount (body) | force (body) | torque |
//! |---|---|---|---|
//! | 0 | (0, -r) | +x | anticlockwise |
//! | 1 | (+r, 0) | +y | anticlockwise |
//! | 2 | (0, +r) | +x | clockwise |
//! | 3 | (-r, 0) | +y | clockwise |

use serde::{Deserialize, Serialize};

use crate::physics::{MassPart, PhysicsError, RigidBodyModel, Thruster};

/// The number of thrusters (and of network outputs).
pub const THRUSTER_COUNT: usize = 4;

/// Geometry and mass of the PSA (`[chosen]` values of the spec unless marked).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BodySettings {
    /// Radius of the round hull, a solid cylinder along z (m). `[chosen]` 0.10
    pub hull_radius: f64,
    /// Height of the hull along z (m). `[chosen]` 0.10
    pub hull_height: f64,
    /// Thruster box: length along its thrust axis, width, height (m). `[chosen]` 0.04 x 0.02 x 0.02
    pub thruster_size: [f64; 3],
    /// Distance of each thruster's centre (its mount) from the hull's centre (m). `[chosen]` 0.12
    pub mount_radius: f64,
    /// Density of hull and thrusters alike (kg/m^3). `[chosen]` 1000
    pub density: f64,
    /// Force of a thruster at full output (N). `[paper]` 1
    pub max_force: f64,
}

impl Default for BodySettings {
    fn default() -> Self {
        BodySettings {
            hull_radius: 0.10,
            hull_height: 0.10,
            thruster_size: [0.04, 0.02, 0.02],
            mount_radius: 0.12,
            density: 1000.0,
            max_force: 1.0,
        }
    }
}

impl BodySettings {
    /// Rejects values outside their [ranges](super::settings::limits).
    pub fn validate(&self) -> Result<(), PhysicsError> {
        let [length, width, height] = self.thruster_size;
        super::settings::limits::check_all(&[
            ("body.hull_radius", self.hull_radius),
            ("body.hull_height", self.hull_height),
            ("body.thruster_size", length),
            ("body.thruster_size", width),
            ("body.thruster_size", height),
            ("body.mount_radius", self.mount_radius),
            ("body.density", self.density),
            ("body.max_force", self.max_force),
        ])
        .map_err(PhysicsError::InvalidModel)
    }

    /// The rigid-body model every backend simulates. Fails on a value
    /// outside its range ([`BodySettings::validate`]).
    pub fn model(&self) -> Result<RigidBodyModel, PhysicsError> {
        self.validate()?;
        let r = self.mount_radius;
        let [length, width, height] = self.thruster_size;
        // (mount, thrust direction); boxes lie with their length along the thrust.
        let layout = [
            ([0.0, -r], [1.0, 0.0]),
            ([r, 0.0], [0.0, 1.0]),
            ([0.0, r], [1.0, 0.0]),
            ([-r, 0.0], [0.0, 1.0]),
        ];
        let mut parts = vec![MassPart::Cylinder {
            radius: self.hull_radius,
            height: self.hull_height,
            center: [0.0, 0.0],
        }];
        parts.extend(layout.iter().map(|&(mount, dir)| MassPart::Cuboid {
            size: if dir[0] != 0.0 {
                [length, width, height]
            } else {
                [width, length, height]
            },
            center: mount,
        }));
        let model = RigidBodyModel {
            density: self.density,
            parts,
            thrusters: layout
                .iter()
                .map(|&(mount, direction)| Thruster { mount, direction })
                .collect(),
            max_force: self.max_force,
        };
        model.validate()?;
        Ok(model)
    }
}
