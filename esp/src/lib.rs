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
//!
//! A run can also be driven from outside, by ask and tell ([`AskTell`]):
//! [`Esp::start`] and [`HillClimb::start`] make runs that ask for networks
//! and are told their fitness; [`lockstep`] advances many such runs
//! together, evaluating every round's networks of all of them in one batch.
//! Either way a run is the one [`Esp::run`] gives, bit for bit.

mod ask;
mod error;
mod esp;
mod esp_run;
mod evaluator;
mod hill_climb;
pub mod lockstep;
pub mod math;
pub mod network;
pub mod operators;
mod record;
pub mod rng;
mod subpop;

pub use ask::{AskPurpose, AskTell, Asked};
pub use error::{RunError, SettingsError};
pub use esp::{BurstMode, Credit, Esp, EspSettings, Sampling, StagnationRule, TopologyMode};
pub use esp_run::EspRun;
pub use evaluator::{evaluate_all, evaluate_each, evaluate_each_part, Evaluator, FnEvaluator, Part};
pub use hill_climb::{HillClimb, HillClimbRun, HillClimbSettings, MutationRates};
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

/// The largest initial weight range, Cauchy scale, Cauchy limit or
/// annealing constant: the paper's are 0.3-10. Weights stay within
/// [`MAX_REAL_SETTING`] times the generations of a run, so that a network's
/// sums stay finite.
pub const MAX_REAL_SETTING: f64 = 1e6;

/// The most generations (ESP) or cycles (hill-climber) of a run (the paper:
/// 2000); a run keeps one record per generation.
pub const MAX_GENERATIONS: usize = 1_000_000;

/// The most neurons per sub-population (the paper: 40).
pub const MAX_SUBPOP_SIZE: usize = 10_000;

/// The most evaluations per neuron and generation (the paper: 10).
pub const MAX_TRIALS_PER_NEURON: usize = 1_000;

/// The most hidden neurons a run starts with (the paper: 5).
pub const MAX_HIDDEN: usize = 100;

/// The most networks evaluated per generation (ESP: `trials_per_neuron`
/// x `subpop_size`; the hill-climber: `candidates`; the paper: 400). A
/// generation holds them all: at [`MAX_HIDDEN`] neurons of a 7-input,
/// 4-output network that is about 1 GB.
pub const MAX_NETWORKS_PER_GENERATION: usize = 100_000;

/// The smallest Cauchy limit, as a multiple of the largest Cauchy scale of
/// a run. A draw `alpha tan(pi u)` is accepted with probability
/// `(2 / pi) atan(limit / alpha)`: at least 6.3 % at this ratio, so the
/// rejection loop ends (the paper's 10 / 0.3 accepts 98 %).
pub const MIN_CAUCHY_LIMIT_PER_SCALE: f64 = 0.1;

/// Checks a setting in (0, [`MAX_REAL_SETTING`]].
pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), SettingsError> {
    if !(value.is_finite() && value > 0.0) {
        Err(SettingsError::NotPositive { name, value })
    } else if value > MAX_REAL_SETTING {
        Err(SettingsError::TooLarge {
            name,
            value,
            max: MAX_REAL_SETTING,
        })
    } else {
        Ok(())
    }
}

/// Checks a count setting in [min, max].
pub(crate) fn check_count(name: &'static str, value: usize, min: usize, max: usize) -> Result<(), SettingsError> {
    if value < min {
        Err(SettingsError::TooFew { name, value, min })
    } else if value > max {
        Err(SettingsError::TooMany { name, value, max })
    } else {
        Ok(())
    }
}

/// Checks that `limit_name` (a Cauchy limit) is at least
/// [`MIN_CAUCHY_LIMIT_PER_SCALE`] times `largest_scale`, the largest Cauchy
/// scale the run draws with (described by `scale_name`).
pub(crate) fn check_cauchy_limit(
    limit_name: &'static str,
    limit: f64,
    scale_name: &'static str,
    largest_scale: f64,
) -> Result<(), SettingsError> {
    if limit >= MIN_CAUCHY_LIMIT_PER_SCALE * largest_scale {
        Ok(())
    } else {
        Err(SettingsError::CauchyLimitTooSmall {
            limit_name,
            limit,
            scale_name,
            scale: largest_scale,
            ratio: MIN_CAUCHY_LIMIT_PER_SCALE,
        })
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
