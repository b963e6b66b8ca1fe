//! Running the replication grid: every (configuration, task, seed) as an
//! independent run in its own folder, then its robustness tests; finished
//! runs are skipped, so a killed grid resumes where it stopped. A process
//! may run one shard of the grid ([`Shard`]), and several processes may
//! work on one folder: each claims a run before running it ([`claim`]).

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use rand::RngExt;
use rayon::prelude::*;

use super::claim::{claim, Attempt, ClaimRecord, DEFAULT_CLAIM_TIMEOUT};
use super::grid::{run_dir, run_status, GridSpec, RunKey, RunStatus, FINISHED_MARKER};
use super::lockstep::{replicate_lockstep, Executor};
use super::ode_check::check_on_ode;
use super::robustness::test_robustness;
use super::shard::Shard;
use super::{run_evolution, EvolveOutcome, RunFiles};
use crate::evaluator::EvalPath;
use crate::psa::NetworkFile;

/// Stream key of the run seeds.
const RUN_SEED: u64 = 201;

/// The seed a run actually uses: derived from the grid seed, the
/// configuration and the task, so that runs of different configurations or
/// tasks are independent samples (Welch's test assumes it). `psa-esp evolve
/// --seed` with this value repeats the run.
pub fn run_seed(key: &RunKey) -> u64 {
    let config_key = key
        .config
        .name()
        .bytes()
        .fold(0u64, |h, b| h.wrapping_mul(131).wrapping_add(b as u64));
    crate::rng::stream(key.seed, &[RUN_SEED, config_key, key.task.number() as u64]).random::<u64>()
}

/// What happened to one run.
#[derive(Debug, Clone)]
pub struct FinishedRun {
    /// The run.
    pub key: RunKey,
    /// Its outcome.
    pub outcome: EvolveOutcome,
}

