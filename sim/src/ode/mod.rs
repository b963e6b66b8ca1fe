//! Safe wrapper over `ode-sys`: ODE initialised once, per-thread ODE data,
//! worlds, bodies, masses and joints as owned values freed on drop.
//!
//! ODE kills the process on its internal errors (`dError` exits, `dDebug`
//! aborts), and its handlers cannot be unwound through, so every argument
//! that ODE would reject is validated here, in Rust, before the call and
//! reported as an [`OdeError`]. Together with `ode-sys` this module holds all
//! of the project's `unsafe` code.
//!
//! [`BareOdeLoop`] is the bare sequence of ODE calls of one PSA step, a
//! benchmark reference for the overhead of this wrapper and the ODE backend.

mod bare;
mod error;
mod mass;
mod messages;
mod runtime;
mod world;

pub use bare::{BareOdeLoop, BareStepper, RawBodyState};
pub use error::OdeError;
pub use mass::Mass;
pub use messages::{recent_messages, OdeMessage, OdeMessageKind};
pub use runtime::{ensure_thread_ready, libode_version, thread_pool, MAX_THREADS};
pub use world::{Body, Joint, World};
