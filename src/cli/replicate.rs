//! `psa-esp replicate`: the paper's experiment grid.

use std::path::PathBuf;
use std::sync::Mutex;

use anyhow::Result;

use super::evolve::progress_bar;
use crate::evolution::MAX_GENERATIONS;
use crate::experiment::grid::{GridPreset, GridSpec, MAX_SEEDS};
use crate::experiment::replicate::{describe, replicate, FinishedRun, GridProgress};
use crate::experiment::GridConfig;
use crate::ode::MAX_THREADS;
use crate::physics::BackendKind;
use crate::psa::limits::MAX_TRIALS;
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
    /// Seeds per configuration and task (seeds 1..=N, at most 10,000).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_SEEDS))]
    pub seeds: Option<u64>,
    /// Generations (ESP) or cycles (hill-climber) per run (at most 1,000,000).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_GENERATIONS as u64))]
    pub generations: Option<u64>,
    /// Physics backend.
    #[arg(long, value_enum)]
    pub backend: Option<BackendKind>,
    /// Fly every champion again on ode after its run on native: its fitness
    /// and robustness results must be bit-identical, recorded in run.json
    /// (default: on for --preset paper on native).
    #[arg(long, overrides_with = "no_ode_check")]
    pub ode_check: bool,
    /// Skip the ODE check of --ode-check.
    #[arg(long, overrides_with = "ode_check")]
    pub no_ode_check: bool,
    /// Trials of each robustness test (at most 1,000,000).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_TRIALS))]
    pub robustness_trials: Option<u64>,
    /// A TOML file of settings laid over every configuration of the grid
    /// (before each configuration's own change); recorded in grid.json.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Worker threads (0 = one per core; at most 1024). Results do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=MAX_THREADS as u64))]
    pub jobs: u64,
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
        spec.generations = self.generations.map_or(spec.generations, |g| g as usize);
        spec.backend = self.backend.unwrap_or(spec.backend);
        spec.robustness_trials = self.robustness_trials.map_or(spec.robustness_trials, |t| t as usize);
        spec.ode_check = match (self.ode_check, self.no_ode_check) {
            (true, _) => true,
            (_, true) => false,
            _ => self.preset == GridPreset::Paper && spec.backend == BackendKind::Native,
        };
        Ok(spec)
    }
}

/// The text of a `--config` file, checked to be a valid overlay of the baseline.
pub fn read_overrides(path: &std::path::Path) -> Result<String> {
    use anyhow::Context;
    let text = crate::io::read_input(path, "configuration")?;
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
    let summary = replicate(&args.out, &spec, args.grid.jobs as usize, &progress)?;
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
