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
//!
//! Beside the folder's model, what runs a grid: [`runner`] (one run: its
//! evolution, robustness tests and marks), the executors run by run
//! ([`replicate`]) and in lockstep ([`lockstep`]), [`sweep`] and
//! [`rescore`], and for batch jobs [`shard`] and [`claim`].

pub mod checkpoint;
pub mod claim;
pub mod lockstep;
pub mod replicate;
pub mod rescore;
pub mod runner;
pub mod shard;
pub mod shared;
pub mod sweep;

use std::path::{Path, PathBuf};
use strum::VariantArray;

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use crate::models::configuration_table;
use crate::{EvolveOutcome, GridConfig, RunConfig, RunFiles};
use psa_sim::named::Named;
use psa_sim::physics::BackendKind;
use psa_sim::psa::Task;

/// The `format` of `grid.json`.
pub const GRID_FORMAT: &str = "psa-esp-grid";
/// Its version.
pub const GRID_VERSION: u32 = 1;

/// The settings a grid sets for all its runs, and the option that sets
/// them: a grid's overrides may not set them.
pub const GRID_KEYS: [(&str, &str); 3] = [
    ("problem.backend", "--backend"),
    ("esp.generations", "--generations"),
    ("hill_climb.cycles", "--generations"),
];

/// The most seeds per configuration and task (the paper: 30).
pub const MAX_SEEDS: u64 = 10_000;

/// Which protocol a grid follows.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Serialize,
    Deserialize,
    strum::VariantArray,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum GridPreset {
    /// A reduced grid that finishes in about a minute on 2 cores.
    Quick,
    /// The paper's full protocol: 2000 generations, 30 seeds, 500-trial
    /// robustness tests, on the `native` backend.
    Paper,
}

