//! `psa-esp replicate`: the paper's experiment grid.

use std::path::PathBuf;
use std::sync::Mutex;

use anyhow::Result;

use super::evolve::progress_bar;
use crate::experiment::grid::{GridPreset, GridSpec};
use crate::experiment::replicate::{describe, replicate, FinishedRun, GridProgress};
use crate::experiment::GridConfig;
use crate::physics::BackendKind;
use crate::psa::Task;

/// Arguments of `replicate`.
#[derive(Debug, clap::Args)]
pub struct ReplicateArgs {
    /// The grid.
    #[command(flatten)]
    pub grid: GridArgs,
    /// The grid's directory; running the same command again resumes it.
    #[arg(long)]
    pub out: PathBuf,
}

/// The options that define a grid (shared by `replicate` and `sweep`).
#[derive(Debug, clap::Args)]
pub struct GridArgs {
    /// quick: a reduced grid (5 seeds, 80 generations, 100-trial robustness,
    /// native backend; about a minute on 2 cores); paper: the full protocol
    /// (30 seeds, 2000 generations, 500-trial robustness, ode backend).
    #[arg(long, value_enum, default_value_t = GridPreset::Quick)]
    pub preset: GridPreset,
    /// Configurations, comma-separated (default: all of baseline, systematic,
    /// max-credit, lesion-off, erase-best, hill-climb, gomez, input-noise, random-init).
    #[arg(long, value_delimiter = ',')]
    pub configs: Option<Vec<GridConfig>>,
    /// Tasks, comma-separated (default: 1,2,3).
    #[arg(long, value_delimiter = ',')]
    pub tasks: Option<Vec<Task>>,
    /// Seeds per configuration and task (seeds 1..=N).
    #[arg(long)]
    pub seeds: Option<u64>,
    /// Generations (ESP) or cycles (hill-climber) per run.
    #[arg(long)]
    pub generations: Option<usize>,
    /// Physics backend.
    #[arg(long, value_enum)]
    pub backend: Option<BackendKind>,
    /// Trials of each robustness test.
    #[arg(long)]
    pub robustness_trials: Option<usize>,
    /// A TOML file of settings laid over every configuration of the grid
    /// (before each configuration's own change); recorded in grid.json.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Worker threads (0 = one per core). Results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub jobs: usize,
}

impl GridArgs {
    /// The grid these options describe.
    pub fn spec(&self) -> Result<GridSpec> {
        let mut spec = GridSpec::from_preset(self.preset);
        if let Some(path) = &self.config {
            spec.overrides = Some(read_overrides(path)?);
        }
        if let Some(c) = &self.configs {
            spec.configs = c.clone();
        }
        if let Some(t) = &self.tasks {
            spec.tasks = t.clone();
        }
        spec.seeds = self.seeds.unwrap_or(spec.seeds);
        spec.generations = self.generations.unwrap_or(spec.generations);
        spec.backend = self.backend.unwrap_or(spec.backend);
        spec.robustness_trials = self.robustness_trials.unwrap_or(spec.robustness_trials);
        Ok(spec)
    }
}

/// The text of a `--config` file, checked to be a valid overlay of the baseline.
pub fn read_overrides(path: &std::path::Path) -> Result<String> {
    use anyhow::Context;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read configuration {}", path.display()))?;
    crate::experiment::RunConfig::baseline_with(&text).with_context(|| format!("configuration {}", path.display()))?;
    Ok(text)
}

/// A bar over the whole grid and a line per finished run (both only on a terminal).
pub struct Progress {
    /// The bar.
    pub bar: indicatif::ProgressBar,
    best: Mutex<f64>,
}

impl Default for Progress {
    fn default() -> Self {
        Progress::new()
    }
}

impl Progress {
    /// A bar with no runs yet.
    pub fn new() -> Progress {
        Progress {
            bar: progress_bar(
                0,
                "{spinner} runs {pos}/{len} [{bar:30}] {msg} elapsed {elapsed} ETA {eta}",
            ),
            best: Mutex::new(f64::NEG_INFINITY),
        }
    }
}

impl GridProgress for Progress {
    fn start(&self, total: usize, done: usize) {
        self.bar.set_length(total as u64);
        self.bar.set_position(done as u64);
        self.bar.reset_eta();
    }

    fn finished(&self, run: &FinishedRun) {
        let mut best = self.best.lock().expect("no panics while holding the lock");
        *best = best.max(run.outcome.champion_fitness);
        self.bar.println(format!(
            "finished {} task {} seed {}: champion {:.1} % ({:.0} s)",
            run.key.config, run.key.task, run.key.seed, run.outcome.champion_fitness, run.outcome.seconds
        ));
        self.bar.set_message(format!("best champion {:.1} %", *best));
        self.bar.inc(1);
    }
}

/// Runs `replicate`.
pub fn run(args: ReplicateArgs) -> Result<i32> {
    let spec = args.grid.spec()?;
    let progress = Progress::new();
    let summary = replicate(&args.out, &spec, args.grid.jobs, &progress)?;
    progress.bar.finish_and_clear();
    say!(
        "grid {} ({}): {} runs, {} already finished, {} run now in {:.0} s",
        args.out.display(),
        describe(&spec),
        summary.total,
        summary.skipped,
        summary.ran,
        summary.seconds
    );
    say!("next: psa-esp report {}", args.out.display());
    Ok(0)
}
