//! psa-esp: evolving neural controllers for the Personal Satellite Assistant
//! (PSA), replicating Høverstad, "Revisiting the Personal Satellite
//! Assistant" (GECCO 2007). This crate is the top of the workspace: the
//! command line ([`cli`], including `bench`) and the `psa-esp` binary.
//!
//! The workspace's crates, each depending only on those before it:
//! 1. `ode-sys`: raw bindgen bindings to libode;
//! 2. `esp-neuroevolution` ([`esp_neuroevolution`]): ESP and the
//!    hill-climber, the network and the random streams, generic over any
//!    evaluation function, which cannot name the PSA;
//! 3. `psa-sim` ([`psa_sim`]): the safe ODE wrapper, the physics backends,
//!    the shared arithmetic, the PSA and its evaluator;
//! 4. `psa-experiment` ([`psa_experiment`]): run configurations, the grid,
//!    robustness tests, results, statistics, the report and the plots;
//! 5. this crate: the command line.
//!
//! Nothing below may depend on this crate, and it re-exports none of them:
//! the command line, the tests and the benchmarks name each crate by its
//! own name.

pub mod cli;
