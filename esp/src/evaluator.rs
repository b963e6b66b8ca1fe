//! What the algorithms search against: anything that scores a network.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

use anyhow::{anyhow, Result};

use crate::RunError;
use rayon::prelude::*;

use crate::network::{Network, NetworkSet};
use crate::rng::{Stream, StreamFamily};

/// Scores networks. `Worker` is per-thread state (for a physics
/// simulation, its world, which may have to stay on the thread that made
/// it); the algorithms make one per parallel task and never move it
/// between threads.
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

    /// The fewest networks worth a batch of their own, at most
    /// [`Evaluator::batch_size`]: a batch of fewer takes at least as long as
    /// one of this many, so the networks left after the full batches are
    /// not cut into smaller pieces for the threads to share (see
    /// [`evaluate_all`]). 1 (the default) lets them be cut as fine as the
    /// thread count asks.
    fn narrowest_batch(&self) -> usize {
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
) -> Result<Vec<f64>, RunError> {
    let streams = StreamFamily::new(seed, key);
    if evaluator.batch_size() > 1 {
        return evaluate_batches(evaluator, networks, &streams);
    }
    (0..networks.len())
        .into_par_iter()
        .map_init(
            || evaluator.worker().map_err(|e| format!("{e:#}")),
            |worker, j| {
                let worker = worker.as_mut().map_err(|e| RunError::Worker(anyhow!("{e}")))?;
                let fitness = evaluator.evaluate(worker, &networks.network(j), &mut streams.stream(j))?;
                check_fitness(&[fitness], j)?;
                Ok(fitness)
            },
        )
        .collect()
}

/// An error naming the first network whose fitness is NaN; `first` is the
/// index of `fitness[0]`.
fn check_fitness(fitness: &[f64], first: usize) -> Result<(), RunError> {
    match fitness.iter().position(|f| f.is_nan()) {
        Some(i) => Err(RunError::NanFitness { network: first + i }),
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

/// Which networks each thread evaluates next: first the full batches of
/// `size`, one at a time, then the tail, the fewer than `size` networks
/// left, shared out among the threads that reach it.
///
/// The tail is cut when a thread reaches it, not beforehand. The thread
/// takes its share of what is left, counting itself and every thread that
/// is still taking batches and has not yet had a piece of the tail, so
/// that the threads finish together when they all take part; but never a
/// piece of fewer than `narrowest` networks (see
/// [`Evaluator::narrowest_batch`]), so the first thread there takes all of
/// a tail that narrow. A thread alone (in `replicate`, where every thread
/// runs a run of its own, the helpers rarely come) takes all of the tail
/// in one batch. A thread that comes back after its piece leaves the rest
/// to the threads still to have theirs; once there are none (one that
/// panicked included, see [`Taker`]), it takes what remains.
#[derive(Debug)]
struct Schedule {
    size: usize,
    /// The fewest networks of a piece of the tail (unless fewer are left).
    narrowest: usize,
    networks: usize,
    /// The next full batch to take.
    next_batch: AtomicUsize,
    /// The first network of the tail not yet taken.
    next_in_tail: AtomicUsize,
    /// Threads taking batches that have not yet had a piece of the tail.
    still_to_share: AtomicUsize,
}

impl Schedule {
    fn new(networks: usize, size: usize, narrowest: usize) -> Schedule {
        let size = size.max(1);
        Schedule {
            size,
            narrowest: narrowest.clamp(1, size),
            networks,
            next_batch: AtomicUsize::new(0),
            next_in_tail: AtomicUsize::new(networks / size * size),
            still_to_share: AtomicUsize::new(0),
        }
    }
}

/// One thread's view of a [`Schedule`]: counted among the threads still to
/// share the tail from its making until it has had a piece of the tail or
/// is dropped (so a thread that panics leaves the rest to the others).
struct Taker<'a> {
    schedule: &'a Schedule,
    shared: bool,
}

impl<'a> Taker<'a> {
    fn new(schedule: &'a Schedule) -> Taker<'a> {
        schedule.still_to_share.fetch_add(1, Ordering::AcqRel);
        Taker {
            schedule,
            shared: false,
        }
    }

    /// The next batch for this thread: `None` when every network is taken,
    /// or when this thread has had its piece of the tail and others are
    /// still to have theirs.
    fn next(&mut self) -> Option<Range<usize>> {
        let schedule = self.schedule;
        let full = schedule.networks / schedule.size;
        if schedule.next_batch.load(Ordering::Acquire) < full {
            let batch = schedule.next_batch.fetch_add(1, Ordering::AcqRel);
            if batch < full {
                return Some(batch * schedule.size..(batch + 1) * schedule.size);
            }
        }
        let takers = if self.shared {
            if schedule.still_to_share.load(Ordering::Acquire) > 0 {
                return None;
            }
            1
        } else {
            self.shared = true;
            // This thread and the others still to share.
            schedule.still_to_share.fetch_sub(1, Ordering::AcqRel)
        };
        let mut start = schedule.next_in_tail.load(Ordering::Acquire);
        loop {
            let left = schedule.networks.checked_sub(start).filter(|&left| left > 0)?;
            let end = start + left.div_ceil(takers).max(schedule.narrowest).min(left);
            match schedule
                .next_in_tail
                .compare_exchange(start, end, Ordering::AcqRel, Ordering::Acquire)
            {
                Ok(_) => return Some(start..end),
                Err(now) => start = now,
            }
        }
    }
}

impl Drop for Taker<'_> {
    fn drop(&mut self) {
        if !self.shared {
            self.schedule.still_to_share.fetch_sub(1, Ordering::AcqRel);
        }
    }
}

/// The batches of one [`evaluate_batches`] call, taken one at a time by
/// whichever thread is free.
struct Batches<'a, S: ?Sized> {
    networks: &'a S,
    schedule: Schedule,
    /// Networks evaluated (or abandoned by a panic).
    done: AtomicUsize,
    /// Each batch's first network and result.
    results: Mutex<Vec<(usize, Result<Vec<f64>, RunError>)>>,
}

