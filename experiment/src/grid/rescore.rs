//! Re-scoring a finished grid without re-evolving it: every finished run's
//! champion tested again under other scoring settings (a TOML document laid
//! over each run's configuration for its tests only), into a new grid
//! folder that `psa-esp report` reads like any other.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use rayon::prelude::*;

use crate::grid::replicate::prepare;
use crate::grid::runner::{mark_finished, run_seed, score_champion};
use crate::grid::shard::Shard;
use crate::grid::{judge_run, run_dir, GridSpec, Judge, RunKey, RunStatus};
use crate::models::configuration_table;
use crate::RunFiles;
use psa_sim::evaluator::EvalPath;

/// The files of a run that re-scoring copies unchanged (its evolution).
const EVOLUTION_FILES: [&str; 4] = RunFiles::NAMES;

/// What [`rescore`] did.
#[derive(Debug, Clone)]
pub struct RescoreSummary {
    /// Finished runs of the source grid.
    pub total: usize,
    /// Runs of the source grid not finished (left out).
    pub unfinished: usize,
    /// Runs already re-scored in the output folder (a resumed re-scoring).
    pub skipped: usize,
    /// Runs re-scored now.
    pub ran: usize,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// The re-scored grid's definition: `source`'s with `overlay` laid over its
/// rescoring (a grid re-scored twice keeps both, the later on top), no ODE
/// check, and `trials` robustness trials when given.
pub fn rescored_spec(source: &GridSpec, overlay: &str, trials: Option<usize>) -> Result<GridSpec> {
    let mut table: toml::Table = match &source.rescoring {
        Some(text) => configuration_table(text).context("the source grid's rescoring")?,
        None => toml::Table::new(),
    };
    let added = configuration_table(overlay).context("the rescoring settings")?;
    crate::config::merge(&mut table, added);
    let spec = GridSpec {
        rescoring: Some(toml::to_string(&table)?),
        ode_check: false,
        robustness_trials: trials.unwrap_or(source.robustness_trials),
        ..source.clone()
    };
    spec.validate()?;
    for config in &spec.configs {
        let scoring = spec.scoring_config(*config)?;
        let evolution = spec.run_config(*config)?;
        if scoring.esp != evolution.esp
            || scoring.hill_climb != evolution.hill_climb
            || scoring.algorithm != evolution.algorithm
        {
            bail!("the rescoring settings change the search ({config}); re-scoring can change the problem's settings only");
        }
    }
    Ok(spec)
}

/// Refuses a rescoring setting that changes nothing the robustness tests
/// fly on any run of `source` (input and output noise, random starts and
/// trials are each test's own; the fitness evolved on is not the one
/// scored unless the scoring is `evolution`): its results would be those
/// of the source, marked re-scored. The error names the setting.
/// Each configuration is judged on its first finished run in `dir` (its
/// own configuration: a grid of an earlier build flew that build's
/// defaults), else on the grid's definition.
pub fn check_rescoring_acts(dir: &Path, source: &GridSpec, overlay: &str) -> Result<()> {
    let added = configuration_table(overlay).context("the rescoring settings")?;
    let mut bases = Vec::new();
    for &config in &source.configs {
        let finished = source.runs().into_iter().find(|key| {
            key.config == config && matches!(judge_run(dir, source, key, Judge::Read), Ok(RunStatus::Finished))
        });
        let run = match finished {
            Some(key) => crate::grid::run_folder_config(&run_dir(dir, &key))?,
            None => source.run_config(config)?,
        };
        let scoring = match &source.rescoring {
            Some(text) => run.with_overrides(text)?,
            None => run,
        };
        bases.push((config, scoring));
    }
    check_each_setting_acts(source, &bases, &added)
}

fn check_each_setting_acts(
    source: &GridSpec,
    bases: &[(crate::GridConfig, crate::RunConfig)],
    added: &toml::Table,
) -> Result<()> {
    fn leaves(table: &toml::Table, prefix: &str, out: &mut Vec<(String, toml::Value)>) {
        for (key, value) in table {
            match value {
                toml::Value::Table(inner) => leaves(inner, &format!("{prefix}{key}."), out),
                other => out.push((format!("{prefix}{key}"), other.clone())),
            }
        }
    }
    let mut settings = Vec::new();
    leaves(added, "", &mut settings);
    for (key, value) in settings {
        let alone = format!("{key} = {value}");
        let mut acts = false;
        for (config, before) in bases {
            let config = *config;
            let after = before
                .with_overrides(&alone)
                .with_context(|| format!("the rescoring setting {alone}"))?;
            for &task in source.tasks.iter().filter(|&&t| config.applies_to(t)) {
                let tested = |c: &crate::RunConfig| crate::champion::robustness::tested_settings(&c.problem, task);
                acts |= task.reads_setting(&key) && tested(before)? != tested(&after)?;
            }
        }
        if !acts {
            bail!(
                "the rescoring setting {alone} changes nothing the robustness tests fly on this grid's tasks ({}): a task reads only its own [problem.tasks] keys and [problem.taskN] table; the tests set their own input and output noise, random starts and trials, and score on fitness.scoring (the fitness evolved on only with scoring = \"evolution\")",
                source.tasks.iter().map(|t| t.to_string()).collect::<Vec<_>>().join(", ")
            );
        }
    }
    Ok(())
}

/// Refuses `out` when it is the grid `source` itself.
pub fn check_out(source: &Path, out: &Path) -> Result<()> {
    if std::fs::canonicalize(source).ok() == std::fs::canonicalize(out).ok() {
        bail!(
            "--out {} is the grid being re-scored; re-scoring writes a new grid folder",
            out.display()
        );
    }
    Ok(())
}

/// Re-tests every finished run of the grid in `source` under `spec` (made
/// by [`rescored_spec`]) into `out`, on `threads` threads (0: one per
/// core): each run's evolution files copied, its `robustness.json` written
/// anew, last. Running it again resumes; results do not depend on threads.
pub fn rescore(source: &Path, out: &Path, spec: &GridSpec, threads: usize) -> Result<RescoreSummary> {
    let clock = Instant::now();
    let source_spec = GridSpec::load(source)?;
    check_out(source, out)?;
    let mut finished = Vec::new();
    let mut unfinished = 0;
    for key in source_spec.runs() {
        match judge_run(source, &source_spec, &key, Judge::Read)? {
            RunStatus::Finished => finished.push(key),
            RunStatus::Missing | RunStatus::Unfinished => unfinished += 1,
        }
    }
    let (todo, _) = prepare(out, spec, Shard::ALL, Judge::Read)?;
    let todo: Vec<RunKey> = todo.into_iter().filter(|k| finished.contains(k)).collect();
    let skipped = finished.len() - todo.len();
    let pool = psa_sim::ode::thread_pool(threads)?;
    pool.install(|| {
        todo.par_iter()
            .with_max_len(1)
            .map(|key| rescore_run(source, out, spec, key))
            .collect::<Result<Vec<()>>>()
    })?;
    Ok(RescoreSummary {
        total: finished.len(),
        unfinished,
        skipped,
        ran: todo.len(),
        seconds: clock.elapsed().as_secs_f64(),
    })
}

/// Copies run `key`'s evolution files from `source` into `out` and writes
/// its robustness tests under `spec`'s scoring.
fn rescore_run(source: &Path, out: &Path, spec: &GridSpec, key: &RunKey) -> Result<()> {
    let (from, to) = (run_dir(source, key), run_dir(out, key));
    psa_sim::io::create_output_dir(&to)?;
    for name in EVOLUTION_FILES {
        let text = psa_sim::io::read_input(&from.join(name), "run file")?;
        psa_sim::io::write_atomic(&to.join(name), text.as_bytes())?;
    }
    let (_, _, robustness) = score_champion(&to, spec, key, run_seed(key), &EvalPath::Fastest)
        .with_context(|| format!("re-scoring {}", from.display()))?;
    mark_finished(&to, &robustness)
}
