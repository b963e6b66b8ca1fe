//! What can go wrong: a setting out of range, or a run that cannot go on.

use thiserror::Error;

use crate::network::NetworkError;

/// A setting out of its range, named as in a configuration file
/// (`esp.subpop_size`, ...).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SettingsError {
    /// A probability outside [0, 1].
    #[error("{name} must be a probability in [0, 1], got {value}")]
    NotAProbability {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A scale or limit that is not finite and positive.
    #[error("{name} must be finite and > 0, got {value}")]
    NotPositive {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// An initial weight range whose width (twice its half-width) overflows.
    #[error("{name} must be at most {max:e}, so that (-{name}, {name}) has a finite width, got {value:e}")]
    RangeTooWide {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The largest value allowed.
        max: f64,
    },
    /// A count below its minimum.
    #[error("{name} must be >= {min}, got {value}")]
    TooFew {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: usize,
        /// The least value allowed.
        min: usize,
    },
}

/// Why a run (or an evaluation of networks) stopped with no result.
#[derive(Debug, Error)]
pub enum RunError {
    /// The evaluator could not make its per-thread state.
    #[error("cannot set up an evaluation worker: {0:#}")]
    Worker(anyhow::Error),
    /// The evaluator failed on a network.
    #[error(transparent)]
    Evaluation(#[from] anyhow::Error),
    /// The evaluator returned NaN.
    #[error("the evaluation returned NaN for network {network}")]
    NanFitness {
        /// The network's index in the call.
        network: usize,
    },
    /// ESP's weights overflowed to infinity or NaN.
    #[error(
        "weight {gene} of neuron {neuron} of sub-population {subpop} is not finite ({value}): \
         the mutation and burst settings let the weights overflow"
    )]
    NonFiniteWeight {
        /// The sub-population.
        subpop: usize,
        /// The neuron within it.
        neuron: usize,
        /// The gene within the neuron.
        gene: usize,
        /// The weight.
        value: f64,
    },
    /// The hill-climber made a network that is not valid (a weight overflowed).
    #[error(transparent)]
    Network(#[from] NetworkError),
}
