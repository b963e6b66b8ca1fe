//! The replication grid on disk: its definition (`grid.json`), one folder
//! per (configuration, task, seed) run, and how a folder is judged
//! finished, missing or damaged.
//!
//! ```text
//! DIR/grid.json
//! DIR/runs/<config>/task<T>/seed<S>/config.toml     resolved configuration (written first)
//!                                   records.csv     one row per generation
//!                                   champion.json   the champion network
//!                                   run.json        results and provenance
//!                                   robustness.json the robustness tests (written last: the run is finished)
//!                                   claim.json      while a process runs it (see `claim`)
//! ```

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use super::{GridConfig, RunConfig};
use crate::physics::BackendKind;
use crate::psa::Task;

/// The `format` of `grid.json`.
pub const GRID_FORMAT: &str = "psa-esp-grid";
/// Its version.
pub const GRID_VERSION: u32 = 1;

/// The most seeds per configuration and task (the paper: 30).
pub const MAX_SEEDS: u64 = 10_000;

/// Which protocol a grid follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GridPreset {
    /// A reduced grid that finishes in about a minute on 2 cores.
    Quick,
    /// The paper's full protocol: 2000 generations, 30 seeds, 500-trial
    /// robustness tests, on the `native` backend.
    Paper,
}

impl GridPreset {
    /// Every preset.
    pub const ALL: [GridPreset; 2] = [GridPreset::Quick, GridPreset::Paper];

    /// The preset's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            GridPreset::Quick => "quick",
            GridPreset::Paper => "paper",
        }
    }
}

/// A grid's definition, written to `grid.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Always [`GRID_FORMAT`].
    pub format: String,
    /// Always [`GRID_VERSION`].
    pub version: u32,
    /// The preset the grid started from.
    pub preset: GridPreset,
    /// The configurations.
    pub configs: Vec<GridConfig>,
    /// The tasks.
    pub tasks: Vec<Task>,
    /// Seeds 1..=seeds.
    pub seeds: u64,
    /// Generations (ESP) or cycles (hill-climber) per run.
    pub generations: usize,
    /// Physics backend.
    pub backend: BackendKind,
    /// Trials of each robustness test.
    pub robustness_trials: usize,
    /// Whether every champion is flown again on `ode` after its run, where
    /// its fitness and robustness results must be bit-identical (grids on
    /// `native` only; see [`super::ode_check`]). On by default for the
    /// paper preset on `native`.
    #[serde(default)]
    pub ode_check: bool,
    /// Settings laid over every configuration of the grid before its own
    /// change (a TOML document, as `--config` files are written).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overrides: Option<String>,
    /// Settings laid over every run's configuration for its champion's
    /// robustness tests and reported score only, not its evolution (a TOML
    /// document): a grid re-scored by `psa-esp rescore`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rescoring: Option<String>,
}

/// The folder status of one run.
#[derive(Debug, Clone, PartialEq)]
pub enum RunStatus {
    /// Not started (no folder).
    Missing,
    /// Started but not finished (killed): it will be run again.
    Unfinished,
    /// Finished: every file present.
    Finished,
}

/// One (configuration, task, seed) cell of the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RunKey {
    /// The configuration.
    pub config: GridConfig,
    /// The task.
    pub task: Task,
    /// The seed.
    pub seed: u64,
}

impl GridSpec {
    /// The definition of `preset` (all configurations and tasks).
    pub fn from_preset(preset: GridPreset) -> GridSpec {
        let (seeds, generations, backend, robustness_trials) = match preset {
            GridPreset::Quick => (5, 80, BackendKind::Native, 100),
            // `native`: the same model as ODE at a fraction of the cost (`--backend ode` for ODE).
            GridPreset::Paper => (30, 2000, BackendKind::Native, 500),
        };
        GridSpec {
            format: GRID_FORMAT.into(),
            version: GRID_VERSION,
            preset,
            configs: GridConfig::ALL.into_iter().filter(|c| c.in_paper()).collect(),
            tasks: Task::ALL.into_iter().filter(|t| t.in_paper()).collect(),
            seeds,
            generations,
            backend,
            robustness_trials,
            ode_check: preset == GridPreset::Paper && backend == BackendKind::Native,
            overrides: None,
            rescoring: None,
        }
    }

    /// Whether this grid is smaller than the paper's protocol.
    pub fn is_reduced(&self) -> bool {
        let paper = GridSpec::from_preset(GridPreset::Paper);
        self.seeds < paper.seeds
            || self.generations < paper.generations
            || self.robustness_trials < paper.robustness_trials
            || paper.configs.iter().any(|c| !self.configs.contains(c))
            || paper.tasks.iter().any(|t| !self.tasks.contains(t))
    }

    /// Rejects an empty or impossible grid.
    pub fn validate(&self) -> Result<()> {
        if self.configs.is_empty() || self.tasks.is_empty() {
            bail!("the grid needs at least one configuration and one task");
        }
        let max_generations = crate::evolution::MAX_GENERATIONS;
        let max_trials = crate::psa::limits::MAX_TRIALS;
        for (name, value, max) in [
            ("seeds", self.seeds, MAX_SEEDS),
            ("generations", self.generations as u64, max_generations as u64),
            ("robustness_trials", self.robustness_trials as u64, max_trials),
        ] {
            if !(1..=max).contains(&value) {
                bail!("{name} must be in [1, {max}], got {value}");
            }
        }
        if !self.backend.is_available() {
            bail!("backend {} is not available in this build", self.backend);
        }
        if self.ode_check && self.backend != BackendKind::Native {
            bail!(
                "the ODE check flies champions evolved on native again on ode; this grid runs on {} (use --backend native or --no-ode-check)",
                self.backend
            );
        }
        for &config in &self.configs {
            self.run_config(config)?;
        }
        Ok(())
    }

