//! The errors of the PSA problem.

use thiserror::Error;

use crate::physics::PhysicsError;

/// Errors of the PSA problem.
#[derive(Debug, Error)]
pub enum PsaError {
    /// A setting has an impossible value.
    #[error("invalid setting: {0}")]
    Setting(String),
    /// The network does not fit the PSA (7 inputs, 4 outputs).
    #[error("network does not fit the PSA: {0}")]
    Network(String),
    /// The physics layer refused or failed.
    #[error(transparent)]
    Physics(#[from] PhysicsError),
}