/// Something to tell the user while the grid runs.
pub trait GridProgress: Sync {
    /// The grid (or this shard of it) has `total` runs, `done` of them
    /// finished before this call.
    fn start(&self, total: usize, done: usize);
    /// A run finished.
    fn finished(&self, run: &FinishedRun);
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
pub fn prepare(dir: &Path, spec: &GridSpec, shard: Shard) -> Result<(Vec<RunKey>, usize)> {
    spec.validate()?;
    let grid_file = super::grid::grid_file(dir);
    // `runs/` first: a grid's run folders appear only after its grid.json.
    if dir.join("runs").exists() && !grid_file.exists() {
        bail!(
            "{} has run folders but no grid.json: not a grid this tool wrote; use another --out",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut json = serde_json::to_string_pretty(spec)?;
    json.push('\n');
    if !grid_file.exists() && crate::io::create_new_atomic(&grid_file, json.as_bytes())? {
        // This process wrote grid.json.
    } else {
        let existing = GridSpec::load(dir)?;
        if existing != *spec {
            bail!(
                "{} holds a grid with another definition ({}); resume it with the same options or use another --out",
                dir.display(),
                describe(&existing)
            );
        }
    }
    let mut todo = Vec::new();
    let mut problems = Vec::new();
    let runs = shard.select(&spec.runs());
    for key in &runs {
        match run_status(dir, spec, key) {
            Ok(RunStatus::Finished) => {}
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
        spec.seeds,
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

/// Runs one run of the grid and its robustness tests, and with
/// `spec.ode_check` flies its champion again on `ode` (recorded in
/// `run.json`; a difference stops the run with an error naming it);
/// `robustness.json`, written last, marks it finished. Its networks are
/// evaluated on `path`.
pub fn run_one(dir: &Path, spec: &GridSpec, key: &RunKey, path: &EvalPath) -> Result<FinishedRun> {
    let folder = run_dir(dir, key);
    let config = spec.run_config(key.config)?;
    let seed = run_seed(key);
    let outcome = run_evolution(&config, key.config.name(), key.task, seed, &folder, path, |_| {})
        .with_context(|| format!("run {}", folder.display()))?;
    test_and_mark(dir, spec, key, outcome)
}

/// A run's robustness tests, once its evolution is written, and its ODE
/// check when `spec.ode_check` (recorded in `run.json`; a difference is an
/// error naming the run); then writes `robustness.json`, which marks it
/// finished.
pub(super) fn test_and_mark(
    dir: &Path,
    spec: &GridSpec,
    key: &RunKey,
    mut outcome: EvolveOutcome,
) -> Result<FinishedRun> {
    let folder = run_dir(dir, key);
    let config = spec.run_config(key.config)?;
    let (_, champion) = NetworkFile::load(&folder.join("champion.json"))?;
    let robustness = test_robustness(
        &champion,
        key.task,
        &config.problem,
        spec.robustness_trials,
        outcome.seed,
    )?;
    if spec.ode_check {
        let check = check_on_ode(
            &champion,
            key.task,
            &config.problem,
            spec.robustness_trials,
            outcome.seed,
            &robustness,
        )
        .with_context(|| format!("run {}: the ODE check", folder.display()))?;
        outcome.ode_check = Some(check.clone());
        outcome.save(&RunFiles::in_dir(&folder).summary)?;
        check.verify(&folder.display().to_string())?;
    }
    let mut json = serde_json::to_string_pretty(&robustness)?;
    json.push('\n');
    crate::io::write_atomic(&folder.join(FINISHED_MARKER), json.as_bytes())?;
    Ok(FinishedRun { key: *key, outcome })
}

/// What became of one run this process went for.
enum Outcome {
    /// This process ran it.
    Ran(FinishedRun),
    /// Another process finished it first.
    AlreadyFinished,
    /// Another process is running it.
    Held(ClaimRecord),
}

/// Claims the run `key` and, unless another process has finished it
/// meanwhile, runs it; the claim goes once its files are complete.
fn claim_and_run(dir: &Path, spec: &GridSpec, key: &RunKey, options: &ReplicateOptions) -> Result<Outcome> {
    let claim = match claim(&run_dir(dir, key), options.claim_timeout)? {
        Attempt::Held(record) => return Ok(Outcome::Held(record)),
        Attempt::Claimed(claim) => claim,
    };
    if run_status(dir, spec, key)? == RunStatus::Finished {
        return Ok(Outcome::AlreadyFinished);
    }
    let run = run_one(dir, spec, key, &options.eval_path)?;
    drop(claim);
    Ok(Outcome::Ran(run))
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
    let clock = Instant::now();
    let (todo, skipped) = prepare(dir, spec, options.shard)?;
    progress.start(todo.len() + skipped, skipped);
    let pool = crate::ode::thread_pool(options.threads)?;
    let failures = Mutex::new(Vec::new());
    let held = Mutex::new(Vec::new());
    let ran = AtomicU64::new(0);
    let finished_elsewhere = AtomicU64::new(0);
    let lock = "no panics while holding the lock";
    let finished = |result: Result<FinishedRun>| match result {
        Ok(run) => {
            ran.fetch_add(1, Ordering::Relaxed);
            progress.finished(&run);
        }
        Err(e) => failures.lock().expect(lock).push(format!("{e:#}")),
    };
    pool.install(|| match options.executor {
        Executor::RunByRun => {
            todo.par_iter()
                .with_max_len(1)
                .for_each(|key| match claim_and_run(dir, spec, key, options) {
                    Ok(Outcome::Ran(run)) => finished(Ok(run)),
                    Ok(Outcome::AlreadyFinished) => {
                        finished_elsewhere.fetch_add(1, Ordering::Relaxed);
                    }
                    Ok(Outcome::Held(claim)) => held.lock().expect(lock).push(HeldRun { key: *key, claim }),
                    Err(e) => finished(Err(e)),
                })
        }
        Executor::Lockstep => {
            // Every run is claimed before the first round and released once
            // all are written.
            let mut claims = Vec::new();
            let mut mine = Vec::new();
            for key in &todo {
                match claim(&run_dir(dir, key), options.claim_timeout) {
                    Ok(Attempt::Held(record)) => held.lock().expect(lock).push(HeldRun {
                        key: *key,
                        claim: record,
                    }),
                    Ok(Attempt::Claimed(claim)) => match run_status(dir, spec, key) {
                        Ok(RunStatus::Finished) => {
                            finished_elsewhere.fetch_add(1, Ordering::Relaxed);
                        }
                        Ok(_) => {
                            claims.push(claim);
                            mine.push(*key);
                        }
                        Err(e) => finished(Err(e)),
                    },
                    Err(e) => finished(Err(e)),
                }
            }
            replicate_lockstep(dir, spec, &mine, &options.eval_path, &finished);
            drop(claims);
        }
    });
    let failures = failures.into_inner().expect(lock);
    if !failures.is_empty() {
        bail!("{} run(s) failed:\n  {}", failures.len(), failures.join("\n  "));
    }
    let mut held = held.into_inner().expect(lock);
    let order = spec.runs();
    held.sort_by_key(|h| order.iter().position(|k| *k == h.key));
    Ok(ReplicateSummary {
        total: todo.len() + skipped,
        skipped: skipped + finished_elsewhere.load(Ordering::Relaxed) as usize,
        ran: ran.load(Ordering::Relaxed) as usize,
        held,
        seconds: clock.elapsed().as_secs_f64(),
    })
}