    /// Every run of the grid, in a fixed order (configuration, task, seed).
    pub fn runs(&self) -> Vec<RunKey> {
        let mut runs = Vec::new();
        for &config in &self.configs {
            for &task in &self.tasks {
                if !config.applies_to(task) {
                    continue;
                }
                for seed in 1..=self.seeds {
                    runs.push(RunKey { config, task, seed });
                }
            }
        }
        runs
    }

    /// The full configuration a run of `config` uses in this grid.
    pub fn run_config(&self, config: GridConfig) -> Result<RunConfig> {
        let base = match &self.overrides {
            Some(text) => RunConfig::baseline_with(text).context("the grid's configuration overrides")?,
            None => RunConfig::default(),
        };
        let mut c = config.apply(base);
        c.esp.generations = self.generations;
        c.hill_climb.cycles = self.generations;
        c.problem.backend = self.backend;
        c.validate()
            .with_context(|| format!("configuration {config} with the grid's overrides"))?;
        Ok(c)
    }

    /// The configuration `config`'s champions are tested and scored with:
    /// [`GridSpec::run_config`] with the grid's rescoring laid over it.
    pub fn scoring_config(&self, config: GridConfig) -> Result<RunConfig> {
        let run = self.run_config(config)?;
        match &self.rescoring {
            Some(text) => run
                .with_overrides(text)
                .with_context(|| format!("configuration {config} with the grid's rescoring")),
            None => Ok(run),
        }
    }

    /// Reads `DIR/grid.json`, checking its format and version.
    pub fn load(dir: &Path) -> Result<GridSpec> {
        let path = grid_file(dir);
        let spec: GridSpec = crate::io::read_versioned_json(&path, GRID_FORMAT, GRID_VERSION, "grid")?;
        spec.validate().with_context(|| format!("{}", path.display()))?;
        Ok(spec)
    }

    /// Writes `DIR/grid.json` atomically.
    pub fn save(&self, dir: &Path) -> Result<()> {
        crate::io::write_json(&grid_file(dir), self)
    }
}

/// `DIR/grid.json`.
pub fn grid_file(dir: &Path) -> PathBuf {
    dir.join("grid.json")
}

/// The folder of one run.
pub fn run_dir(dir: &Path, key: &RunKey) -> PathBuf {
    dir.join("runs")
        .join(key.config.name())
        .join(format!("task{}", key.task))
        .join(format!("seed{}", key.seed))
}

/// The file whose presence marks a run finished (written last).
pub const FINISHED_MARKER: &str = "robustness.json";

/// Judges a run folder: missing, unfinished (to be run again), finished,
/// or an error naming the folder when it holds another configuration or a
/// damaged file.
pub fn run_status(dir: &Path, spec: &GridSpec, key: &RunKey) -> Result<RunStatus> {
    let folder = run_dir(dir, key);
    if !folder.exists() {
        return Ok(RunStatus::Missing);
    }
    let config_path = folder.join("config.toml");
    if !config_path.exists() {
        // Killed before its first file: nothing of value in it.
        return Ok(RunStatus::Unfinished);
    }
    let text = crate::io::read_input(&config_path, "run configuration")?;
    let expected = spec.run_config(key.config)?;
    let found = RunConfig::default()
        .with_overrides(&text)
        .with_context(|| format!("{}: damaged configuration", config_path.display()))?;
    if found != expected {
        bail!(
            "{}: holds a different configuration than {} in this grid (another grid's run?); move it away or use another output directory",
            folder.display(),
            key.config
        );
    }
    if !folder.join(FINISHED_MARKER).exists() {
        return Ok(RunStatus::Unfinished);
    }
    for name in ["records.csv", "champion.json", "run.json"] {
        if !folder.join(name).exists() {
            bail!(
                "{}: finished run without {name}: the folder is damaged",
                folder.display()
            );
        }
    }
    check_finished_files(&folder, spec)?;
    Ok(RunStatus::Finished)
}

/// Parses the files of a finished run, so that a damaged one is never
/// counted: the robustness results, the summary, the champion, and a record
/// per generation.
fn check_finished_files(folder: &Path, spec: &GridSpec) -> Result<()> {
    let read = |name: &str| -> Result<String> {
        let path = folder.join(name);
        crate::io::read_input(&path, "run file")
    };
    let damaged = |name: &str| format!("{}: damaged file", folder.join(name).display());
    serde_json::from_str::<super::robustness::Robustness>(&read(FINISHED_MARKER)?)
        .with_context(|| damaged(FINISHED_MARKER))?;
    let summary: serde_json::Value = serde_json::from_str(&read("run.json")?).with_context(|| damaged("run.json"))?;
    if !summary.get("champion_fitness").is_some_and(|f| f.is_number()) {
        bail!("{}: no champion_fitness", damaged("run.json"));
    }
    crate::psa::NetworkFile::load(&folder.join("champion.json"))?;
    let rows = read("records.csv")?.lines().count();
    if rows != spec.generations + 1 {
        bail!(
            "{}: {} rows, expected a header and {} generations",
            damaged("records.csv"),
            rows,
            spec.generations
        );
    }
    Ok(())
}
