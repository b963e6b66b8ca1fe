//! What a run reports: a record per generation (or cycle) and the champion.

use serde::{Deserialize, Serialize};

use crate::network::Network;

/// The outcome of a lesion test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "change")]
pub enum LesionOutcome {
    /// No neuron was redundant: a sub-population was added.
    Add,
    /// Hidden neuron `neuron` was redundant: its sub-population was removed.
    Remove {
        /// The redundant neuron.
        neuron: usize,
    },
}

/// One generation of ESP, or one cycle of the hill-climber.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GenerationRecord {
    /// Generation (cycle) number, from 1.
    pub generation: usize,
    /// Lowest network fitness this generation.
    pub min: f64,
    /// Mean network fitness this generation.
    pub mean: f64,
    /// Highest network fitness this generation.
    pub max: f64,
    /// The search's own best network fitness so far (ESP: the network burst
    /// mutation builds on, none right after erase-best forgot it;
    /// hill-climber: the base network's fitness).
    pub best: Option<f64>,
    /// The champion's fitness: the best network ever evaluated.
    pub champion: f64,
    /// Network evaluations used so far, lesion tests included.
    pub evaluations: u64,
    /// Sub-populations (hidden neurons searched) after this generation.
    pub subpops: usize,
    /// Whether a burst mutation happened at the end of this generation.
    pub burst: bool,
    /// Burst mutations so far.
    pub bursts: usize,
    /// The lesion test at the end of this generation, if any.
    pub lesion: Option<LesionOutcome>,
}

/// The best network ever evaluated.
#[derive(Debug, Clone, PartialEq)]
pub struct Champion {
    /// The network.
    pub network: Network,
    /// Its fitness when it was evaluated.
    pub fitness: f64,
    /// The generation (cycle) it was found in, from 1.
    pub generation: usize,
}

/// The outcome of a run.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// The champion.
    pub champion: Champion,
    /// One record per generation (cycle).
    pub records: Vec<GenerationRecord>,
}