impl Named for GridPreset {
    const WHAT: &'static str = "grid preset";
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
    /// How many seeds: seeds `first_seed..first_seed + seeds`.
    pub seeds: u64,
    /// The first seed (1 when absent: every grid of an earlier build);
    /// written only when it is not 1, so such a grid.json reads as before.
    #[serde(default = "first_seed_one", skip_serializing_if = "is_first_seed_one")]
    pub first_seed: u64,
    /// Generations (ESP) or cycles (hill-climber) per run.
    pub generations: usize,
    /// Physics backend.
    pub backend: BackendKind,
    /// Trials of each robustness test.
    pub robustness_trials: usize,
    /// Whether every champion is flown again on `ode` after its run, where
    /// its fitness and robustness results must be bit-identical (grids on
    /// `native` only; see [`crate::champion::ode_check`]). On by default for the
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

/// The first seed of a grid that names none.
fn first_seed_one() -> u64 {
    1
}

/// Whether `first_seed` is the one a grid.json may leave out.
fn is_first_seed_one(first_seed: &u64) -> bool {
    *first_seed == 1
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
            configs: GridConfig::all().into_iter().filter(|c| c.in_paper()).collect(),
            tasks: Task::VARIANTS.iter().copied().filter(|t| t.in_paper()).collect(),
            seeds,
            first_seed: 1,
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
        let max_generations = esp_neuroevolution::MAX_GENERATIONS;
        let max_trials = psa_sim::psa::settings::limits::MAX_TRIALS;
        for (name, value, max) in [
            ("seeds", self.seeds, MAX_SEEDS),
            ("generations", self.generations as u64, max_generations as u64),
            ("robustness_trials", self.robustness_trials as u64, max_trials),
        ] {
            if !(1..=max).contains(&value) {
                bail!("{name} must be in [1, {max}], got {value}");
            }
        }
        if self.first_seed == 0 {
            bail!("first_seed must be at least 1 (seeds are numbered from 1), got 0");
        }
        if self.first_seed.checked_add(self.seeds - 1).is_none() {
            bail!(
                "first_seed {} with {} seeds would pass the largest seed, {}",
                self.first_seed,
                self.seeds,
                u64::MAX
            );
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

    /// The checks of a grid about to be written, beyond [`GridSpec::validate`]
    /// (which grids an earlier build wrote must pass to be read): no
    /// configuration or task listed twice (each run would be counted
    /// twice), no setting in the overrides that the grid sets itself (it
    /// would do nothing), and every configuration valid on every task it
    /// runs (random starts on task 2), so that nothing fails after the
    /// first run has started.
    pub fn check_new(&self) -> Result<()> {
        self.validate()?;
        for (text, what) in [(&self.overrides, "configuration"), (&self.rescoring, "rescoring")] {
            let Some(text) = text else { continue };
            let table = configuration_table(text).with_context(|| format!("the grid's {what}"))?;
            for (key, option) in GRID_KEYS {
                let mut parts = key.split('.');
                let (section, name) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
                if table.get(section).and_then(|t| t.get(name)).is_some() {
                    bail!("{key} in the grid's {what}: a grid sets it for all its runs (use {option})");
                }
            }
        }
        // A setting of the grid's own configuration that no task of the
        // grid reads would label runs it does not change.
        if let Some(text) = &self.overrides {
            let base = crate::RunConfig::baseline_with("")?;
            let with = crate::RunConfig::baseline_with(text).context("the grid's configuration")?;
            for (key, value, _) in differences(&with, &base)? {
                if !self.tasks.iter().any(|task| task.reads_setting(&key)) {
                    let tasks: Vec<String> = self.tasks.iter().map(Task::to_string).collect();
                    bail!(
                        "{key} = {value} in the grid's configuration changes nothing: no task of this grid ({}) reads it (a task reads only its own [problem.tasks] keys and [problem.taskN] table); leave it out, or run the task that reads it",
                        tasks.join(", ")
                    );
                }
            }
        }
        for &config in &self.configs {
            let run = self.run_config(config)?;
            for &task in &self.tasks {
                if config.applies_to(task) {
                    run.problem
                        .for_task(task)
                        .with_context(|| format!("configuration {config} on task {task}"))?;
                }
            }
        }

        for (i, config) in self.configs.iter().enumerate() {
            if self.configs[..i].contains(config) {
                bail!("configuration {config} is listed twice");
            }
        }
        for (i, task) in self.tasks.iter().enumerate() {
            if self.tasks[..i].contains(task) {
                bail!("task {task} is listed twice");
            }
        }
        Ok(())
    }

    /// Whether a run of the grid reads the dotted `key`: some task it runs
    /// reads it ([`Task::reads_setting`]) under a configuration whose
    /// algorithm does (ESP no `hill_climb.*` setting, the hill-climber no
    /// `esp.*` one).
    pub fn reads_setting(&self, key: &str) -> Result<bool> {
        for &config in &self.configs {
            let run = self.run_config(config)?;
            let reads = |task: &Task| config.applies_to(*task) && task.reads_setting(key);
            if algorithm_reads(run.algorithm, key) && self.tasks.iter().any(reads) {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Every run of the grid, in a fixed order (configuration, task, seed),
    /// each once (a `grid.json` of an earlier build may list a
    /// configuration or task twice).
    pub fn runs(&self) -> Vec<RunKey> {
        let mut runs = Vec::new();
        for (i, &config) in self.configs.iter().enumerate() {
            if self.configs[..i].contains(&config) {
                continue;
            }
            for (j, &task) in self.tasks.iter().enumerate() {
                if !config.applies_to(task) || self.tasks[..j].contains(&task) {
                    continue;
                }
                for seed in self.seed_range() {
                    runs.push(RunKey { config, task, seed });
                }
            }
        }
        runs
    }

    /// The grid's seeds, `first_seed` to `first_seed + seeds - 1` (valid
    /// grids only: [`GridSpec::validate`] refuses a range past `u64::MAX`).
    pub fn seed_range(&self) -> std::ops::RangeInclusive<u64> {
        self.first_seed..=self.first_seed.saturating_add(self.seeds.saturating_sub(1))
    }

    /// The seeds in words: "1 to 30".
    pub fn seeds_label(&self) -> String {
        format!("{} to {}", self.seed_range().start(), self.seed_range().end())
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

    /// The configuration a run of `config` had in this grid when the build
    /// at `placement` wrote it: [`GridSpec::run_config`] with every setting
    /// of the table of defaults (`psa::settings::defaults`) at that build's value,
    /// under the grid's overrides. An error when the build cannot be placed.
    pub fn run_config_at(
        &self,
        config: GridConfig,
        placement: &psa_sim::psa::settings::defaults::Placement,
    ) -> Result<RunConfig> {
        let mut table = toml::Table::try_from(RunConfig::default())?;
        crate::config::merge(&mut table, crate::models::defaults_at(placement)?);
        if let Some(text) = &self.overrides {
            let overrides = configuration_table(text).context("the grid's configuration overrides")?;
            crate::config::merge(&mut table, overrides);
        }
        let base: RunConfig = table.try_into()?;
        let mut c = config.apply(base);
        c.esp.generations = self.generations;
        c.hill_climb.cycles = self.generations;
        c.problem.backend = self.backend;
        Ok(c)
    }

    /// The settings `grid.json` states itself for a run of `config`: its
    /// overrides, those the configuration's own change sets, generations
    /// and backend (what [`Judge::Read`] checks a run against).
    pub fn stated_keys(&self, config: GridConfig) -> Result<Vec<String>> {
        let mut keys: Vec<String> = GRID_KEYS.iter().map(|(k, _)| k.to_string()).collect();
        let base = match &self.overrides {
            Some(text) => {
                let mut set = Vec::new();
                leaves(
                    &configuration_table(text).context("the grid's configuration overrides")?,
                    "",
                    &mut set,
                );
                keys.extend(set.into_iter().map(|(k, _)| k));
                RunConfig::baseline_with(text).context("the grid's configuration overrides")?
            }
            None => RunConfig::default(),
        };
        let (mut before, mut after) = (Vec::new(), Vec::new());
        leaves(&toml::Table::try_from(&base)?, "", &mut before);
        leaves(&toml::Table::try_from(config.apply(base))?, "", &mut after);
        keys.extend(after.into_iter().filter(|kv| !before.contains(kv)).map(|(k, _)| k));
        Ok(keys)
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
        let spec: GridSpec = psa_sim::io::read_versioned_json(&path, GRID_FORMAT, GRID_VERSION, "grid")?;
        spec.validate().with_context(|| format!("{}", path.display()))?;
        Ok(spec)
    }

    /// Writes `DIR/grid.json` atomically.
    pub fn save(&self, dir: &Path) -> Result<()> {
        psa_sim::io::write_json(&grid_file(dir), self)
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

/// How a run folder is judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Judge {
    /// To resume the grid: the run's configuration must be the one this
    /// build gives it (else the error names the first setting that differs
    /// and the build that wrote the run).
    Resume,
    /// To read the grid (`report`, `rescore`): the run's own files are the
    /// truth, so a grid any build of this tool wrote reads; the run must
    /// agree with the grid on what `grid.json` states itself (its
    /// overrides, the configuration's own change, generations, backend).
    Read,
}

/// Judges a run folder for resuming ([`Judge::Resume`]); see [`judge_run`].
pub fn run_status(dir: &Path, spec: &GridSpec, key: &RunKey) -> Result<RunStatus> {
    judge_run(dir, spec, key, Judge::Resume)
}

/// Judges a run folder: missing, unfinished (to be run again), finished,
/// or an error naming the folder when it holds another configuration or a
/// damaged file.
pub fn judge_run(dir: &Path, spec: &GridSpec, key: &RunKey, judge: Judge) -> Result<RunStatus> {
    let folder = run_dir(dir, key);
    if !folder.exists() {
        return Ok(RunStatus::Missing);
    }
    let config_path = RunFiles::in_dir(&folder).config;
    if !config_path.exists() {
        // Killed before its first file: nothing of value in it.
        return Ok(RunStatus::Unfinished);
    }
    let expected = spec.run_config(key.config)?;
    match judge {
        Judge::Resume => {
            let found = run_folder_config(&folder)?;
            let differ = differences_read_by(key.task, &found, &expected)?;
            if !differ.is_empty() {
                let shown: Vec<String> = differ
                    .iter()
                    .map(|(setting, there, here)| format!("{setting} = {there} there, {here} in this build"))
                    .collect();
                // Only a run of this grid under its build's defaults is
                // one `report` reads; say which this is.
                let why = if judge_run(dir, spec, key, Judge::Read).is_ok() {
                    "a run of this grid under an earlier build's defaults: `report` reads it, and resuming needs the build that wrote it, or another output directory"
                } else {
                    "a run of another grid, which `report` does not count either: move it away, or use another output directory"
                };
                bail!(
                    "{}: holds a different configuration than {} in this grid ({}): {}; {why}",
                    folder.display(),
                    key.config,
                    folder_build(&folder),
                    shown.join("; ")
                );
            }
        }
        Judge::Read => {
            let found = run_folder_config(&folder)?;
            // The run as its own build made it: this grid under that build's
            // defaults (`psa::settings::defaults`); every setting must agree.
            let placement = folder_placement(&folder);
            if let psa_sim::psa::settings::defaults::Placement::Unknown(why) = &placement {
                // A finished run whose run.json names no build this build
                // can place: no earlier defaults can vouch for it, so each
                // setting its task reads must be this grid's.
                if RunFiles::in_dir(&folder).summary.exists() {
                    if let Some((setting, there, here)) =
                        differences_read_by(key.task, &found, &expected)?.into_iter().next()
                    {
                        bail!(
                            "{}: holds a different configuration than {} in this grid: {setting} = {there} there, {here} in this grid, and its build cannot be placed ({why}) to show that build's defaults gave it (another grid's run?); move it away",
                            folder.display(),
                            key.config,
                        );
                    }
                }
            }
            if let Ok(at_build) = spec.run_config_at(key.config, &placement) {
                let differ = differences_read_by(key.task, &found, &at_build)?;
                if !differ.is_empty() {
                    let shown: Vec<String> = differ
                        .iter()
                        .map(|(setting, there, here)| format!("{setting} = {there} there, {here} in this grid"))
                        .collect();
                    bail!(
                        "{}: holds a different configuration than {} in this grid under the defaults of its build ({}): {} (another grid's run?); move it away",
                        folder.display(),
                        key.config,
                        folder_build(&folder),
                        shown.join("; ")
                    );
                }
            }
            // A build that cannot be placed: every setting whose default never
            // changed (no row in `psa::settings::defaults`) holds at any build.
            let changed_ever = |setting: &str| {
                psa_sim::psa::settings::defaults::CHANGES
                    .iter()
                    .any(|c| c.key == setting)
            };
            if let Some((setting, there, here)) = differences_read_by(key.task, &found, &expected)?
                .into_iter()
                .find(|(setting, _, _)| !changed_ever(setting))
            {
                bail!(
                    "{}: holds a different configuration than {} in this grid: {setting} = {there} there, {here} at every build (another grid's run?); move it away",
                    folder.display(),
                    key.config,
                );
            }
            // And the settings grid.json states.
            for setting in spec.stated_keys(key.config)? {
                if !key.task.reads_setting(&setting) || !algorithm_reads(expected.algorithm, &setting) {
                    continue;
                }
                let (there, here) = (leaf(&found, &setting)?, leaf(&expected, &setting)?);
                if there != here {
                    bail!(
                        "{}: holds a different configuration than {} in this grid: {setting} = {} there, {} in grid.json (another grid's run?); move it away",
                        folder.display(),
                        key.config,
                        there.map_or("nothing".into(), |v| v.to_string()),
                        here.map_or("nothing".into(), |v| v.to_string())
                    );
                }
            }
        }
    }
    if !folder.join(FINISHED_MARKER).exists() {
        return Ok(RunStatus::Unfinished);
    }
    for name in [RunFiles::RECORDS, RunFiles::CHAMPION, RunFiles::SUMMARY] {
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

/// The configuration of the run in `folder` (its `config.toml`), each
/// setting it lacks given the value the build that wrote it used (named
/// by its `run.json`; see `psa::settings::defaults`).
pub fn run_folder_config(folder: &Path) -> Result<RunConfig> {
    let path = RunFiles::in_dir(folder).config;
    let text = psa_sim::io::read_input(&path, "run configuration")?;
    // The run.json that names the build is read first: a damaged one is
    // named itself, not blamed on config.toml.
    let summary = RunFiles::in_dir(folder).summary;
    if summary.exists() {
        let json = psa_sim::io::read_input(&summary, "run summary")?;
        serde_json::from_str::<serde_json::Value>(&json).with_context(|| {
            format!(
                "{}: damaged file, so the build that wrote the run is unknown",
                summary.display()
            )
        })?;
    }
    let damaged = || format!("{}: damaged configuration", path.display());
    let table: toml::Table = toml::from_str(&text).with_context(damaged)?;
    let mut doc = serde_json::to_value(&table).with_context(damaged)?;
    let placement = folder_placement(folder);
    psa_sim::psa::settings::defaults::fill(&mut doc, "", &placement)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let table: toml::Table = serde_json::from_value(doc).with_context(damaged)?;
    RunConfig::default()
        .with_overrides(&toml::to_string(&table)?)
        .with_context(damaged)
}

/// Where the build that wrote the run in `folder` stands in the table of
/// defaults: by its `run.json`'s `build`.
fn folder_placement(folder: &Path) -> psa_sim::psa::settings::defaults::Placement {
    use psa_sim::psa::settings::defaults::Placement;
    match EvolveOutcome::build_of(&RunFiles::in_dir(folder).summary) {
        Some(serde_json::Value::Object(build)) => Placement::of_json(Some(&build)),
        _ if RunFiles::in_dir(folder).summary.exists() => Placement::Unknown("its run.json names no build".into()),
        _ => Placement::Unknown("its run.json, which names its build, is not written (yet)".into()),
    }
}

/// The build that wrote the run in `folder`, in words.
fn folder_build(folder: &Path) -> String {
    match EvolveOutcome::build_of(&RunFiles::in_dir(folder).summary) {
        Some(build) => format!(
            "the run was written by version {} commit {}",
            build.get("tool_version").and_then(|v| v.as_str()).unwrap_or("?"),
            build.get("git_commit").and_then(|v| v.as_str()).unwrap_or("?")
        ),
        None => "the run is unfinished: no run.json names its build".into(),
    }
}

/// Every leaf setting of a TOML table, as dotted keys with their values.
pub(crate) fn leaves(table: &toml::Table, prefix: &str, out: &mut Vec<(String, toml::Value)>) {
    for (key, value) in table {
        let path = format!("{prefix}{key}");
        match value {
            toml::Value::Table(inner) => leaves(inner, &format!("{path}."), out),
            other => out.push((path, other.clone())),
        }
    }
}

/// Every setting of `config` a run of `task` reads
/// ([`Task::reads_setting`]) and its algorithm reads (ESP no
/// `hill_climb.*` setting, the hill-climber no `esp.*` one), one `key =
/// value` line each: two configurations with the same lines make the same
/// runs of `task`.
pub fn settings_read_by(task: Task, config: &RunConfig) -> Result<String> {
    let mut all = Vec::new();
    leaves(&toml::Table::try_from(config)?, "", &mut all);
    Ok(all
        .into_iter()
        .filter(|(key, _)| task.reads_setting(key) && algorithm_reads(config.algorithm, key))
        .map(|(key, value)| format!("{key} = {value}\n"))
        .collect())
}

/// Whether a run of `algorithm` reads the dotted `key`: ESP reads no
/// `hill_climb.*` setting and the hill-climber no `esp.*` one.
fn algorithm_reads(algorithm: crate::Algorithm, key: &str) -> bool {
    match algorithm {
        crate::Algorithm::Esp => !key.starts_with("hill_climb."),
        crate::Algorithm::HillClimb => !key.starts_with("esp."),
    }
}

/// The value of the dotted `key` in `config` (`None` when absent).
pub(crate) fn leaf(config: &RunConfig, key: &str) -> Result<Option<toml::Value>> {
    let table = toml::Table::try_from(config)?;
    let mut at = &table;
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().unwrap_or("");
    for part in parts {
        match at.get(part).and_then(|v| v.as_table()) {
            Some(inner) => at = inner,
            None => return Ok(None),
        }
    }
    Ok(at.get(last).cloned())
}

/// Every setting in which `a` and `b` differ: its key and both values.
pub fn differences(a: &RunConfig, b: &RunConfig) -> Result<Vec<(String, String, String)>> {
    let (mut left, mut right) = (Vec::new(), Vec::new());
    leaves(&toml::Table::try_from(a)?, "", &mut left);
    leaves(&toml::Table::try_from(b)?, "", &mut right);
    let mut differ = Vec::new();
    for (key, value) in &left {
        let other = right.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        if other != Some(value) {
            differ.push((
                key.clone(),
                value.to_string(),
                other.map_or("nothing".into(), |v| v.to_string()),
            ));
        }
    }
    for (key, value) in &right {
        if !left.iter().any(|(k, _)| k == key) {
            differ.push((key.clone(), "nothing".into(), value.to_string()));
        }
    }
    Ok(differ)
}

/// [`differences`] in the settings a run of `task` reads: a task-1 run
/// written under another task-2 start is the same run
/// ([`Task::reads_setting`]), so a grid whose task 2 changed keeps its
/// task-1 and task-3 runs; likewise an ESP run under another hill-climber
/// setting (and the other way round; a change of algorithm is itself a
/// difference).
pub(crate) fn differences_read_by(task: Task, a: &RunConfig, b: &RunConfig) -> Result<Vec<(String, String, String)>> {
    let mut differ = differences(a, b)?;
    differ.retain(|(setting, _, _)| task.reads_setting(setting) && algorithm_reads(a.algorithm, setting));
    Ok(differ)
}

/// Parses the files of a finished run, so that a damaged one is never
/// counted: the robustness results, the summary, the champion, and a record
/// per generation.
fn check_finished_files(folder: &Path, spec: &GridSpec) -> Result<()> {
    let read = |name: &str| -> Result<String> {
        let path = folder.join(name);
        psa_sim::io::read_input(&path, "run file")
    };
    let damaged = |name: &str| format!("{}: damaged file", folder.join(name).display());
    serde_json::from_str::<crate::champion::robustness::Robustness>(&read(FINISHED_MARKER)?)
        .with_context(|| damaged(FINISHED_MARKER))?;
    let summary = EvolveOutcome::load(&RunFiles::in_dir(folder).summary)?;
    if !summary.champion_fitness.is_finite() {
        bail!("{}: no finite champion_fitness", damaged(RunFiles::SUMMARY));
    }
    psa_sim::psa::NetworkFile::load(&RunFiles::in_dir(folder).champion)?;
    let rows = read(RunFiles::RECORDS)?.lines().count();
    if rows != spec.generations + 1 {
        bail!(
            "{}: {} rows, expected a header and {} generations",
            damaged(RunFiles::RECORDS),
            rows,
            spec.generations
        );
    }
    Ok(())
}
