//! psa-esp: evolving neural controllers for the Personal Satellite Assistant
//! (PSA), replicating Høverstad, "Revisiting the Personal Satellite
//! Assistant" (GECCO 2007). This crate is the top of the workspace: the
//! command line ([`cli`], including `bench`) and the `psa-esp` binary.
//!
//! The workspace's crates, each depending only on those before it:
//! 1. `ode-sys`: raw bindgen bindings to libode;
//! 2. `esp-neuroevolution` ([`evolution`], with [`network`] and [`rng`]):
//!    ESP and the hill-climber, generic over any evaluation function, which
//!    cannot name the PSA;
//! 3. `psa-sim`: the safe ODE wrapper ([`ode`]), the physics backends
//!    ([`physics`]), the shared arithmetic ([`numeric`]), the PSA ([`psa`])
//!    and its evaluator ([`evaluator`]), with [`io`] and [`provenance`];
//! 4. `psa-experiment` ([`experiment`], with [`plots`]): run configurations,
//!    the grid, robustness tests, results, statistics and the report;
//! 5. this crate: the command line.
//!
//! Nothing below may depend on this crate. The layers are re-exported here
//! under the paths the command line, the tests and the benchmarks use.

pub mod cli;

pub use esp_neuroevolution as evolution;
pub use esp_neuroevolution::{network, rng};
pub use psa_experiment as experiment;
pub use psa_experiment::plots;
pub use psa_sim::{evaluator, io, numeric, ode, physics, provenance, psa};
