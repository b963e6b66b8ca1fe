//! What a run reports: a record per generation (or cycle) and the champion.

use serde::{Deserialize, Serialize};

use crate::limits::check_finite;
use crate::network::Network;
use crate::SettingsError;

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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Champion {
    /// The network.
    pub network: Network,
    /// Its fitness when it was evaluated.
    pub fitness: f64,
    /// The generation (cycle) it was found in, from 1.
    pub generation: usize,
    /// The evaluation that found it, counting every network the run
    /// evaluated (lesion tests included) from 1: a run stopped at a goal
    /// fitness took this many evaluations to reach it.
    pub evaluation: u64,
}

/// The outcome of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    /// The champion.
    pub champion: Champion,
    /// One record per generation (cycle).
    pub records: Vec<GenerationRecord>,
    /// Why the run ended.
    pub ending: Ending,
}

impl RunResult {
    /// Network evaluations the run spent, lesion tests included.
    pub fn evaluations(&self) -> u64 {
        self.records.last().map_or(0, |r| r.evaluations)
    }
}

/// What a run does after a generation (cycle): the per-generation callback
/// returns it, or returns `()`, which means [`Control::Continue`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Control {
    /// Go on to the next generation.
    #[default]
    Continue,
    /// End the run now and return its result.
    Stop,
}

impl From<()> for Control {
    fn from((): ()) -> Control {
        Control::Continue
    }
}

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ending {
    /// It ran all its generations (cycles).
    Completed,
    /// The champion reached [`StopAt::goal`].
    Goal,
    /// The run spent [`StopAt::evaluations`].
    Budget,
    /// The per-generation callback returned [`Control::Stop`].
    Stopped,
}

/// When a run ends before its last generation, decided after every
/// generation (cycle). A generation is never cut short: a run that reaches
/// its budget in the middle of a generation finishes it (and its lesion
/// test), and its result says exactly how many evaluations it spent.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct StopAt {
    /// End once the champion's fitness is at least this. Must be finite
    /// ([`StopAt::validate`]).
    pub goal: Option<f64>,
    /// End once at least this many networks have been evaluated.
    pub evaluations: Option<u64>,
}

impl StopAt {
    /// Never before the last generation.
    pub const NEVER: StopAt = StopAt {
        goal: None,
        evaluations: None,
    };

    /// Rejects a goal that is NaN or infinite (a run would never, or
    /// always, reach it). Runs check their stop conditions when they start.
    pub fn validate(&self) -> Result<(), SettingsError> {
        self.goal.map_or(Ok(()), |goal| check_finite("stop.goal", goal))
    }

    /// The decision after the generation that `record` describes, given
    /// the callback's: why the run ends there, if it does.
    pub fn decide(&self, record: &GenerationRecord, callback: Control) -> Option<Ending> {
        if self.goal.is_some_and(|goal| record.champion >= goal) {
            Some(Ending::Goal)
        } else if self.evaluations.is_some_and(|budget| record.evaluations >= budget) {
            Some(Ending::Budget)
        } else if callback == Control::Stop {
            Some(Ending::Stopped)
        } else {
            None
        }
    }
}
