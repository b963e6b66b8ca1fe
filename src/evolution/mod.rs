//! Search algorithms over networks: Enforced Sub-Populations (ESP) with every
//! modification of Høverstad (2007) as a switch, and his hill-climber.
//!
//! Both are generic: they search [`Network`](crate::network::Network)s against any [`Evaluator`] and
//! know nothing of the PSA. Network evaluations run in parallel on rayon;
//! every random draw comes from a stream keyed by what it is for (seed,
//! generation, network, ...), so a run is bit-identical for any thread count.
//!
//! ```
//! use psa_esp::evolution::{Esp, EspSettings, FnEvaluator};
//! use psa_esp::network::Network;
//!
//! // Any control problem: here, make output 0 follow input 0 (a 2-H-1 network, bias last).
//! let evaluator = FnEvaluator::new(2, 1, |net: &Network, _rng: &mut psa_esp::rng::Stream| {
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

mod esp;
mod evaluator;
mod hill_climb;
pub mod operators;
mod record;
mod subpop;

pub use esp::{BurstMode, Credit, Esp, EspSettings, Sampling, StagnationRule, TopologyMode};
pub use evaluator::{evaluate_all, evaluate_each, Evaluator, FnEvaluator};
pub use hill_climb::{HillClimb, HillClimbSettings, MutationRates};
pub use record::{Champion, GenerationRecord, LesionOutcome, RunResult};

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
pub(crate) fn check_probability(name: &str, p: f64) -> Result<(), String> {
    if (0.0..=1.0).contains(&p) {
        Ok(())
    } else {
        Err(format!("{name} must be a probability in [0, 1], got {p}"))
    }
}

/// Checks a positive, finite setting.
pub(crate) fn check_positive(name: &str, v: f64) -> Result<(), String> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(format!("{name} must be finite and > 0, got {v}"))
    }
}

/// Checks the half-width of an initial weight interval (-v, v): positive,
/// and small enough for the interval's width to be finite.
pub(crate) fn check_init_range(name: &str, v: f64) -> Result<(), String> {
    check_positive(name, v)?;
    if (2.0 * v).is_finite() {
        Ok(())
    } else {
        Err(format!(
            "{name} must be at most {:e}, so that (-{name}, {name}) has a finite width, got {v:e}",
            f64::MAX / 2.0
        ))
    }
}

/// Checks a count setting.
pub(crate) fn check_count(name: &str, n: usize, min: usize) -> Result<(), String> {
    if n >= min {
        Ok(())
    } else {
        Err(format!("{name} must be >= {min}, got {n}"))
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
