//! What the algorithms search against: anything that scores a network.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use anyhow::{anyhow, Result};
use rayon::prelude::*;

use crate::network::{Network, NetworkSet};
use crate::rng::{Stream, StreamFamily};

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

    /// The fitness of networks `range` of `networks`, network `j` with the
    /// stream `streams.stream(j)`: what [`Evaluator::evaluate`] gives each,
    /// bit for bit. The default calls it network by network; a batched
    /// evaluator evaluates them in lockstep, reading their weights in place.
    /// Making the streams is part of the evaluation: an evaluator that
    /// draws nothing need not make them.
    fn evaluate_batch<S: NetworkSet + ?Sized>(
        &self,
        worker: &mut Self::Worker,
        networks: &S,
        range: Range<usize>,
        streams: &StreamFamily,
    ) -> Result<Vec<f64>> {
        evaluate_each(self, worker, networks, range, streams)
    }
}

/// [`Evaluator::evaluate_batch`] network by network, through
/// [`Evaluator::evaluate`]: the default, and what a batched evaluator falls
/// back on.
pub fn evaluate_each<E: Evaluator + ?Sized, S: NetworkSet + ?Sized>(
    evaluator: &E,
    worker: &mut E::Worker,
    networks: &S,
    range: Range<usize>,
    streams: &StreamFamily,
) -> Result<Vec<f64>> {
    range
        .map(|j| evaluator.evaluate(worker, &networks.network(j), &mut streams.stream(j)))
        .collect()
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
/// them in batches of its [`Evaluator::batch_size`], which the threads take
/// as they come free (the calling thread waits for the others' batches
/// without going to sleep, and they stay awake until the next call), any
/// other one network at a time. The result is in order and independent of
/// the thread count and of the batching.
pub fn evaluate_all<E: Evaluator, S: NetworkSet + ?Sized>(
    evaluator: &E,
    networks: &S,
    seed: u64,
    key: &[u64],
) -> Result<Vec<f64>> {
    let streams = StreamFamily::new(seed, key);
    if evaluator.batch_size() > 1 {
        return evaluate_batches(evaluator, networks, &streams);
    }
    (0..networks.len())
        .into_par_iter()
        .map_init(
            || evaluator.worker().map_err(|e| format!("{e:#}")),
            |worker, j| {
                let worker = worker
                    .as_mut()
                    .map_err(|e| anyhow!("cannot set up an evaluation worker: {e}"))?;
                let fitness = evaluator.evaluate(worker, &networks.network(j), &mut streams.stream(j))?;
                check_fitness(&[fitness], j)?;
                Ok(fitness)
            },
        )
        .collect()
}

/// An error naming the first network whose fitness is NaN; `first` is the
/// index of `fitness[0]`.
fn check_fitness(fitness: &[f64], first: usize) -> Result<()> {
    match fitness.iter().position(|f| f.is_nan()) {
        Some(i) => Err(anyhow!("the evaluation returned NaN for network {}", first + i)),
        None => Ok(()),
    }
}

/// Counts the calls of [`evaluate_batches`]: a thread kept awake after one
/// (see [`keep_warm`]) goes back to rayon when the next begins.
static BATCH_CALLS: AtomicU64 = AtomicU64::new(0);

/// How long a helper thread stays awake for the next generation's
/// evaluations before it goes back to rayon, which puts idle threads to
/// sleep. ESP's own work between two evaluations takes well under this.
const KEEP_WARM: Duration = Duration::from_millis(2);

/// The batches `networks` networks are evaluated in: as many full batches
/// of `size` as fit, then what is left in one piece per thread, so that
/// the threads finish together.
fn batch_ranges(networks: usize, size: usize, threads: usize) -> Vec<Range<usize>> {
    let full = networks / size * size;
    let mut ranges: Vec<Range<usize>> = (0..full).step_by(size).map(|start| start..start + size).collect();
    let left = networks - full;
    let pieces = threads.clamp(1, left.max(1));
    ranges.extend(
        (0..pieces)
            .map(|p| full + left * p / pieces..full + left * (p + 1) / pieces)
            .filter(|range| !range.is_empty()),
    );
    ranges
}

/// The batches of one [`evaluate_batches`] call, taken one at a time by
/// whichever thread is free.
struct Batches<'a, S: ?Sized> {
    networks: &'a S,
    ranges: Vec<Range<usize>>,
    /// The next batch to take.
    next: AtomicUsize,
    /// Batches finished (or abandoned by a panic).
    done: AtomicUsize,
    /// Each batch's result, set once by the thread that took it.
    results: Vec<OnceLock<Result<Vec<f64>>>>,
}

/// Counts a batch as done when dropped, so that a panicking evaluation
/// never leaves the calling thread waiting for it.
struct CountDone<'a>(&'a AtomicUsize);

