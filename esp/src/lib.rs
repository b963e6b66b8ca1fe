//! Enforced Sub-Populations (ESP), the neuroevolution method of Gomez &
//! Miikkulainen, with every modification of Høverstad, "Revisiting the
//! Personal Satellite Assistant" (GECCO 2007), as a switch; and his
//! parallel stochastic hill-climber.
//!
//! Both search [`Network`](network::Network)s (one hidden layer of
//! logistic units, stored neuron by neuron as ESP needs it) against any
//! [`Evaluator`]: a function that scores a network on your problem. Network
//! evaluations run in parallel on rayon; every random draw comes from a
//! counter-based stream ([`rng`]) keyed by what it is for (seed, generation,
//! network, ...), so a run is bit-identical for any thread count.
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
//!         net.activate(&[x, 1.0], &mut out);
//!         error += (out[0] - x).powi(2);
//!     }
//!     Ok(-error)
//! });
//! let settings = EspSettings { subpop_size: 20, initial_hidden: 2, generations: 30, ..EspSettings::default() };
//! let result = Esp::new(settings, 7).unwrap().run(&evaluator, |_| {}).unwrap();
//! assert!(result.champion.fitness > -0.05);
//! ```

mod error;
mod esp;
mod evaluator;
mod hill_climb;
pub mod math;
pub mod network;
pub mod operators;
mod record;
pub mod rng;
mod subpop;

pub use error::{RunError, SettingsError};
pub use esp::{BurstMode, Credit, Esp, EspSettings, Sampling, StagnationRule, TopologyMode};
pub use evaluator::{evaluate_all, evaluate_each, Evaluator, FnEvaluator};
pub use hill_climb::{HillClimb, HillClimbSettings, MutationRates};
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

/// Checks a probability setting.
pub(crate) fn check_probability(name: &'static str, value: f64) -> Result<(), SettingsError> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(SettingsError::NotAProbability { name, value })
    }
}

/// Checks a positive, finite setting.
pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), SettingsError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SettingsError::NotPositive { name, value })
    }
}

/// Checks the half-width of an initial weight interval (-v, v): positive,
/// and small enough for the interval's width to be finite.
pub(crate) fn check_init_range(name: &'static str, value: f64) -> Result<(), SettingsError> {
    check_positive(name, value)?;
    if (2.0 * value).is_finite() {
        Ok(())
    } else {
        Err(SettingsError::RangeTooWide {
            name,
            value,
            max: f64::MAX / 2.0,
        })
    }
}

/// Checks a count setting.
pub(crate) fn check_count(name: &'static str, value: usize, min: usize) -> Result<(), SettingsError> {
    if value >= min {
        Ok(())
    } else {
        Err(SettingsError::TooFew { name, value, min })
    }
}

/// The first position of the highest fitness, and that fitness.
pub(crate) fn best_of(fitness: &[f64]) -> (usize, f64) {
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
