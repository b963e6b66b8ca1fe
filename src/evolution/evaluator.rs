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

    /// How many networks [`Evaluator::evaluate_batch`] takes at a time to
    /// best effect; 1 (the default) means no batching.
    fn batch_size(&self) -> usize {
        1
    }

    /// The fitness of each network, network `i` with stream `rngs[i]`: what
    /// [`Evaluator::evaluate`] gives each, bit for bit. The default calls it
    /// network by network; a batched evaluator evaluates them in lockstep.
    fn evaluate_batch(
        &self,
        worker: &mut Self::Worker,
        networks: &[&Network],
        rngs: &mut [Stream],
    ) -> Result<Vec<f64>> {
        networks
            .iter()
            .zip(rngs)
            .map(|(network, rng)| self.evaluate(worker, network, rng))
            .collect()
    }
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
/// gets the stream `stream(seed, [key.., j])`. A batched evaluator gets
/// them in one even share per thread (it splits a share into its own
/// blocks), any other one network at a time. The result is in order and
/// independent of the thread count and of the batching.
pub fn evaluate_all<E: Evaluator>(evaluator: &E, networks: &[Network], seed: u64, key: &[u64]) -> Result<Vec<f64>> {
    let batch = match evaluator.batch_size() {
        0 | 1 => 1,
        _ => networks.len().div_ceil(rayon::current_num_threads()).max(1),
    };
    let batches: Vec<Vec<f64>> = networks
        .par_chunks(batch)
        .enumerate()
        .map_init(
            || evaluator.worker().map_err(|e| format!("{e:#}")),
            |worker, (b, chunk)| {
                let worker = worker
                    .as_mut()
                    .map_err(|e| anyhow!("cannot set up an evaluation worker: {e}"))?;
                let first = b * batch;
                let mut full_key = [key, &[0]].concat();
                let mut rngs: Vec<Stream> = (first..first + chunk.len())
                    .map(|j| {
                        *full_key.last_mut().expect("the key has the network index") = j as u64;
                        stream(seed, &full_key)
                    })
                    .collect();
                let refs: Vec<&Network> = chunk.iter().collect();
                let fitness = evaluator.evaluate_batch(worker, &refs, &mut rngs)?;
                if let Some(i) = fitness.iter().position(|f| f.is_nan()) {
                    return Err(anyhow!("the evaluation returned NaN for network {}", first + i));
                }
                Ok(fitness)
            },
        )
        .collect::<Result<_>>()?;
    Ok(batches.concat())
}
