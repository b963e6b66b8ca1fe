//! The Personal Satellite Assistant as a control problem: its body and
//! thrusters, sensors and noise, the paper's three tasks, both fitness
//! functions, trials, and the network file format.

pub mod batch;
pub mod body;
pub mod cuda;
pub mod error;
pub mod fitness;
mod flight;
pub mod network_file;
pub mod ode_lockstep;
pub mod sensors;
pub mod settings;
pub mod step;
pub mod task;
pub mod trial;

pub use batch::BatchRunner;
pub use body::{BodySettings, THRUSTER_COUNT};
pub use error::PsaError;
pub use fitness::{FitnessKind, FitnessSettings, FitnessState, Scoring, SlowingRule};
pub use network_file::{NetworkFile, NetworkFileError};
pub use ode_lockstep::OdeLockstepRunner;
pub use sensors::{HeadingInput, HeadingWrap, NoiseSettings, SensorSettings, INPUT_COUNT};
pub use settings::{PsaSettings, TaskOverrides};
pub use task::{Target, Task, TaskSettings};
pub use trial::{mean_of_trials, TrialRecord, TrialRunner};
