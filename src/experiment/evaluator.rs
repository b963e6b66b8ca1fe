//! The PSA control problem as an [`Evaluator`] for the search algorithms.

use anyhow::Result;

use crate::evolution::Evaluator;
use crate::network::Network;
use crate::psa::{PsaSettings, Task, TrialRunner, INPUT_COUNT, THRUSTER_COUNT};
use crate::rng::Stream;

/// Scores a network by its fitness on a task (in % of the theoretical
/// maximum, the mean over `settings.trials` trials). Each worker thread
/// owns one physics world, reused between evaluations.
#[derive(Debug, Clone)]
pub struct PsaEvaluator {
    settings: PsaSettings,
    task: Task,
}

impl PsaEvaluator {
    /// An evaluator of `task`; fails on invalid settings.
    pub fn new(settings: PsaSettings, task: Task) -> Result<PsaEvaluator> {
        // Building one runner checks every setting (and random init vs task) up front.
        TrialRunner::new(&settings, task)?;
        Ok(PsaEvaluator { settings, task })
    }
}

impl Evaluator for PsaEvaluator {
    type Worker = TrialRunner;
    fn inputs(&self) -> usize {
        INPUT_COUNT
    }
    fn outputs(&self) -> usize {
        THRUSTER_COUNT
    }
    fn worker(&self) -> Result<TrialRunner> {
        Ok(TrialRunner::new(&self.settings, self.task)?)
    }
    fn evaluate(&self, runner: &mut TrialRunner, network: &Network, rng: &mut Stream) -> Result<f64> {
        Ok(runner.evaluate(network, rng)?)
    }
}
