//! One evolution run, written to its own directory.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;

use super::{Algorithm, PsaEvaluator, RunConfig};
use crate::evolution::{Esp, GenerationRecord, HillClimb, RunResult};
use crate::io::write_atomic;
use crate::psa::{NetworkFile, Task};

/// The files of a run directory.
#[derive(Debug, Clone)]
pub struct RunFiles {
    /// The resolved configuration (`config.toml`).
    pub config: PathBuf,
    /// One row per generation (`records.csv`).
    pub records: PathBuf,
    /// The champion network (`champion.json`).
    pub champion: PathBuf,
    /// Task, seed, results, build and times (`run.json`).
    pub summary: PathBuf,
}

impl RunFiles {
    /// The files of the run directory `dir`.
    pub fn in_dir(dir: &Path) -> RunFiles {
        RunFiles {
            config: dir.join("config.toml"),
            records: dir.join("records.csv"),
            champion: dir.join("champion.json"),
            summary: dir.join("run.json"),
        }
    }
}

/// What `run.json` holds.
#[derive(Debug, Clone, Serialize)]
pub struct EvolveOutcome {
    /// The task.
    pub task: Task,
    /// The seed.
    pub seed: u64,
    /// A label for the configuration (the preset's name).
    pub label: String,
    /// The physics backend.
    pub backend: crate::physics::BackendKind,
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
    pub build: crate::provenance::BuildInfo,
    /// Start time (RFC 3339).
    pub started: String,
    /// End time (RFC 3339).
    pub finished: String,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// The ODE check of a grid run on `native` (see
    /// [`super::ode_check`]), added once the check ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ode_check: Option<super::ode_check::OdeCheck>,
}

impl EvolveOutcome {
    /// Writes the outcome to `path` (a run's `run.json`) atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let mut json = serde_json::to_string_pretty(self)?;
        json.push('\n');
        write_atomic(path, json.as_bytes())
    }
}

/// The records as CSV, one row per generation.
pub fn records_csv(records: &[GenerationRecord]) -> String {
    let mut csv = String::from("generation,min,mean,max,best,champion,evaluations,subpops,burst,bursts,lesion\n");
    for r in records {
        let best = r.best.map_or(String::new(), |b| b.to_string());
        let lesion = match r.lesion {
            None => String::new(),
            Some(crate::evolution::LesionOutcome::Add) => "add".into(),
            Some(crate::evolution::LesionOutcome::Remove { neuron }) => format!("remove {neuron}"),
        };
        let _ = writeln!(
            csv,
            "{},{},{},{},{best},{},{},{},{},{},{lesion}",
            r.generation, r.min, r.mean, r.max, r.champion, r.evaluations, r.subpops, r.burst, r.bursts
        );
    }
    csv
}

/// Runs `config` on `task` with `seed` on the current rayon pool and writes
/// `config.toml`, `records.csv`, `champion.json` and `run.json` (each
/// atomically) into `dir`. `on_generation` sees every record as it comes.
pub fn run_evolution(
    config: &RunConfig,
    label: &str,
    task: Task,
    seed: u64,
    dir: &Path,
    on_generation: impl FnMut(&GenerationRecord),
) -> Result<EvolveOutcome> {
    config.validate()?;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create output directory {}", dir.display()))?;
    let files = RunFiles::in_dir(dir);
    write_atomic(&files.config, config.to_toml()?.as_bytes())?;
    let started = crate::provenance::now_rfc3339();
    let clock = Instant::now();
    let evaluator = PsaEvaluator::new(config.problem.clone(), task)?;
    let result: RunResult = match config.algorithm {
        Algorithm::Esp => Esp::new(config.esp.clone(), seed)
            .map_err(anyhow::Error::msg)?
            .run(&evaluator, on_generation)?,
        Algorithm::HillClimb => HillClimb::new(config.hill_climb.clone(), seed)
            .map_err(anyhow::Error::msg)?
            .run(&evaluator, on_generation)?,
    };
    let seconds = clock.elapsed().as_secs_f64();
    write_atomic(&files.records, records_csv(&result.records).as_bytes())?;
    let champion = &result.champion;
    let mut extra = serde_json::Map::new();
    extra.insert("configuration".into(), label.into());
    extra.insert("seed".into(), seed.into());
    extra.insert("fitness_percent".into(), champion.fitness.into());
    extra.insert("generation".into(), champion.generation.into());
    extra.insert("backend".into(), config.problem.backend.name().into());
    NetworkFile::new(&champion.network, task, &config.problem, extra).save(&files.champion)?;
    let last = result.records.last().context("a run has at least one generation")?;
    let outcome = EvolveOutcome {
        task,
        seed,
        label: label.to_string(),
        backend: config.problem.backend,
        champion_fitness: champion.fitness,
        champion_generation: champion.generation,
        generations: result.records.len(),
        evaluations: last.evaluations,
        bursts: last.bursts,
        champion_hidden: champion.network.hidden(),
        build: crate::provenance::build_info(),
        started,
        finished: crate::provenance::now_rfc3339(),
        seconds,
        ode_check: None,
    };
    outcome.save(&files.summary)?;
    Ok(outcome)
}
