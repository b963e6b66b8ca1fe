//! The tests of a run's champion: its robustness tests ([`robustness`]:
//! input noise and random starts) and its flight again on `ode`
//! ([`ode_check`]), which must agree bit for bit.

pub mod ode_check;
pub mod robustness;
