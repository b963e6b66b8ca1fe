//! The Personal Satellite Assistant: its body and thrusters.

pub mod body;

pub use body::{BodySettings, THRUSTER_COUNT};
