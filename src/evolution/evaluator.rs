//! What the algorithms search against: anything that scores a network.

use anyhow::{anyhow, Result};
use rayon::prelude::*;

use crate::network::Network;
use crate::rng::{stream, Stream};

/// Scores networks. `Worker` is per-thread state (for the PSA: a physics
/// world, which must stay on the thread that made it); the algorithms make
/// one per parallel task and never move it between threads.
pub trait Evaluator: Sync {
    /// Per-thread evaluation state.
    type Worker;
    /// Network inputs (bias included).
    fn inputs(&self) -> usize;
    /// Network outputs.
    fn outputs(&self) -> usize;
    /// Makes the per-thread state.
    fn worker(&self) -> Result<Self::Worker>;
    /// The fitness of `network`; all randomness must come from `rng`, so that
    /// the same network and stream give the same fitness. Higher is better.
    fn evaluate(&self, worker: &mut Self::Worker, network: &Network, rng: &mut Stream) -> Result<f64>;
}

/// An [`Evaluator`] from a plain function.
pub struct FnEvaluator<F> {
    inputs: usize,
    outputs: usize,
    function: F,
}

impl<F> FnEvaluator<F>
where
    F: Fn(&Network, &mut Stream) -> Result<f64> + Sync,
{
    /// Wraps `function`, which scores networks of `inputs` inputs and `outputs` outputs.
    pub fn new(inputs: usize, outputs: usize, function: F) -> Self {
        FnEvaluator {
            inputs,
            outputs,
            function,
        }
    }
}

impl<F> Evaluator for FnEvaluator<F>
where
    F: Fn(&Network, &mut Stream) -> Result<f64> + Sync,
{
    type Worker = ();
    fn inputs(&self) -> usize {
        self.inputs
    }
    fn outputs(&self) -> usize {
        self.outputs
    }
    fn worker(&self) -> Result<()> {
        Ok(())
    }
    fn evaluate(&self, _: &mut (), network: &Network, rng: &mut Stream) -> Result<f64> {
        (self.function)(network, rng)
    }
}

/// Evaluates `networks` in parallel on the current rayon pool; network `j`
/// gets the stream `stream(seed, [key.., j])`. The result is in order and
/// independent of the thread count.
pub fn evaluate_all<E: Evaluator>(evaluator: &E, networks: &[Network], seed: u64, key: &[u64]) -> Result<Vec<f64>> {
    networks
        .par_iter()
        .enumerate()
        .map_init(
            || evaluator.worker().map_err(|e| format!("{e:#}")),
            |worker, (j, network)| {
                let worker = worker
                    .as_mut()
                    .map_err(|e| anyhow!("cannot set up an evaluation worker: {e}"))?;
                let mut full_key = key.to_vec();
                full_key.push(j as u64);
                let fitness = evaluator.evaluate(worker, network, &mut stream(seed, &full_key))?;
                if fitness.is_nan() {
                    return Err(anyhow!("the evaluation returned NaN for network {j}"));
                }
                Ok(fitness)
            },
        )
        .collect()
}
