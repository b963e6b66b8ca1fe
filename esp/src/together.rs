//! Many runs advanced together: every round, all their asked networks are
//! evaluated in one parallel pass, then each run is told its share.
//!
//! A run's results depend on its settings and seed only, never on who
//! evaluates its networks or beside which others ([`crate::AskTell`]), so
//! [`run_together`] gives every run exactly what it gives on its own. What it
//! changes is the shape of the work: one batch of every run's networks per
//! round instead of one per run and generation, which suits an evaluator
//! that pays per call (a GPU launch) more than per network.

use std::ops::Range;

use rayon::prelude::*;

use crate::ask::AskTell;
use crate::evaluator::{batch_ranges, check_fitness, Part};
use crate::network::NetworkSet;
use crate::rng::StreamFamily;
use crate::{Control, Evaluator, GenerationRecord, RunError};

/// Networks to evaluate: `networks` scored by `evaluator`, network `j`
/// with `streams.stream(j)`.
pub struct Job<'a, E, S: ?Sized> {
    /// The evaluator.
    pub evaluator: &'a E,
    /// The networks.
    pub networks: &'a S,
    /// Their streams.
    pub streams: StreamFamily,
}

/// Evaluates every job in one parallel pass on the current rayon pool: the
/// batches of all jobs ([`Evaluator::batch_size`], as [`crate::evaluate_all`]
/// cuts them) go to whichever thread is free, a worker made per thread and
/// distinct evaluator. Returns each job's fitness (what
/// [`crate::evaluate_all`] gives it alone, bit for bit) or its first error
/// in network order.
pub fn evaluate_jobs<E: Evaluator, S: NetworkSet + ?Sized>(jobs: &[Job<'_, E, S>]) -> Vec<Result<Vec<f64>, RunError>> {
    // Jobs that share an evaluator share its workers.
    let mut distinct: Vec<&E> = Vec::new();
    let ids: Vec<usize> = jobs
        .iter()
        .map(
            |job| match distinct.iter().position(|e| std::ptr::eq(*e, job.evaluator)) {
                Some(id) => id,
                None => {
                    distinct.push(job.evaluator);
                    distinct.len() - 1
                }
            },
        )
        .collect();
    // An evaluator that takes its parts together gets all its jobs in one call.
    let together: Vec<usize> = (0..distinct.len())
        .filter(|&id| distinct[id].takes_parts_together())
        .collect();
    let groups: Vec<Vec<usize>> = together
        .iter()
        .map(|&id| (0..jobs.len()).filter(|&i| ids[i] == id).collect())
        .collect();
    let grouped: Vec<(usize, Result<Vec<f64>, RunError>)> = groups
        .par_iter()
        .with_max_len(1)
        .flat_map_iter(|group| evaluate_group(jobs, group))
        .collect();
    let threads = rayon::current_num_threads();
    let pieces: Vec<(usize, Range<usize>)> = jobs
        .iter()
        .enumerate()
        .filter(|&(i, _)| !together.contains(&ids[i]))
        .flat_map(|(i, job)| {
            let (e, len) = (job.evaluator, job.networks.len());
            let ranges = if e.batch_size() > 1 {
                batch_ranges(len, e.batch_size(), e.narrowest_batch(), threads)
            } else {
                (0..len).map(|j| j..j + 1).collect()
            };
            ranges.into_iter().map(move |range| (i, range))
        })
        .collect();
    let init = || -> Vec<Option<E::Worker>> { distinct.iter().map(|_| None).collect() };
    let evaluate = |workers: &mut Vec<Option<E::Worker>>, (i, range): (usize, Range<usize>)| {
        (i, evaluate_piece(&jobs[i], &mut workers[ids[i]], range))
    };
    // Batches go one per task; single networks in rayon's own splits, so
    // that a costly worker (a physics world) is made a few times per
    // thread, not once per network.
    let results: Vec<(usize, Result<Vec<f64>, RunError>)> = if distinct.iter().any(|e| e.batch_size() > 1) {
        pieces
            .into_par_iter()
            .with_max_len(1)
            .map_init(init, evaluate)
            .collect()
    } else {
        pieces.into_par_iter().map_init(init, evaluate).collect()
    };
    let mut fitness: Vec<Result<Vec<f64>, RunError>> = jobs
        .iter()
        .map(|job| Ok(Vec::with_capacity(job.networks.len())))
        .collect();
    for (i, piece) in grouped.into_iter().chain(results) {
        if let Ok(done) = &mut fitness[i] {
            match piece {
                Ok(values) => done.extend(values),
                Err(e) => fitness[i] = Err(e),
            }
        }
    }
    fitness
}

/// Jobs `group` of `jobs`, which share an evaluator that takes its parts
/// together, in one [`Evaluator::evaluate_parts`] call: each job's fitness
/// or error.
fn evaluate_group<E: Evaluator, S: NetworkSet + ?Sized>(
    jobs: &[Job<'_, E, S>],
    group: &[usize],
) -> Vec<(usize, Result<Vec<f64>, RunError>)> {
    let evaluator = jobs[group[0]].evaluator;
    let mut worker = match evaluator.worker() {
        Ok(worker) => worker,
        Err(e) => {
            let message = format!("{e:#}");
            return group
                .iter()
                .map(|&i| (i, Err(RunError::Worker(anyhow::anyhow!("{message}")))))
                .collect();
        }
    };
    let parts: Vec<Part<'_, S>> = group
        .iter()
        .map(|&i| Part {
            networks: jobs[i].networks,
            range: 0..jobs[i].networks.len(),
            streams: &jobs[i].streams,
        })
        .collect();
    let results = evaluator.evaluate_parts(&mut worker, &parts);
    assert_eq!(results.len(), group.len(), "one result per part");
    group
        .iter()
        .zip(results)
        .map(|(&i, result)| {
            let checked = result
                .map_err(RunError::from)
                .and_then(|fitness| check_fitness(&fitness, 0).map(|()| fitness));
            (i, checked)
        })
        .collect()
}

/// Networks `range` of `job`, with the worker in `slot` (made if absent).
fn evaluate_piece<E: Evaluator, S: NetworkSet + ?Sized>(
    job: &Job<'_, E, S>,
    slot: &mut Option<E::Worker>,
    range: Range<usize>,
) -> Result<Vec<f64>, RunError> {
    let worker = match slot {
        Some(worker) => worker,
        None => slot.insert(job.evaluator.worker().map_err(RunError::Worker)?),
    };
    let start = range.start;
    let fitness = if job.evaluator.batch_size() > 1 {
        job.evaluator
            .evaluate_batch(worker, job.networks, range, &job.streams)?
    } else {
        range
            .map(|j| {
                job.evaluator
                    .evaluate(worker, &job.networks.network(j), &mut job.streams.stream(j))
            })
            .collect::<anyhow::Result<Vec<f64>>>()?
    };
    check_fitness(&fitness, start)?;
    Ok(fitness)
}

/// Advances `runs` together until each has ended or failed: every round
/// asks each live run for its networks, evaluates them all with
/// [`evaluate_jobs`] (run `i` with `evaluators[i]`), then tells each run
/// its fitness; asking and telling run in parallel too. `on_record(i,
/// record)` sees every record of run `i` as it comes ([`Control::Stop`]
/// stops that run, as a callback of `run` does). Returns each run's error,
/// `None` for one that ended; a failed run leaves the others going.
///
/// # Panics
/// If `evaluators` and `runs` differ in length.
pub fn run_together<R: AskTell + Send, E: Evaluator>(
    runs: &mut [R],
    evaluators: &[&E],
    on_record: impl Fn(usize, &GenerationRecord) -> Control + Sync,
) -> Vec<Option<RunError>> {
    run_together_with(runs, evaluators, on_record, |_, _| {})
}

/// [`run_together`], calling `after_round(round, runs)` after every round
/// (from 1) with all the runs as they stand: the place to save them
/// (serde: [`AnyRun`](crate::AnyRun), [`EspRun`](crate::EspRun)), so that
/// runs killed with their process resume, restored, where the last save
/// left them, each still bit-identical to its own run.
///
/// # Panics
/// If `evaluators` and `runs` differ in length.
pub fn run_together_with<R: AskTell + Send, E: Evaluator>(
    runs: &mut [R],
    evaluators: &[&E],
    on_record: impl Fn(usize, &GenerationRecord) -> Control + Sync,
    mut after_round: impl FnMut(usize, &[R]),
) -> Vec<Option<RunError>> {
    assert_eq!(runs.len(), evaluators.len(), "one evaluator per run");
    let mut failed: Vec<Option<RunError>> = runs.iter().map(|_| None).collect();
    let mut live: Vec<bool> = vec![true; runs.len()];
    let mut round = 0;
    while live.iter().any(|&l| l) {
        round += 1;
        let asked: Vec<_> = runs
            .par_iter_mut()
            .zip(&live)
            .map(|(run, &live)| if live { Some(run.ask()) } else { None })
            .collect();
        let mut owners = Vec::new();
        let mut jobs = Vec::new();
        let mut tickets = vec![None; live.len()];
        for (i, asked) in asked.iter().enumerate() {
            match asked {
                Some(Ok(Some(asked))) => {
                    owners.push(i);
                    tickets[i] = Some(asked.ticket());
                    jobs.push(Job {
                        evaluator: evaluators[i],
                        networks: asked,
                        streams: asked.streams(),
                    });
                }
                Some(Ok(None)) | None => live[i] = false,
                Some(Err(_)) => {}
            }
        }
        let mut fitness: Vec<Option<Result<Vec<f64>, RunError>>> = live.iter().map(|_| None).collect();
        for (i, result) in owners.into_iter().zip(evaluate_jobs(&jobs)) {
            fitness[i] = Some(result);
        }
        drop(jobs);
        for (i, asked) in asked.into_iter().enumerate() {
            if let Some(Err(e)) = asked {
                failed[i] = Some(e);
                live[i] = false;
            }
        }
        let told: Vec<Option<RunError>> = runs
            .par_iter_mut()
            .zip(fitness.into_par_iter().zip(tickets))
            .enumerate()
            .map(|(i, (run, (fitness, ticket)))| {
                let (fitness, ticket) = (fitness?, ticket?);
                let result = fitness.and_then(|fitness| run.tell(ticket, &fitness).map(|record| record.cloned()));
                match result {
                    Ok(Some(record)) => {
                        if on_record(i, &record) == Control::Stop {
                            run.stop();
                        }
                        None
                    }
                    Ok(None) => None,
                    Err(e) => Some(e),
                }
            })
            .collect();
        for (i, error) in told.into_iter().enumerate() {
            if let Some(e) = error {
                failed[i] = Some(e);
                live[i] = false;
            }
        }
        after_round(round, runs);
    }
    failed
}