impl Drop for CountDone<'_> {
    fn drop(&mut self) {
        self.0.fetch_add(1, Ordering::Release);
    }
}

impl<S: NetworkSet + ?Sized> Batches<'_, S> {
    /// Takes and evaluates batches until none is left.
    fn take_and_run<E: Evaluator>(&self, evaluator: &E, streams: &StreamFamily) {
        let mut worker = None;
        loop {
            let b = self.next.fetch_add(1, Ordering::AcqRel);
            let Some(range) = self.ranges.get(b) else {
                return;
            };
            let _done = CountDone(&self.done);
            let result = self.evaluate(evaluator, &mut worker, range.clone(), streams);
            assert!(self.results[b].set(result).is_ok(), "each batch is taken once");
        }
    }

    fn evaluate<E: Evaluator>(
        &self,
        evaluator: &E,
        worker: &mut Option<E::Worker>,
        range: Range<usize>,
        streams: &StreamFamily,
    ) -> Result<Vec<f64>> {
        let worker = match worker {
            Some(worker) => worker,
            None => worker.insert(
                evaluator
                    .worker()
                    .map_err(|e| anyhow!("cannot set up an evaluation worker: {e:#}"))?,
            ),
        };
        let start = range.start;
        let fitness = evaluator.evaluate_batch(worker, self.networks, range, streams)?;
        check_fitness(&fitness, start)?;
        Ok(fitness)
    }
}

/// [`evaluate_all`] for a batched evaluator: batches of
/// [`Evaluator::batch_size`] networks (see [`batch_ranges`]), which the
/// threads take one at a time as they come free, so that a thread slowed
/// down (on a shared host, say) does less of the work.
///
/// The calling thread offers the pool one helper job per other thread,
/// takes batches until none is left, and then waits for the batches the
/// helpers are evaluating without going to sleep (it yields its core
/// while it waits). A thread that is busy elsewhere (in `replicate`, every
/// thread runs a run of its own) never holds any batch up: the caller
/// takes every batch no helper took. Rayon would put a waiting thread to
/// sleep, and on a virtual machine waking a sleeping thread takes a tenth
/// of a millisecond or more, twice per generation (once to start a helper,
/// once to resume the caller). For the same reason the helpers are kept
/// awake until the next call (see [`keep_warm`]).
///
/// `evaluate_batch` must not wait on rayon itself (the evaluator's work is
/// plain computation): a thread waits only for batches that other threads
/// are evaluating.
fn evaluate_batches<E: Evaluator, S: NetworkSet + ?Sized>(
    evaluator: &E,
    networks: &S,
    streams: &StreamFamily,
) -> Result<Vec<f64>> {
    BATCH_CALLS.fetch_add(1, Ordering::AcqRel);
    let threads = rayon::current_num_threads();
    let ranges = batch_ranges(networks.len(), evaluator.batch_size(), threads);
    let batches = Batches {
        networks,
        results: ranges.iter().map(|_| OnceLock::new()).collect(),
        ranges,
        next: AtomicUsize::new(0),
        done: AtomicUsize::new(0),
    };
    let helpers = threads.min(batches.ranges.len()).saturating_sub(1);
    rayon::scope(|scope| {
        for _ in 0..helpers {
            scope.spawn(|_| batches.take_and_run(evaluator, streams));
        }
        batches.take_and_run(evaluator, streams);
        while batches.done.load(Ordering::Acquire) < batches.ranges.len() {
            std::thread::yield_now();
        }
    });
    for _ in 0..helpers {
        keep_warm();
    }
    let mut fitness = Vec::with_capacity(networks.len());
    for result in batches.results {
        fitness.extend(result.into_inner().expect("every batch was evaluated")?);
    }
    Ok(fitness)
}

/// Offers the pool a job that keeps the thread that takes it awake
/// (yielding its core) until the next [`evaluate_batches`] call, for at
/// most [`KEEP_WARM`], so that it can take a batch at once. Only a thread
/// that steals the job waits: a thread steals only when it has nothing
/// else to do, while the offering thread could pop it from its own queue
/// in the middle of other work (waiting for a rayon job, say), so there it
/// returns at once.
fn keep_warm() {
    let call = BATCH_CALLS.load(Ordering::Acquire);
    let offered_by = rayon::current_thread_index();
    rayon::spawn(move || {
        if rayon::current_thread_index() == offered_by {
            return;
        }
        let start = Instant::now();
        while BATCH_CALLS.load(Ordering::Acquire) == call && start.elapsed() < KEEP_WARM {
            std::thread::yield_now();
        }
    });
}

#[cfg(test)]
mod tests {
    use rand::Rng;

    use super::*;
    use crate::rng::stream;

    /// A batched evaluator whose fitness is network `j`'s first gene plus
    /// the first draw of its stream; `fail_at` makes the network with that
    /// first gene an error, `nan_at` a NaN, and any gene from `panic_from`
    /// on a panic.
    struct Batched {
        fail_at: Option<f64>,
        nan_at: Option<f64>,
        panic_from: Option<f64>,
    }

