//! The lockstep grid executor: every run of a grid (or of what is left of
//! it) advanced together, one round per generation, each round's networks
//! of all runs evaluated in one batch (the search crate's [`lockstep`]).
//! Each run is the run it is on its own, bit for bit: its files are
//! byte-identical to those of the run-by-run executor (run.json's times
//! aside).

use std::path::Path;
use std::sync::Mutex;

use anyhow::{Context, Result};
use rayon::prelude::*;

use super::grid::{run_dir, GridSpec, RunKey};
use super::grid_run::{run_seed, test_and_mark, FinishedRun};
use super::{Algorithm, GridConfig, RunConfig, RunStart};
use crate::evaluator::{EvalPath, PsaEvaluator};
use crate::evolution::lockstep::lockstep;
use crate::evolution::{AskTell, Control, Esp, HillClimb};
use crate::psa::Task;

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
    /// (a grid's runs, of equal length, end at the same round), so a grid
    /// killed before then resumes from its last finished runs.
    Lockstep,
}

/// A run started on disk, ready to be driven.
struct Started {
    key: RunKey,
    config: RunConfig,
    seed: u64,
    start: RunStart,
    /// Its evaluator's index.
    evaluator: usize,
}

/// Runs `todo` of `spec` in `dir` in lockstep on the current rayon pool,
/// their networks evaluated on `path`, handing each run's outcome to
/// `finished` as [`crate::grid_run::run_one`] would give it.
pub(super) fn replicate_lockstep(
    dir: &Path,
    spec: &GridSpec,
    todo: &[RunKey],
    path: &EvalPath,
    finished: &(dyn Fn(Result<FinishedRun>) + Sync),
) {
    let mut evaluators: Vec<((GridConfig, Task), PsaEvaluator)> = Vec::new();
    let mut started = Vec::new();
    let mut runs: Vec<Box<dyn AskTell + Send>> = Vec::new();
    for key in todo {
        let folder = run_dir(dir, key);
        match begin(spec, key, &folder, path, &mut evaluators) {
            Ok((run, search)) => {
                started.push(run);
                runs.push(search);
            }
            Err(e) => finished(Err(e.context(format!("run {}", folder.display())))),
        }
    }
    let which: Vec<&PsaEvaluator> = started.iter().map(|s| &evaluators[s.evaluator].1).collect();
    let live: Vec<Mutex<&mut RunStart>> = started.iter_mut().map(|s| Mutex::new(&mut s.start)).collect();
    let errors = lockstep(&mut runs, &which, |run, record| {
        live[run]
            .lock()
            .expect("no panics while holding the lock")
            .record(record);
        Control::Continue
    });
    drop(live);
    started
        .into_par_iter()
        .zip(runs)
        .zip(errors)
        .with_max_len(1)
        .for_each(|((run, search), error)| {
            let folder = run_dir(dir, &run.key);
            let outcome = match error {
                Some(e) => Err(e.into()),
                None => search.result().map_err(anyhow::Error::from).and_then(|result| {
                    run.start
                        .finish(&run.config, run.key.config.name(), run.key.task, run.seed, &result)
                }),
            };
            finished(
                outcome
                    .with_context(|| format!("run {}", folder.display()))
                    .and_then(|outcome| test_and_mark(dir, spec, &run.key, outcome)),
            );
        });
}

/// Starts run `key` in `folder` (its `config.toml`, as the run-by-run
/// executor writes it) and its search; finds or makes its evaluator.
fn begin(
    spec: &GridSpec,
    key: &RunKey,
    folder: &Path,
    path: &EvalPath,
    evaluators: &mut Vec<((GridConfig, Task), PsaEvaluator)>,
) -> Result<(Started, Box<dyn AskTell + Send>)> {
    let config = spec.run_config(key.config)?;
    let seed = run_seed(key);
    let start = RunStart::new(&config, folder)?;
    let cell = (key.config, key.task);
    let evaluator = match evaluators.iter().position(|(c, _)| *c == cell) {
        Some(index) => index,
        None => {
            evaluators.push((cell, PsaEvaluator::new(config.problem.clone(), key.task, path)?));
            evaluators.len() - 1
        }
    };
    let (inputs, outputs) = {
        use crate::evolution::Evaluator;
        let e = &evaluators[evaluator].1;
        (e.inputs(), e.outputs())
    };
    let search: Box<dyn AskTell + Send> = match config.algorithm {
        Algorithm::Esp => Box::new(
            Esp::new(config.esp.clone(), seed)
                .map_err(anyhow::Error::msg)?
                .start(inputs, outputs)?,
        ),
        Algorithm::HillClimb => Box::new(
            HillClimb::new(config.hill_climb.clone(), seed)
                .map_err(anyhow::Error::msg)?
                .start(inputs, outputs)?,
        ),
    };
    Ok((
        Started {
            key: *key,
            config,
            seed,
            start,
            evaluator,
        },
        search,
    ))
}
