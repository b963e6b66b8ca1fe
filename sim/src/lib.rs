//! psa-sim: the Personal Satellite Assistant (PSA) of Høverstad, "Revisiting
//! the Personal Satellite Assistant" (GECCO 2007), simulated: a round robot
//! with four one-way thrusters in a frictionless cabin, its sensors, the
//! paper's three tasks and both fitness functions, and an evaluator that
//! scores neural controllers on them for the search crate
//! `esp-neuroevolution`. Usable on its own, as a benchmark or a control
//! problem; its model is specified in `docs/specification.md`.
//!
//! Layers, each depending only on those before it:
//! 1. `ode-sys` (a separate crate): raw bindgen bindings to libode;
//! 2. [`ode`]: the safe ODE wrapper (with the CUDA launcher in
//!    [`psa::cuda`], all of the project's `unsafe` outside `ode-sys`);
//! 3. [`numeric`]: the per-step arithmetic shared by the scalar and the
//!    batched paths, and the SIMD lanes;
//! 4. [`physics`]: the backends `ode`, `native` and `rapier` behind one trait;
//! 5. [`psa`]: the robot, its thrusters, sensors, noise, tasks and fitness,
//!    trials on every evaluation path, and the network file;
//! 6. [`evaluator`]: the PSA as an evaluation function, on the
//!    [`EvalPath`] its caller names.
//!
//! Beside them: [`io`] (atomic writes), [`named`] (the enumerations read
//! by name) and [`provenance`].
//!
//! It may not depend on the experiment crate (`psa-experiment`), on
//! plotting or on the command line (`plotters`, `clap`): `.ci/run` checks
//! its `cargo tree`.

pub mod evaluator;
pub mod io;
pub mod named;
pub mod numeric;
pub mod ode;
pub mod physics;
pub mod provenance;
pub mod psa;

pub use evaluator::{EvalPath, PsaEvaluator, PsaWorker};
