//! Running the replication grid: every (configuration, task, seed) as an
//! independent run in its own folder, then its robustness tests; finished
//! runs are skipped, so a killed grid resumes where it stopped. A process
//! may run one shard of the grid ([`Shard`]), and several processes may
//! work on one folder: each claims a run before running it ([`claim`]).

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{bail, Result};
use rayon::prelude::*;

use crate::grid::claim::{claim, Attempt, Claim, ClaimRecord, DEFAULT_CLAIM_TIMEOUT};
use crate::grid::lockstep::{replicate_lockstep, Executor};
use crate::grid::runner::{run_one, FinishedRun};
use crate::grid::shard::Shard;
use crate::grid::{judge_run, run_dir, run_status, GridSpec, Judge, RunKey, RunStatus};
use psa_sim::evaluator::EvalPath;

/// Something to tell the user while the grid runs.
pub trait GridProgress: Sync {
    /// The grid (or this shard of it) has `total` runs, `done` of them
    /// finished before this call.
    fn start(&self, total: usize, done: usize);
    /// A run of the grid in folder `grid` finished.
    fn finished(&self, grid: &Path, run: &FinishedRun);
}

/// How [`replicate`] runs: threads, shard, claims, executor and evaluation
/// path.
#[derive(Debug, Clone)]
pub struct ReplicateOptions {
    /// Worker threads (0 = one per core). Results do not depend on it.
    pub threads: usize,
    /// Which runs of the grid's run order this process does.
    pub shard: Shard,
    /// How old another process's claim on a run may grow before this one
    /// takes it over.
    pub claim_timeout: Duration,
    /// How the runs are advanced: run by run, or all in lockstep. Results
    /// do not depend on it.
    pub executor: Executor,
    /// Where the runs' networks are evaluated. Results do not depend on it.
    pub eval_path: EvalPath,
}

impl Default for ReplicateOptions {
    fn default() -> Self {
        ReplicateOptions {
            threads: 0,
            shard: Shard::ALL,
            claim_timeout: DEFAULT_CLAIM_TIMEOUT,
            executor: Executor::RunByRun,
            eval_path: EvalPath::Fastest,
        }
    }
}

/// A run another live process holds (and this one left to it).
#[derive(Debug, Clone)]
pub struct HeldRun {
    /// The run.
    pub key: RunKey,
    /// Who holds it.
    pub claim: ClaimRecord,
}

