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
    /// A scale, limit or constant above [`MAX_REAL_SETTING`](crate::MAX_REAL_SETTING).
    #[error("{name} must be in (0, {max:e}], got {value:e}")]
    TooLarge {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The largest value allowed.
        max: f64,
    },
    /// A count above its maximum.
    #[error("{name} must be <= {max}, got {value}")]
    TooMany {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: usize,
        /// The largest value allowed.
        max: usize,
    },
    /// ESP's networks per generation (trials per neuron x sub-population size) above the limit.
    #[error(
        "esp.trials_per_neuron x esp.subpop_size = {trials_per_neuron} x {subpop_size} networks per generation, more than {max}"
    )]
    TooManyNetworks {
        /// `esp.trials_per_neuron`.
        trials_per_neuron: usize,
        /// `esp.subpop_size`.
        subpop_size: usize,
        /// The most networks per generation.
        max: usize,
    },
    /// A Cauchy limit so small against its scale that the rejection draw
    /// would rarely accept.
    #[error(
        "{limit_name} = {limit:?} must be at least {ratio} x {scale_name} = {scale:e}, so that a Cauchy draw is accepted with probability >= 6 % (the draw is repeated until one is)"
    )]
    CauchyLimitTooSmall {
        /// The limit's setting.
        limit_name: &'static str,
        /// Its value.
        limit: f64,
        /// The scale it is measured against.
        scale_name: &'static str,
        /// That scale's largest value in the run.
        scale: f64,
        /// The least limit per scale.
        ratio: f64,
    },
    /// A value that must be finite and >= 0 and is not.
    #[error("{name} must be finite and >= 0, got {value}")]
    Negative {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A value that must be finite and is NaN or infinite.
    #[error("{name} must be finite, got {value}")]
    NotFinite {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
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
    /// The evaluator returned an infinite fitness, which the ranking of
    /// networks and neurons cannot use (a mean of +inf and -inf is NaN, a
    /// lesion test's share of infinity is undefined).
    #[error("the evaluation returned {value} for network {network}: fitness must be finite")]
    InfiniteFitness {
        /// The network's index in the call.
        network: usize,
        /// The fitness.
        value: f64,
    },
    /// A run's settings or stop conditions are out of range.
    #[error(transparent)]
    Settings(#[from] SettingsError),
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
    /// The hill-climber made a network that is not valid (a weight
    /// overflowed), or a run was started on networks of no inputs or outputs.
    #[error(transparent)]
    Network(#[from] NetworkError),
    /// A run was told another number of fitnesses than it asked networks.
    #[error("told {got} fitnesses for the {expected} networks asked")]
    FitnessCount {
        /// Networks asked.
        expected: usize,
        /// Fitnesses told.
        got: usize,
    },
    /// A run was told fitnesses with a ticket of another run (or of this
    /// run before it was saved and restored).
    #[error("the ticket belongs to another run: tell a run what its own ask asked")]
    ForeignTicket,
    /// A run was told fitnesses for an ask it was told already: a tell
    /// repeated, or a tell with no ask since the last one.
    #[error("ask {ticket} was told already (this run has been told {told} times): ask again, then tell")]
    TicketTold {
        /// The ask the ticket names, counting tells from 0.
        ticket: u64,
        /// Tells the run has taken.
        told: u64,
    },
    /// A run was told fitnesses after it had ended.
    #[error("the run has ended: it asks for no more networks")]
    Ended,
    /// A saved run that does not fit its own settings (written by another
    /// version, or changed by hand).
    #[error("cannot restore the run: {0}")]
    Restore(String),
    /// A run's result was asked for before it ended.
    #[error("the run has not ended: it still asks for networks")]
    NotEnded,
}
