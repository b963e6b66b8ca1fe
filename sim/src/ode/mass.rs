//! ODE's mass parameters (`dMass`) as a plain Rust value with validated
//! constructors.

use super::error::{check_finite, check_positive};
use super::OdeError;

/// A mass distribution: total mass, centre of mass and 3x3 inertia about
/// the centre of mass' reference point, in ODE's own representation.
#[derive(Clone, Copy)]
pub struct Mass {
    raw: ode_sys::dMass,
}

impl std::fmt::Debug for Mass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mass")
            .field("mass", &self.total())
            .field("center", &self.center())
            .field("inertia", &self.inertia())
            .finish()
    }
}

/// ODE's axis numbering for `dMassSetCylinder`: 1 = x, 2 = y, 3 = z.
const Z_AXIS: i32 = 3;

impl Mass {
    /// A solid cylinder of uniform `density` with its axis along z.
    pub fn cylinder_z(density: f64, radius: f64, height: f64) -> Result<Mass, OdeError> {
        check_positive("density", density)?;
        check_positive("cylinder radius", radius)?;
        check_positive("cylinder height", height)?;
        let mut raw = ode_sys::dMass::default();
        // SAFETY: `raw` is a valid dMass; all arguments are positive and finite.
        unsafe { ode_sys::dMassSetCylinder(&mut raw, density, Z_AXIS, radius, height) };
        Ok(Mass { raw })
    }

    /// A solid box of uniform `density` with side lengths along x, y, z.
    pub fn cuboid(density: f64, size: [f64; 3]) -> Result<Mass, OdeError> {
        check_positive("density", density)?;
        for side in size {
            check_positive("box side length", side)?;
        }
        let mut raw = ode_sys::dMass::default();
        // SAFETY: `raw` is a valid dMass; all arguments are positive and finite.
        unsafe { ode_sys::dMassSetBox(&mut raw, density, size[0], size[1], size[2]) };
        Ok(Mass { raw })
    }

    /// Moves the distribution by `offset` (ODE's parallel-axis update).
    pub fn translate(&mut self, offset: [f64; 3]) -> Result<(), OdeError> {
        let [x, y, z] = check_finite("mass translation", offset)?;
        // SAFETY: `raw` is a valid dMass; the offset is finite.
        unsafe { ode_sys::dMassTranslate(&mut self.raw, x, y, z) };
        Ok(())
    }

    /// Adds another distribution to this one (ODE's `dMassAdd`).
    pub fn add(&mut self, other: &Mass) {
        // SAFETY: both are valid dMass values built by the checked constructors.
        unsafe { ode_sys::dMassAdd(&mut self.raw, &other.raw) };
    }

    /// Total mass in kg.
    pub fn total(&self) -> f64 {
        self.raw.mass
    }

    /// Centre of mass relative to the reference point.
    pub fn center(&self) -> [f64; 3] {
        [self.raw.c[0], self.raw.c[1], self.raw.c[2]]
    }

    /// The 3x3 inertia tensor (ODE stores it as 3 rows of 4).
    pub fn inertia(&self) -> [[f64; 3]; 3] {
        let i = &self.raw.I;
        [[i[0], i[1], i[2]], [i[4], i[5], i[6]], [i[8], i[9], i[10]]]
    }

    /// The checks `dBodySetMass` would abort on, done in Rust: positive
    /// finite mass, centre of mass at the origin (within ODE's dEpsilon),
    /// symmetric positive-definite inertia.
    pub fn validate_for_body(&self) -> Result<(), OdeError> {
        check_positive("mass", self.total())?;
        let c = self.center();
        if c.iter().any(|v| !v.is_finite() || v.abs() > f64::EPSILON) {
            return Err(OdeError::invalid(
                "centre of mass",
                c,
                "must be at the body origin: translate the mass by minus its centre first",
            ));
        }
        let m = self.inertia();
        let finite = m.iter().flatten().all(|v| v.is_finite());
        let symmetric = (0..3).all(|r| (0..3).all(|k| m[r][k] == m[k][r]));
        // Sylvester's criterion: leading principal minors all positive.
        let d1 = m[0][0];
        let d2 = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        let d3 = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        if !(finite && symmetric && d1 > 0.0 && d2 > 0.0 && d3 > 0.0) {
            return Err(OdeError::invalid(
                "inertia tensor",
                m,
                "must be finite, symmetric and positive definite",
            ));
        }
        Ok(())
    }

    pub(super) fn raw(&self) -> &ode_sys::dMass {
        &self.raw
    }
}

impl Mass {
    pub(super) fn from_raw(raw: ode_sys::dMass) -> Mass {
        Mass { raw }
    }
}