/// The summary of [`replicate`].
#[derive(Debug, Clone)]
pub struct ReplicateSummary {
    /// Runs in the grid (or in this shard of it).
    pub total: usize,
    /// Runs that were already finished (by any process).
    pub skipped: usize,
    /// Runs done now by this process.
    pub ran: usize,
    /// Runs other processes were running, left to them.
    pub held: Vec<HeldRun>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Checks `dir` against `spec`: a new directory gets `grid.json` (of
/// processes starting together, exactly one writes it); an existing grid
/// must have the same definition. Returns the runs of `shard` still to do,
/// and how many of its runs are finished.
pub fn prepare(dir: &Path, spec: &GridSpec, shard: Shard, judge: Judge) -> Result<(Vec<RunKey>, usize)> {
    spec.validate()?;
    let grid_file = crate::grid::grid_file(dir);
    // `runs/` first: a grid's run folders appear only after its grid.json.
    if dir.join("runs").exists() && !grid_file.exists() {
        bail!(
            "{} has run folders but no grid.json: not a grid this tool wrote; use another --out",
            dir.display()
        );
    }
    // A new grid is checked whole before its folder or its first run (a
    // re-scored grid's definition is its source's, read as written:
    // `Judge::Read`).
    if !grid_file.exists() && judge == Judge::Resume {
        spec.check_new()?;
    }
    psa_sim::io::create_output_dir(dir)?;
    let mut json = serde_json::to_string_pretty(spec)?;
    json.push('\n');
    if !grid_file.exists() && psa_sim::io::create_new_atomic(&grid_file, json.as_bytes())? {
        // This process wrote grid.json.
    } else {
        let existing = GridSpec::load(dir)?;
        if existing != *spec {
            extend_seeds(dir, &existing, spec)?;
        }
    }
    let mut todo = Vec::new();
    let mut problems = Vec::new();
    let runs = shard.select(&spec.runs());
    psa_sim::io::remove_stale_temporaries(dir);
    for key in &runs {
        let folder = run_dir(dir, key);
        psa_sim::io::remove_stale_temporaries(&folder);
        match judge_run(dir, spec, key, judge) {
            Ok(RunStatus::Finished) => {
                // What a killed process left in a finished run.
                crate::grid::claim::clear_stale(&folder, DEFAULT_CLAIM_TIMEOUT)?;
                crate::grid::checkpoint::remove_checkpoint(&folder)?;
            }
            Ok(RunStatus::Missing | RunStatus::Unfinished) => todo.push(*key),
            Err(e) => problems.push(format!("{e:#}")),
        }
    }
    if !problems.is_empty() {
        bail!(
            "{} run folder(s) cannot be resumed safely and were left untouched:\n  {}",
            problems.len(),
            problems.join("\n  ")
        );
    }
    let done = runs.len() - todo.len();
    Ok((todo, done))
}

/// A one-line description of a grid.
pub fn describe(spec: &GridSpec) -> String {
    let configs: Vec<&str> = spec.configs.iter().map(|c| c.name()).collect();
    let tasks: Vec<String> = spec.tasks.iter().map(|t| t.to_string()).collect();
    format!(
        "configs {}, tasks {}, seeds {}, {} generations, backend {}{}, {} robustness trials",
        configs.join(","),
        tasks.join(","),
        spec.seeds_label(),
        spec.generations,
        spec.backend,
        if spec.ode_check {
            " (every champion checked on ode)"
        } else {
            ""
        },
        spec.robustness_trials
    )
}

/// A grid `spec` that differs from the `existing` one in `dir` only in its
/// seeds: a range inside the existing one resumes those runs; a range
/// that starts right after it extends the grid (grid.json rewritten with
/// the two ranges joined), so that adding seeds to a finished grid is one
/// command (`--first-seed 31 --seeds 30` on a grid of seeds 1 to 30).
/// Anything else is refused: another definition, seeds that overlap the
/// existing ones only in part, or that leave a gap or lie before them (a
/// grid's seeds are one range; a forgotten `--first-seed` never extends a
/// grid backwards).
fn extend_seeds(dir: &Path, existing: &GridSpec, spec: &GridSpec) -> Result<()> {
    let refuse = |why: String| -> Result<()> {
        bail!(
            "{} holds a grid with another definition ({}){why}; resume it with the same options or use another --out",
            dir.display(),
            describe(existing)
        )
    };
    let seeds_only = GridSpec {
        seeds: existing.seeds,
        first_seed: existing.first_seed,
        ..spec.clone()
    };
    if seeds_only != *existing {
        return refuse(String::new());
    }
    let (old, new) = (existing.seed_range(), spec.seed_range());
    if old.contains(new.start()) && old.contains(new.end()) {
        return Ok(());
    }
    let overlaps = new.start() <= old.end() && old.start() <= new.end();
    if overlaps {
        return refuse(format!(
            ": seeds {} clash with its seeds {} (a grid's seeds are one range: extend it with seeds right after or before its own)",
            spec.seeds_label(),
            existing.seeds_label()
        ));
    }
    if old.end().checked_add(1) != Some(*new.start()) {
        return refuse(format!(
            ": seeds {} do not start right after its seeds {} (a grid's seeds are one range, extended at its end: --first-seed {})",
            spec.seeds_label(),
            existing.seeds_label(),
            old.end().saturating_add(1)
        ));
    }
    let joined = GridSpec {
        seeds: existing.seeds + spec.seeds,
        ..existing.clone()
    };
    joined.validate()?;
    joined.save(dir)
}

/// What claiming a run found.
enum Claimed {
    /// The run is this process's (until the claim is dropped), and unfinished.
    Mine(Claim),
    /// Another process finished it first.
    AlreadyFinished,
    /// Another process is running it.
    Held(ClaimRecord),
}

/// Claims the run `key` unless another live process holds it; a run
/// another process finished meanwhile is left alone.
fn claim_unfinished(dir: &Path, spec: &GridSpec, key: &RunKey, timeout: Duration) -> Result<Claimed> {
    let claim = match claim(&run_dir(dir, key), timeout)? {
        Attempt::Held(record) => return Ok(Claimed::Held(record)),
        Attempt::Claimed(claim) => claim,
    };
    if run_status(dir, spec, key)? == RunStatus::Finished {
        return Ok(Claimed::AlreadyFinished);
    }
    Ok(Claimed::Mine(claim))
}

/// Runs every unfinished run of `options.shard` of `spec` in `dir`, on
/// `options.threads` threads, claiming each run first so that other
/// processes on the same folder never run it too. Results do not depend on
/// threads, shards, other processes or interruptions.
pub fn replicate(
    dir: &Path,
    spec: &GridSpec,
    options: &ReplicateOptions,
    progress: &dyn GridProgress,
) -> Result<ReplicateSummary> {
    let job = GridJob {
        dir,
        spec,
        shard: options.shard,
        elsewhere: &[],
    };
    let mut summaries = replicate_grids(&[job], options, progress)?;
    Ok(summaries.remove(0))
}

/// One grid of those [`replicate_grids`] runs together: its folder, its
/// definition and the shard of its run order this process does.
#[derive(Debug, Clone, Copy)]
pub struct GridJob<'a> {
    /// The grid's folder.
    pub dir: &'a Path,
    /// Its definition.
    pub spec: &'a GridSpec,
    /// The runs of it this process does.
    pub shard: Shard,
    /// Runs of it that another grid flies (a sweep's shared runs,
    /// [`crate::grid::shared`]): never run here, written from that grid's.
    pub elsewhere: &'a [RunKey],
}

/// Runs several grids (a sweep's variants) as one, as [`replicate`] runs
/// one (`options.shard` aside: each grid names its own): their unfinished
/// runs share the threads, and with [`Executor::Lockstep`] all of them
/// advance in one pass, each round's networks of every grid evaluated as
/// one batch. Returns each grid's summary, in the order of `grids`; its
/// `seconds` are those of the whole call.
pub fn replicate_grids(
    grids: &[GridJob],
    options: &ReplicateOptions,
    progress: &dyn GridProgress,
) -> Result<Vec<ReplicateSummary>> {
    let clock = Instant::now();
    let mut todo: Vec<(usize, RunKey)> = Vec::new();
    // Per grid: its runs in this shard, and those finished before.
    let mut totals = Vec::new();
    let mut skipped = Vec::new();
    for (grid, job) in grids.iter().enumerate() {
        let (runs, finished) = prepare(job.dir, job.spec, job.shard, Judge::Resume)?;
        let runs: Vec<RunKey> = runs.into_iter().filter(|k| !job.elsewhere.contains(k)).collect();
        totals.push(runs.len() + finished);
        skipped.push(finished);
        todo.extend(runs.into_iter().map(|key| (grid, key)));
    }
    let skipped_in_all: usize = skipped.iter().sum();
    progress.start(todo.len() + skipped_in_all, skipped_in_all);
    let pool = psa_sim::ode::thread_pool(options.threads)?;
    let failures = Mutex::new(Vec::new());
    let held = Mutex::new(Vec::new());
    let counter = || grids.iter().map(|_| AtomicU64::new(0)).collect::<Vec<_>>();
    let (ran, finished_elsewhere) = (counter(), counter());
    let lock = "no panics while holding the lock";
    let finished = |grid: usize, result: Result<FinishedRun>| match result {
        Ok(run) => {
            ran[grid].fetch_add(1, Ordering::Relaxed);
            progress.finished(grids[grid].dir, &run);
        }
        Err(e) => failures.lock().expect(lock).push(format!("{e:#}")),
    };
    // The claim on a run if it is this process's; the other outcomes are
    // counted here.
    let take = |&(grid, key): &(usize, RunKey)| {
        let job = &grids[grid];
        match claim_unfinished(job.dir, job.spec, &key, options.claim_timeout) {
            Ok(Claimed::Mine(claim)) => Some(claim),
            Ok(Claimed::AlreadyFinished) => {
                finished_elsewhere[grid].fetch_add(1, Ordering::Relaxed);
                None
            }
            Ok(Claimed::Held(claim)) => {
                held.lock().expect(lock).push((grid, HeldRun { key, claim }));
                None
            }
            Err(e) => {
                finished(grid, Err(e));
                None
            }
        }
    };
    pool.install(|| match options.executor {
        Executor::RunByRun => todo.par_iter().with_max_len(1).for_each(|run| {
            if let Some(claim) = take(run) {
                let (grid, key) = run;
                let job = &grids[*grid];
                // The claim goes once the run's files are complete.
                let outcome = run_one(job.dir, job.spec, key, &options.eval_path);
                drop(claim);
                finished(*grid, outcome);
            }
        }),
        Executor::Lockstep => {
            // Every run is claimed before the first round and released once
            // all are written.
            let mut claims = Vec::new();
            let mut mine = Vec::new();
            for run in &todo {
                if let Some(claim) = take(run) {
                    claims.push(claim);
                    mine.push(*run);
                }
            }
            let folders: Vec<(&Path, &GridSpec)> = grids.iter().map(|g| (g.dir, g.spec)).collect();
            replicate_lockstep(&folders, &mine, &options.eval_path, &finished);
            drop(claims);
        }
    });
    let failures = failures.into_inner().expect(lock);
    if !failures.is_empty() {
        bail!("{} run(s) failed:\n  {}", failures.len(), failures.join("\n  "));
    }
    let held = held.into_inner().expect(lock);
    let seconds = clock.elapsed().as_secs_f64();
    Ok(grids
        .iter()
        .enumerate()
        .map(|(grid, job)| {
            let order = job.spec.runs();
            let mut mine: Vec<HeldRun> = held
                .iter()
                .filter(|(g, _)| *g == grid)
                .map(|(_, h)| h.clone())
                .collect();
            mine.sort_by_key(|h| order.iter().position(|k| *k == h.key));
            ReplicateSummary {
                total: totals[grid],
                skipped: skipped[grid] + finished_elsewhere[grid].load(Ordering::Relaxed) as usize,
                ran: ran[grid].load(Ordering::Relaxed) as usize,
                held: mine,
                seconds,
            }
        })
        .collect())
}
