//! One run of a grid: the seed it runs with, the run itself and, once its
//! evolution is written, its robustness tests and ODE check and the file
//! that marks it finished. Both executors (run by run in
//! [`crate::grid::replicate`], all together in [`crate::grid::lockstep`]) run their
//! runs through it.

use std::path::Path;

use anyhow::{Context, Result};
use rand::RngExt;

use crate::champion::ode_check::check_on_ode;
use crate::champion::robustness::{test_robustness, Robustness};
use crate::grid::{run_dir, GridSpec, RunKey, FINISHED_MARKER};
use crate::{run_evolution, EvolveOutcome, RunFiles};
use psa_sim::evaluator::EvalPath;
use psa_sim::psa::NetworkFile;

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
    esp_neuroevolution::rng::stream(key.seed, &[RUN_SEED, config_key, key.task.number() as u64]).random::<u64>()
}

/// What happened to one run.
#[derive(Debug, Clone)]
pub struct FinishedRun {
    /// The run.
    pub key: RunKey,
    /// Its outcome.
    pub outcome: EvolveOutcome,
}

/// Runs one run of the grid and its robustness tests, and with
/// `spec.ode_check` flies its champion again on `ode` (recorded in
/// `run.json`; a difference stops the run with an error naming it);
/// `robustness.json`, written last, marks it finished. Its networks are
/// evaluated on `path`.
pub fn run_one(dir: &Path, spec: &GridSpec, key: &RunKey, path: &EvalPath) -> Result<FinishedRun> {
    let folder = run_dir(dir, key);
    crate::grid::checkpoint::check_checkpoint(&folder)?;
    let config = spec.run_config(key.config)?;
    let seed = run_seed(key);
    let outcome = run_evolution(&config, key.config.name(), key.task, seed, &folder, path, |_| {})
        .with_context(|| format!("run {}", folder.display()))?;
    test_and_mark(dir, spec, key, outcome, path)
}

/// A run's robustness tests (their trials on `path`'s kernel where it has
/// one, as [`test_robustness`] says), once its evolution is written, and
/// its ODE check when `spec.ode_check` (recorded in `run.json`; a
/// difference is an error naming the run); then writes `robustness.json`,
/// which marks it finished.
pub(crate) fn test_and_mark(
    dir: &Path,
    spec: &GridSpec,
    key: &RunKey,
    mut outcome: EvolveOutcome,
    path: &EvalPath,
) -> Result<FinishedRun> {
    let folder = run_dir(dir, key);
    let (champion, scoring, robustness) = score_champion(&folder, spec, key, outcome.seed, path)?;
    if spec.ode_check {
        let check = check_on_ode(
            &champion,
            key.task,
            &scoring.problem,
            spec.robustness_trials,
            outcome.seed,
            &robustness,
        )
        .with_context(|| format!("run {}: the ODE check", folder.display()))?;
        outcome.ode_check = Some(check.clone());
        outcome.save(&RunFiles::in_dir(&folder).summary)?;
        check.verify(&folder.display().to_string())?;
    }
    // A checkpoint an earlier lockstep process left (this run ran again
    // from the start, or resumed from it): a finished run holds only its
    // documented files.
    crate::grid::checkpoint::remove_checkpoint(&folder)?;
    mark_finished(&folder, &robustness)?;
    Ok(FinishedRun { key: *key, outcome })
}

/// The robustness tests of the champion in `folder` (run `key` of `spec`,
/// run seed `seed`) under the grid's scoring configuration, on `path`; returns the
/// champion, that configuration and the results.
pub(crate) fn score_champion(
    folder: &Path,
    spec: &GridSpec,
    key: &RunKey,
    seed: u64,
    path: &EvalPath,
) -> Result<(esp_neuroevolution::network::Network, crate::RunConfig, Robustness)> {
    // The run's own configuration (a grid an earlier build wrote is
    // re-scored under the defaults it was evolved with), with the grid's
    // rescoring laid over it.
    let run = crate::grid::run_folder_config(folder)?;
    let scoring = match &spec.rescoring {
        Some(text) => run
            .with_overrides(text)
            .with_context(|| format!("configuration {} with the grid's rescoring", key.config))?,
        None => run,
    };
    let (_, champion) = NetworkFile::load(&RunFiles::in_dir(folder).champion)?;
    let mut robustness = test_robustness(
        &champion,
        key.task,
        &scoring.problem,
        spec.robustness_trials,
        seed,
        path,
    )?;
    robustness.rescored |= spec.rescoring.is_some();
    Ok((champion, scoring, robustness))
}

/// Writes `robustness.json`, the run's last file, which marks it finished.
pub(crate) fn mark_finished(folder: &Path, robustness: &Robustness) -> Result<()> {
    let mut json = serde_json::to_string_pretty(robustness)?;
    json.push('\n');
    psa_sim::io::write_atomic(&folder.join(FINISHED_MARKER), json.as_bytes())
}