/// Counts a batch's networks as done when dropped, so that a panicking
/// evaluation never leaves the calling thread waiting for it.
struct CountDone<'a>(&'a AtomicUsize, usize);

impl Drop for CountDone<'_> {
    fn drop(&mut self) {
        self.0.fetch_add(self.1, Ordering::Release);
    }
}

impl<S: NetworkSet + ?Sized> Batches<'_, S> {
    /// Takes and evaluates batches until none is left for this thread;
    /// the `caller` goes on until every network is evaluated, taking what
    /// the others leave, and yields its core while it waits.
    fn take_and_run<E: Evaluator>(&self, evaluator: &E, streams: &StreamFamily, caller: bool) {
        let mut worker = None;
        let mut taker = Taker::new(&self.schedule);
        loop {
            match taker.next() {
                Some(range) => {
                    let _done = CountDone(&self.done, range.len());
                    let result = self.evaluate(evaluator, &mut worker, range.clone(), streams);
                    self.results
                        .lock()
                        .unwrap_or_else(PoisonError::into_inner)
                        .push((range.start, result));
                }
                None if caller && self.done.load(Ordering::Acquire) < self.schedule.networks => {
                    std::thread::yield_now()
                }
                None => return,
            }
        }
    }

    fn evaluate<E: Evaluator>(
        &self,
        evaluator: &E,
        worker: &mut Option<E::Worker>,
        range: Range<usize>,
        streams: &StreamFamily,
    ) -> Result<Vec<f64>, RunError> {
        let worker = match worker {
            Some(worker) => worker,
            None => worker.insert(evaluator.worker().map_err(RunError::Worker)?),
        };
        let start = range.start;
        let fitness = evaluator.evaluate_batch(worker, self.networks, range, streams)?;
        check_fitness(&fitness, start)?;
        Ok(fitness)
    }
}

