//! psa-esp: evolving neural controllers for the Personal Satellite Assistant
//! (PSA), replicating Høverstad, "Revisiting the Personal Satellite
//! Assistant" (GECCO 2007).
//!
//! Layers, each depending only on those before it:
//! 1. `ode-sys` (a separate crate): raw bindgen bindings to libode;
//! 2. [`ode`]: the safe ODE wrapper (all of the project's other `unsafe`);
//! 3. [`physics`]: the backends `ode`, `native` and `rapier` behind one trait;
//! 4. [`psa`]: the robot, its thrusters, sensors, noise, tasks and fitness,
//!    and the batched evaluation path;
//! 5. [`evolution`]: ESP and the hill-climber, generic over any evaluation
//!    function: the workspace's search crate `esp-neuroevolution` (which
//!    also holds [`network`] and [`rng`]), which cannot name the PSA;
//! 6. [`experiment`]: run configurations, the experiment grid, robustness
//!    tests, statistics and the report (with [`plots`]);
//! 7. [`cli`]: the command line, including `bench`.
//!
//! Beside the layers: [`numeric`] (the shared per-step arithmetic and SIMD
//! lanes), [`io`] (atomic writes) and [`provenance`].

pub mod cli;
pub mod experiment;
pub mod io;
pub mod numeric;
pub mod ode;
pub mod physics;
pub mod plots;
pub mod provenance;
pub mod psa;

// The search crate under the paths the application has always used.
pub use esp_neuroevolution as evolution;
pub use esp_neuroevolution::{network, rng};
