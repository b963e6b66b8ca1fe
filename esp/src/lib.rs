//! Enforced Sub-Populations (ESP), the neuroevolution method of Gomez &
//! Miikkulainen, with every modification of Høverstad, "Revisiting the
//! Personal Satellite Assistant" (GECCO 2007), as a switch; and his
//! parallel stochastic hill-climber.
//!
//! Both search [`Network`](network::Network)s (one hidden layer of
//! logistic units, stored neuron by neuron as ESP needs it) against any
//! [`Evaluator`]: a function that scores a network on your problem. Higher
//! fitness is better, of any sign (minimise a cost by returning its
//! negative); it must be finite. Network evaluations run in parallel on
//! [`rayon`] (the current pool: `rayon::ThreadPoolBuilder::new().num_threads(n).build()?.install(|| esp.run(..))`
//! chooses the thread count); every random draw comes from a
//! counter-based stream ([`rng`]) keyed by what it is for (seed,
//! generation, network, ...), so a run is bit-identical for any thread
//! count.
//!
//! ```
//! use esp_neuroevolution::network::Network;
//! use esp_neuroevolution::{Esp, EspSettings, FnEvaluator};
//!
//! // Any control problem: here, make output 0 follow input 0 (a 2-H-1 network, bias last).
//! let evaluator = FnEvaluator::new(2, 1, |net: &Network, _rng: &mut esp_neuroevolution::rng::Stream| {
//!     let mut out = [0.0];
//!     let mut error = 0.0;
//!     for x in [0.0, 0.25, 0.5, 0.75, 1.0] {
//!         net.try_activate(&[x, 1.0], &mut out)?; // a wrong length is an error, not a panic
//!         error += (out[0] - x).powi(2);
//!     }
//!     Ok(-error)
//! });
//! let settings = EspSettings { subpop_size: 20, initial_hidden: 2, generations: 30, ..EspSettings::default() };
//! let result = Esp::new(settings, 7).unwrap().run(&evaluator, |_| {}).unwrap();
//! assert!(result.champion.fitness > -0.05);
//! ```
//!
//! A run can also be driven from outside, by ask and tell ([`AskTell`]):
//! [`Esp::start`] and [`HillClimb::start`] make runs that ask for networks
//! and are told their fitness with the ask's [`Ticket`]; [`together`]
//! advances many such runs together, evaluating every round's networks of
//! all of them in one batch. Either way a run is the one [`Esp::run`]
//! gives, bit for bit. A run under way ([`EspRun`], [`HillClimbRun`],
//! [`AnyRun`]) is serde as a whole: saved at any point and restored, it
//! ends as the run never stopped would have; so are its
//! [`Network`](network::Network)s, [`Champion`] and [`RunResult`].
//!
//! [`progress`] is a ready-made per-generation callback; [`limits`] holds
//! every setting's bounds.

mod any_run;
mod ask;
mod error;
mod esp;
mod evaluator;
mod hill_climb;
pub mod limits;
pub mod math;
pub mod network;
pub mod operators;
mod progress;
mod record;
pub mod rng;
mod run;
mod subpop;
pub mod together;

pub use any_run::AnyRun;
pub use ask::{AskPurpose, AskTell, Asked, Ticket};
pub use error::{RunError, SettingsError};
pub use esp::{BurstMode, Credit, EraseAt, Esp, EspRun, EspSettings, Relesion, Sampling, StagnationRule, TopologyMode};
pub use evaluator::{evaluate_all, evaluate_each, evaluate_each_part, evaluate_range, Evaluator, FnEvaluator, Part};
pub use hill_climb::{HillClimb, HillClimbRun, HillClimbSettings, MutationRates};
pub use limits::{
    MAX_GENERATIONS, MAX_HIDDEN, MAX_NETWORKS_PER_GENERATION, MAX_NETWORK_SIDE, MAX_REAL_SETTING, MAX_SUBPOP_SIZE,
    MAX_TRIALS_PER_NEURON, MIN_CAUCHY_LIMIT_PER_SCALE, MIN_SUBPOP_SIZE,
};
pub use progress::progress;
/// The random number crate whose traits draw from a [`rng::Stream`]
/// (`use esp_neuroevolution::rand::RngExt;` then `rng.random::<f64>()`),
/// re-exported so that an evaluator uses the version the streams implement.
pub use rand;
/// The thread pool crate the evaluations run on, re-exported for choosing
/// a run's thread count:
/// `rayon::ThreadPoolBuilder::new().num_threads(4).build()?.install(|| esp.run(&evaluator, |_| {}))`.
/// A run is bit-identical on any number of threads.
pub use rayon;
pub use record::{Champion, Control, Ending, GenerationRecord, LesionOutcome, RunResult, StopAt};

/// Records reserved at a run's start: at most its generations, which may
/// be many more than a run that stops early needs.
pub(crate) const RECORDS_RESERVED: usize = 4096;

/// Keys of the random streams, one per purpose.
pub(crate) mod purpose {
    /// Initial weights.
    pub const INIT: u64 = 1;
    /// Choosing neurons to form networks.
    pub const SAMPLE: u64 = 2;
    /// Evaluating a network of a generation.
    pub const EVALUATE: u64 = 3;
    /// Crossover and mutation in a sub-population.
    pub const BREED: u64 = 4;
    /// Burst mutation.
    pub const BURST: u64 = 5;
    /// Lesion test evaluations.
    pub const LESION: u64 = 6;
    /// A new sub-population.
    pub const NEW_SUBPOP: u64 = 7;
    /// Hill-climber mutations.
    pub const MUTATE: u64 = 8;
}

/// The first position of the highest fitness, and that fitness.
pub fn best_of(fitness: &[f64]) -> (usize, f64) {
    fitness.iter().enumerate().fold(
        (0, f64::NEG_INFINITY),
        |best, (j, &f)| if f > best.1 { (j, f) } else { best },
    )
}

/// The lowest and the mean fitness.
pub(crate) fn min_and_mean(fitness: &[f64]) -> (f64, f64) {
    let min = fitness.iter().copied().fold(f64::INFINITY, f64::min);
    (min, fitness.iter().sum::<f64>() / fitness.len() as f64)
}