/// [`evaluate_all`] for a batched evaluator: batches of
/// [`Evaluator::batch_size`] networks and a tail shared out among the
/// threads that reach it (see [`Schedule`]), which the threads take one at
/// a time as they come free, so that a thread slowed down (on a shared
/// host, say) does less of the work.
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
) -> Result<Vec<f64>, RunError> {
    BATCH_CALLS.fetch_add(1, Ordering::AcqRel);
    let threads = rayon::current_num_threads();
    let batches = Batches {
        networks,
        schedule: Schedule::new(networks.len(), evaluator.batch_size(), evaluator.narrowest_batch()),
        done: AtomicUsize::new(0),
        results: Mutex::new(Vec::new()),
    };
    // No more helpers than batches could keep busy.
    let size = batches.schedule.size;
    let (full, tail) = (networks.len() / size, networks.len() % size);
    let helpers = threads.min(full + tail.min(threads)).saturating_sub(1);
    rayon::scope(|scope| {
        for _ in 0..helpers {
            scope.spawn(|_| batches.take_and_run(evaluator, streams, false));
        }
        batches.take_and_run(evaluator, streams, true);
    });
    for _ in 0..helpers {
        keep_warm();
    }
    let mut results = batches.results.into_inner().unwrap_or_else(PoisonError::into_inner);
    results.sort_unstable_by_key(|&(start, _)| start);
    let mut fitness = Vec::with_capacity(networks.len());
    for (_, result) in results {
        fitness.extend(result?);
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

    /// Every batch `schedule` gives the threads, which all start together,
    /// `order` naming which thread asks next, until none gets anything.
    fn takes(schedule: &Schedule, order: &[usize]) -> Vec<(usize, Range<usize>)> {
        let threads = order.iter().max().map_or(0, |&t| t + 1);
        let mut takers: Vec<Taker> = (0..threads).map(|_| Taker::new(schedule)).collect();
        let mut taken = Vec::new();
        loop {
            let before = taken.len();
            for &t in order {
                if let Some(range) = takers[t].next() {
                    taken.push((t, range));
                }
            }
            if taken.len() == before {
                return taken;
            }
        }
    }

    #[test]
    fn a_lone_thread_takes_the_full_batches_then_the_whole_tail() {
        let taken = takes(&Schedule::new(400, 32, 1), &[0]);
        let ranges: Vec<_> = taken.into_iter().map(|(_, range)| range).collect();
        let mut expected: Vec<_> = (0..12).map(|b| b * 32..(b + 1) * 32).collect();
        expected.push(384..400);
        assert_eq!(ranges, expected);
        assert!(takes(&Schedule::new(0, 32, 1), &[0]).is_empty());
        assert_eq!(takes(&Schedule::new(5, 32, 1), &[0]), [(0, 0..5)]);
    }

    #[test]
    fn threads_that_all_reach_the_tail_share_it_evenly() {
        // Two threads, asking in turn: six full batches each, then half the tail each.
        let taken = takes(&Schedule::new(400, 32, 1), &[0, 1]);
        assert_eq!(taken[..12].iter().filter(|(t, _)| *t == 0).count(), 6);
        assert_eq!(taken[12..], [(0, 384..392), (1, 392..400)]);
        // Three threads and a tail of 7: 3, 2 and 2.
        let taken = takes(&Schedule::new(7, 32, 1), &[0, 1, 2]);
        assert_eq!(taken, [(0, 0..3), (1, 3..5), (2, 5..7)]);
    }

    #[test]
    fn the_tail_is_not_cut_narrower_than_the_evaluator_asks() {
        let taken = takes(&Schedule::new(400, 32, 16), &[0, 1]);
        assert_eq!(taken[12..], [(0, 384..400)]);
        let taken = takes(&Schedule::new(20, 32, 8), &[0, 1, 2]);
        assert_eq!(taken, [(0, 0..8), (1, 8..16), (2, 16..20)]);
    }

    #[test]
    fn a_thread_back_before_the_others_leaves_them_their_share() {
        let schedule = Schedule::new(48, 32, 1);
        let (mut first, mut second) = (Taker::new(&schedule), Taker::new(&schedule));
        assert_eq!(first.next(), Some(0..32));
        assert_eq!(first.next(), Some(32..40));
        // The second thread has not had its piece yet.
        assert_eq!(first.next(), None);
        assert_eq!(second.next(), Some(40..48));
        assert_eq!(second.next(), None);
        assert_eq!(first.next(), None);
    }

    #[test]
    fn a_thread_that_comes_late_finds_the_tail_taken() {
        let schedule = Schedule::new(7, 32, 1);
        let mut first = Taker::new(&schedule);
        assert_eq!(first.next(), Some(0..7));
        assert_eq!(Taker::new(&schedule).next(), None);
    }

    #[test]
    fn the_rest_of_a_thread_that_drops_out_goes_to_the_others() {
        let schedule = Schedule::new(48, 32, 1);
        let mut first = Taker::new(&schedule);
        let second = Taker::new(&schedule);
        assert_eq!(first.next(), Some(0..32));
        assert_eq!(first.next(), Some(32..40));
        assert_eq!(first.next(), None);
        drop(second); // as when its thread panics
        assert_eq!(first.next(), Some(40..48));
        assert_eq!(first.next(), None);
    }

    #[test]
    fn the_tail_is_always_taken_whole_and_once() {
        for (networks, narrowest) in (0..100).flat_map(|n| [(n, 1), (n, 3), (n, 8)]) {
            for threads in 1..5 {
                let order: Vec<usize> = (0..threads).collect();
                let mut ranges: Vec<_> = takes(&Schedule::new(networks, 8, narrowest), &order)
                    .into_iter()
                    .map(|(_, range)| range)
                    .collect();
                ranges.sort_by_key(|range| range.start);
                let covered: Vec<usize> = ranges.into_iter().flatten().collect();
                assert_eq!(
                    covered,
                    (0..networks).collect::<Vec<_>>(),
                    "{networks} networks, {threads} threads, pieces of at least {narrowest}"
                );
            }
        }
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
