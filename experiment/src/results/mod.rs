//! The results model: what a finished run's files hold, read and written
//! by the same types. [`EvolveOutcome`] is `run.json`; [`RunData`] is a
//! finished run as the report and `runs.csv` see it (its `run.json`, its
//! robustness tests and its `records.csv`). Beside it, [`runs_table`]
//! (`runs.csv`), [`columns`] (the column tables of the CSV files) and
//! [`stats`] (Welch's test and the other statistics).

pub mod columns;
pub mod runs_table;
pub mod stats;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use crate::champion::robustness::Robustness;
use crate::grid::{RunKey, FINISHED_MARKER};
use crate::RunFiles;
use psa_sim::io::write_atomic;
use psa_sim::psa::Task;

/// What `run.json` holds: written by [`crate::run_evolution`] (and the ODE
/// check), read by the report, by this one type.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvolveOutcome {
    /// The task.
    pub task: Task,
    /// The seed (written as a string: see [`psa_sim::io::u64_string`]).
    #[serde(with = "psa_sim::io::u64_string")]
    pub seed: u64,
    /// A label for the configuration (the preset's name).
    pub label: String,
    /// The physics backend.
    pub backend: psa_sim::physics::BackendKind,
    /// The champion's fitness (% of the theoretical maximum).
    pub champion_fitness: f64,
    /// The generation (cycle) it was found in.
    pub champion_generation: usize,
    /// Generations (cycles) run.
    pub generations: usize,
    /// Network evaluations used, lesion tests included.
    pub evaluations: u64,
    /// Burst mutations.
    pub bursts: usize,
    /// Hidden neurons of the champion.
    pub champion_hidden: usize,
    /// Tool version, git commit, libode version.
    pub build: psa_sim::provenance::BuildInfo,
    /// Start time (RFC 3339).
    pub started: String,
    /// End time (RFC 3339).
    pub finished: String,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// The ODE check of a grid run on `native` (see
    /// [`crate::champion::ode_check`]), added once the check ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ode_check: Option<crate::champion::ode_check::OdeCheck>,
}

impl EvolveOutcome {
    /// Writes the outcome to `path` (a run's `run.json`) atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let mut json = serde_json::to_string_pretty(self)?;
        json.push('\n');
        write_atomic(path, json.as_bytes())
    }

    /// Reads the `run.json` at `path`; fails naming the file where it is
    /// damaged (it does not parse as this type).
    pub fn load(path: &Path) -> Result<EvolveOutcome> {
        let text = psa_sim::io::read_input(path, "run file")?;
        serde_json::from_str(&text).with_context(|| format!("{}: damaged file", path.display()))
    }

    /// The `build` of the `run.json` at `path`, whatever build wrote it: a
    /// file of an earlier build need not parse as this one's type, and
    /// its `build` is what says which defaults it ran under. `None` where
    /// the file is missing, damaged or names no build.
    pub fn build_of(path: &Path) -> Option<serde_json::Value> {
        psa_sim::io::read_input_text(path)
            .ok()
            .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
            .and_then(|run| run.get("build").cloned())
    }
}

/// One generation of `records.csv` (the columns the report uses), fitness in %.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenerationRow {
    /// Generation (cycle), from 1.
    pub generation: usize,
    /// Worst network of the generation.
    pub min: f64,
    /// Mean network of the generation.
    pub mean: f64,
    /// Best network of the generation.
    pub max: f64,
    /// Best network so far (the champion).
    pub champion: f64,
}

/// A finished run whose files all parse.
#[derive(Debug, Clone)]
pub struct RunData {
    /// The run.
    pub key: RunKey,
    /// Its `run.json`.
    pub summary: EvolveOutcome,
    /// The robustness tests of its champion.
    pub robustness: Robustness,
    /// One row per generation.
    pub records: Vec<GenerationRow>,
}

/// Reads the files of a finished run.
pub fn load_run(folder: &Path, key: &RunKey) -> Result<RunData> {
    let read = |name: &str| -> Result<(PathBuf, String)> {
        let path = folder.join(name);
        let text = psa_sim::io::read_input(&path, "run file")?;
        Ok((path, text))
    };
    let path = folder.join(RunFiles::SUMMARY);
    let summary = EvolveOutcome::load(&path)?;
    if summary.task != key.task || !summary.champion_fitness.is_finite() {
        bail!(
            "{}: task {} and champion fitness {} do not fit the run of task {}",
            path.display(),
            summary.task,
            summary.champion_fitness,
            key.task
        );
    }
    let (path, text) = read(FINISHED_MARKER)?;
    let robustness: Robustness =
        serde_json::from_str(&text).with_context(|| format!("{}: damaged file", path.display()))?;
    let (path, text) = read(RunFiles::RECORDS)?;
    let records = parse_records(&text).with_context(|| format!("{}: damaged file", path.display()))?;
    Ok(RunData {
        key: *key,
        summary,
        robustness,
        records,
    })
}

/// Parses `records.csv` by its header's column names.
pub fn parse_records(text: &str) -> Result<Vec<GenerationRow>> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().context("empty file")?.split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .with_context(|| format!("no column {name:?} in the header"))
    };
    let [g, min, mean, max, champion] = ["generation", "min", "mean", "max", "champion"].map(column);
    let (g, min, mean, max, champion) = (g?, min?, mean?, max?, champion?);
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let fields: Vec<&str> = line.split(',').collect();
        let number = |c: usize| -> Result<f64> {
            let field = fields.get(c).copied().unwrap_or("");
            let v: f64 = field
                .parse()
                .with_context(|| format!("line {}: {:?} is not a number", i + 2, field))?;
            if !v.is_finite() {
                bail!("line {}: {v} is not finite", i + 2);
            }
            Ok(v)
        };
        rows.push(GenerationRow {
            generation: number(g)? as usize,
            min: number(min)?,
            mean: number(mean)?,
            max: number(max)?,
            champion: number(champion)?,
        });
    }
    if rows.is_empty() {
        bail!("no generations");
    }
    Ok(rows)
}
