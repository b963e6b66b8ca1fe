//! Running the replication grid: every (configuration, task, seed) as an
//! independent run in its own folder, then its robustness tests; finished
//! runs are skipped, so a killed grid resumes where it stopped.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use rand::RngExt;
use rayon::prelude::*;

use super::grid::{run_dir, run_status, GridSpec, RunKey, RunStatus, FINISHED_MARKER};
use super::ode_check::check_on_ode;
use super::robustness::test_robustness;
use super::{run_evolution, EvolveOutcome, RunFiles};
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
    /// The grid has `total` runs, `done` of them finished before this call.
    fn start(&self, total: usize, done: usize);
    /// A run finished.
    fn finished(&self, run: &FinishedRun);
}

/// The summary of [`replicate`].
#[derive(Debug, Clone)]
pub struct ReplicateSummary {
    /// Runs in the grid.
    pub total: usize,
    /// Runs that were already finished.
    pub skipped: usize,
    /// Runs done now.
    pub ran: usize,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Checks `dir` against `spec`: a new directory gets `grid.json`; an
/// existing grid must have the same definition. Returns the runs to do.
pub fn prepare(dir: &Path, spec: &GridSpec) -> Result<(Vec<RunKey>, usize)> {
    spec.validate()?;
    if super::grid::grid_file(dir).exists() {
        let existing = GridSpec::load(dir)?;
        if existing != *spec {
            bail!(
                "{} holds a grid with another definition ({}); resume it with the same options or use another --out",
                dir.display(),
                describe(&existing)
            );
        }
    } else {
        if dir.join("runs").exists() {
            bail!(
                "{} has run folders but no grid.json: not a grid this tool wrote; use another --out",
                dir.display()
            );
        }
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        spec.save(dir)?;
    }
    let mut todo = Vec::new();
    let mut problems = Vec::new();
    let runs = spec.runs();
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
/// `robustness.json`, written last, marks it finished.
pub fn run_one(dir: &Path, spec: &GridSpec, key: &RunKey) -> Result<FinishedRun> {
    let folder = run_dir(dir, key);
    let config = spec.run_config(key.config)?;
    let seed = run_seed(key);
    let mut outcome = run_evolution(&config, key.config.name(), key.task, seed, &folder, |_| {})
        .with_context(|| format!("run {}", folder.display()))?;
    let (_, champion) = NetworkFile::load(&folder.join("champion.json"))?;
    let robustness = test_robustness(&champion, key.task, &config.problem, spec.robustness_trials, seed)?;
    if spec.ode_check {
        let check = check_on_ode(
            &champion,
            key.task,
            &config.problem,
            spec.robustness_trials,
            seed,
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

/// Runs every unfinished run of `spec` in `dir` on `jobs` threads (0 = one
/// per core). Results do not depend on `jobs` or on interruptions.
pub fn replicate(dir: &Path, spec: &GridSpec, jobs: usize, progress: &dyn GridProgress) -> Result<ReplicateSummary> {
    let clock = Instant::now();
    let (todo, skipped) = prepare(dir, spec)?;
    progress.start(todo.len() + skipped, skipped);
    let pool = crate::ode::thread_pool(jobs)?;
    let failures = Mutex::new(Vec::new());
    let ran = AtomicU64::new(0);
    pool.install(|| {
        todo.par_iter()
            .with_max_len(1)
            .for_each(|key| match run_one(dir, spec, key) {
                Ok(run) => {
                    ran.fetch_add(1, Ordering::Relaxed);
                    progress.finished(&run);
                }
                Err(e) => failures
                    .lock()
                    .expect("no panics while holding the lock")
                    .push(format!("{e:#}")),
            })
    });
    let failures = failures.into_inner().expect("no panics while holding the lock");
    if !failures.is_empty() {
        bail!("{} run(s) failed:\n  {}", failures.len(), failures.join("\n  "));
    }
    Ok(ReplicateSummary {
        total: todo.len() + skipped,
        skipped,
        ran: ran.load(Ordering::Relaxed) as usize,
        seconds: clock.elapsed().as_secs_f64(),
    })
}