    impl Evaluator for Batched {
        type Worker = ();
        fn inputs(&self) -> usize {
            1
        }
        fn outputs(&self) -> usize {
            1
        }
        fn worker(&self) -> Result<()> {
            Ok(())
        }
        fn evaluate(&self, _: &mut (), network: &Network, rng: &mut Stream) -> Result<f64> {
            let gene = network.neuron(0)[0];
            assert!(self.panic_from.is_none_or(|from| gene < from), "evaluator panicked");
            if Some(gene) == self.fail_at {
                return Err(anyhow!("network with gene {gene} failed"));
            }
            if Some(gene) == self.nan_at {
                return Ok(f64::NAN);
            }
            Ok(gene + (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
        }
        fn batch_size(&self) -> usize {
            8
        }
    }

    fn networks(count: usize) -> Vec<Network> {
        (0..count)
            .map(|j| Network::from_genes(1, 1, vec![j as f64, 0.5]).expect("finite genes"))
            .collect()
    }

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
    }

    const CLEAN: Batched = Batched {
        fail_at: None,
        nan_at: None,
        panic_from: None,
    };

    #[test]
    fn full_batches_come_first_and_the_rest_is_split_over_the_threads() {
        let ranges = |n, threads| batch_ranges(n, 32, threads);
        assert_eq!(
            ranges(400, 1),
            [
                0..32,
                32..64,
                64..96,
                96..128,
                128..160,
                160..192,
                192..224,
                224..256,
                256..288,
                288..320,
                320..352,
                352..384,
                384..400
            ]
        );
        assert_eq!(ranges(400, 2)[11..], [352..384, 384..392, 392..400]);
        assert_eq!(ranges(64, 2), [0..32, 32..64]);
        assert_eq!(ranges(5, 2), [0..2, 2..5]);
        assert_eq!(ranges(3, 8), [0..1, 1..2, 2..3]);
        assert!(ranges(0, 2).is_empty());
    }

    #[test]
    fn batches_give_each_network_its_own_stream_whatever_the_thread_count() {
        let nets = networks(45);
        let expected: Vec<f64> = nets
            .iter()
            .enumerate()
            .map(|(j, n)| CLEAN.evaluate(&mut (), n, &mut stream(5, &[3, 9, j as u64])).unwrap())
            .collect();
        for threads in [1, 2, 3, 5] {
            for _ in 0..20 {
                let got = pool(threads)
                    .install(|| evaluate_all(&CLEAN, &nets[..], 5, &[3, 9]))
                    .unwrap();
                assert_eq!(got, expected, "{threads} threads");
            }
        }
        assert!(pool(2)
            .install(|| evaluate_all(&CLEAN, &[] as &[Network], 5, &[]))
            .unwrap()
            .is_empty());
    }

    #[test]
    fn an_error_or_nan_in_any_batch_names_its_network() {
        let nets = networks(40);
        for threads in [1, 2, 4] {
            let failing = Batched {
                fail_at: Some(33.0),
                ..CLEAN
            };
            let error = pool(threads)
                .install(|| evaluate_all(&failing, &nets[..], 1, &[]))
                .unwrap_err();
            assert!(format!("{error:#}").contains("gene 33 failed"), "{error:#}");
            let nan = Batched {
                nan_at: Some(21.0),
                ..CLEAN
            };
            let error = pool(threads)
                .install(|| evaluate_all(&nan, &nets[..], 1, &[]))
                .unwrap_err();
            assert!(error.to_string().contains("NaN for network 21"), "{error}");
        }
    }

    #[test]
    fn concurrent_evaluations_on_a_busy_pool_finish_with_the_right_results() {
        // As in `replicate`: every thread runs work of its own that calls
        // evaluate_all again and again, so no thread is free to take
        // another's batches; each must evaluate its own.
        let nets = networks(50);
        let expected = pool(1).install(|| evaluate_all(&CLEAN, &nets[..], 2, &[7])).unwrap();
        let runs: Vec<Vec<f64>> = pool(2).install(|| {
            (0..6)
                .into_par_iter()
                .map(|_| {
                    let mut last = Vec::new();
                    for _ in 0..200 {
                        last = evaluate_all(&CLEAN, &nets[..], 2, &[7]).unwrap();
                    }
                    last
                })
                .collect()
        });
        assert!(runs.iter().all(|r| *r == expected));
    }

    #[test]
    #[should_panic(expected = "evaluator panicked")]
    fn a_panicking_batch_panics_the_caller_instead_of_leaving_it_waiting() {
        let panicking = Batched {
            panic_from: Some(30.0),
            ..CLEAN
        };
        let _ = pool(2).install(|| evaluate_all(&panicking, &networks(40)[..], 1, &[]));
    }
}
