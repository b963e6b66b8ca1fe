//! The lockstep grid executor: every run of a grid, or of several grids
//! (a sweep's variants), or of what is left of them, advanced together,
//! one round per generation, each round's networks of all runs evaluated
//! in one batch (the search crate's [`run_together_with`]).
//! Each run is the run it is on its own, bit for bit: its files are
//! byte-identical to those of the run-by-run executor (run.json's times
//! aside). Every `CHECKPOINT_ROUNDS` rounds or more (so that saving takes
//! at most `CHECKPOINT_SHARE` of the time) each unfinished run saves its
//! whole state to its [checkpoint](crate::grid::checkpoint) in its folder; a grid killed and started
//! again resumes each run from there, to the same files.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{Context, Result};
use rayon::prelude::*;

use crate::grid::checkpoint::{check_checkpoint, remove_checkpoint, resume, save_checkpoints, CHECKPOINT};
use crate::grid::runner::{run_seed, test_and_mark, FinishedRun};
use crate::grid::{run_dir, GridSpec, RunKey};
use crate::{Algorithm, GridConfig, RunConfig, RunStart};
use esp_neuroevolution::together::run_together_with;
use esp_neuroevolution::{AnyRun, AskTell, Control, Esp, HillClimb};
use psa_sim::evaluator::{EvalPath, PsaEvaluator};
use psa_sim::psa::Task;

/// Rounds between two checkpoints of the runs at least (a round is a
/// generation, or an ESP lesion test).
const CHECKPOINT_ROUNDS: usize = 20;

/// The share of a grid's time that saving checkpoints may take at most:
/// where rounds are fast (on a GPU), checkpoints are spaced further than
/// [`CHECKPOINT_ROUNDS`] apart, so that a save's time is at most this share
/// of the time since the last one.
const CHECKPOINT_SHARE: f64 = 0.05;

/// How `replicate` and `sweep` advance the runs of a grid. Results do not
/// depend on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Executor {
    /// Each run from start to end on its own, the runs spread over the
    /// threads (a finished run is written at once).
    #[default]
    RunByRun,
    /// All runs together, a generation per round, every round's networks
    /// evaluated as one batch; the runs are written once all have ended
    /// (a grid's runs, of equal length, end at the same round), and saved
    /// every few rounds, so a grid killed before then resumes each run
    /// from its last checkpoint.
    Lockstep,
}

/// A run started on disk, ready to be driven.
struct Started {
    /// Its grid's index.
    grid: usize,
    key: RunKey,
    config: RunConfig,
    seed: u64,
    start: RunStart,
    /// Its evaluator's index.
    evaluator: usize,
}

/// An evaluator of one grid's configuration and task.
type CellEvaluator = ((usize, GridConfig, Task), PsaEvaluator);

/// Runs `todo` (each a run of one of `grids`, a folder and its definition,
/// by index) in lockstep on the current rayon pool, their networks
/// evaluated on `path`: every grid's runs in one pass. Hands each run's
/// outcome to `finished` with its grid's index, as
/// [`crate::grid::runner::run_one`] would give it.
pub(super) fn replicate_lockstep(
    grids: &[(&Path, &GridSpec)],
    todo: &[(usize, RunKey)],
    path: &EvalPath,
    finished: &(dyn Fn(usize, Result<FinishedRun>) + Sync),
) {
    let mut evaluators: Vec<CellEvaluator> = Vec::new();
    let mut started = Vec::new();
    let mut runs: Vec<AnyRun> = Vec::new();
    for &(grid, key) in todo {
        let (dir, spec) = grids[grid];
        let folder = run_dir(dir, &key);
        match begin(spec, grid, &key, &folder, path, &mut evaluators) {
            Ok((run, search)) => {
                started.push(run);
                runs.push(search);
            }
            Err(e) => finished(grid, Err(e.context(format!("run {}", folder.display())))),
        }
    }
    let which: Vec<&PsaEvaluator> = started.iter().map(|s| &evaluators[s.evaluator].1).collect();
    let folders: Vec<PathBuf> = started
        .iter()
        .map(|s| run_dir(grids[s.grid].0, &s.key).join(CHECKPOINT))
        .collect();
    let live: Vec<Mutex<&mut RunStart>> = started.iter_mut().map(|s| Mutex::new(&mut s.start)).collect();
    let on_record = |run: usize, record: &_| {
        live[run]
            .lock()
            .expect("no panics while holding the lock")
            .record(record);
        Control::Continue
    };
    let (mut last_save, mut save_time) = (std::time::Instant::now(), std::time::Duration::ZERO);
    let errors = run_together_with(&mut runs, &which, on_record, |round, runs| {
        if round % CHECKPOINT_ROUNDS == 0
            && save_time.as_secs_f64() <= CHECKPOINT_SHARE * last_save.elapsed().as_secs_f64()
        {
            let start = std::time::Instant::now();
            save_checkpoints(runs, &folders);
            (last_save, save_time) = (std::time::Instant::now(), start.elapsed());
        }
    });
    drop(live);
    started
        .into_par_iter()
        .zip(runs)
        .zip(errors)
        .with_max_len(1)
        .for_each(|((run, search), error)| {
            let (dir, spec) = grids[run.grid];
            let folder = run_dir(dir, &run.key);
            let outcome = match error {
                Some(e) => Err(e.into()),
                None => search.result().map_err(anyhow::Error::from).and_then(|result| {
                    let outcome =
                        run.start
                            .finish(&run.config, run.key.config.name(), run.key.task, run.seed, &result)?;
                    remove_checkpoint(&folder)?;
                    Ok(outcome)
                }),
            };
            finished(
                run.grid,
                outcome
                    .with_context(|| format!("run {}", folder.display()))
                    .and_then(|outcome| test_and_mark(dir, spec, &run.key, outcome, path)),
            );
        });
}

/// Starts run `key` of grid `grid` (of definition `spec`) in `folder` (its
/// `config.toml`, as the run-by-run executor writes it) and its search,
/// resumed from its checkpoint if it has one; finds or makes its evaluator.
fn begin(
    spec: &GridSpec,
    grid: usize,
    key: &RunKey,
    folder: &Path,
    path: &EvalPath,
    evaluators: &mut Vec<CellEvaluator>,
) -> Result<(Started, AnyRun)> {
    check_checkpoint(folder)?;
    let config = spec.run_config(key.config)?;
    let seed = run_seed(key);
    let mut start = RunStart::new(&config, folder)?;
    let cell = (grid, key.config, key.task);
    let evaluator = match evaluators.iter().position(|(c, _)| *c == cell) {
        Some(index) => index,
        None => {
            evaluators.push((cell, PsaEvaluator::new(config.problem.clone(), key.task, path)?));
            evaluators.len() - 1
        }
    };
    let (inputs, outputs) = {
        use esp_neuroevolution::Evaluator;
        let e = &evaluators[evaluator].1;
        (e.inputs(), e.outputs())
    };
    let fresh: AnyRun = match config.algorithm {
        Algorithm::Esp => Esp::new(config.esp.clone(), seed)
            .map_err(anyhow::Error::msg)?
            .start(inputs, outputs)?
            .into(),
        Algorithm::HillClimb => HillClimb::new(config.hill_climb.clone(), seed)
            .map_err(anyhow::Error::msg)?
            .start(inputs, outputs)?
            .into(),
    };
    let search = resume(folder, fresh)?;
    for record in search.records() {
        start.record(record);
    }
    Ok((
        Started {
            grid,
            key: *key,
            config,
            seed,
            start,
            evaluator,
        },
        search,
    ))
}
