//! A run's whole configuration, the paper's presets, and TOML overrides.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use esp_neuroevolution::{BurstMode, Credit, EspSettings, HillClimbSettings, Sampling, TopologyMode, MAX_GENERATIONS};
use psa_sim::named::Named;
use psa_sim::psa::PsaSettings;
use strum::VariantArray;

/// Which search algorithm (read and written by name: [`Named`]).
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
pub enum Algorithm {
    /// Enforced Sub-Populations.
    Esp,
    /// The hill-climber (also read as "hill-climb", its preset's name).
    #[serde(alias = "hill-climb")]
    #[strum(to_string = "hill_climb", serialize = "hill-climb")]
    HillClimb,
}

impl Named for Algorithm {
    const WHAT: &'static str = "algorithm";
}

/// Everything that defines a run but its task and seed; written beside
/// every result as `config.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunConfig {
    /// The search algorithm.
    pub algorithm: Algorithm,
    /// ESP's settings (used when `algorithm = "esp"`).
    pub esp: EspSettings,
    /// The hill-climber's settings (used when `algorithm = "hill_climb"`).
    pub hill_climb: HillClimbSettings,
    /// The control problem.
    pub problem: PsaSettings,
}

impl Default for RunConfig {
    fn default() -> Self {
        Preset::Baseline.config()
    }
}

/// ESP's settings for the PSA, the paper's baseline (its Table 1):
/// Høverstad's ESP with 5 sub-populations of 40 neurons at first, 10
/// networks per neuron (400 a generation) and 2000 generations; the
/// stagnation of 50 generations is chosen: D picked it from the paper's
/// burst totals (docs/sweeps/s05-stagnation-b.md, s28-stagnation-b-spreads.md),
/// and with the heading in (-pi, pi] it is not told apart from 40 beyond seed noise
/// (docs/model.md, "How sure the fit is").
pub fn paper_esp_settings() -> EspSettings {
    EspSettings {
        subpop_size: 40,
        trials_per_neuron: 10,
        initial_hidden: 5,
        generations: 2000,
        init_range: 6.0,
        stagnation: 50,
        ..EspSettings::hoverstad()
    }
}

impl RunConfig {
    /// The baseline: ESP, every setting at its default.
    fn base() -> RunConfig {
        RunConfig {
            algorithm: Algorithm::Esp,
            esp: paper_esp_settings(),
            hill_climb: HillClimbSettings::default(),
            problem: PsaSettings::default(),
        }
    }
}

/// The baseline configuration (Table 1), which the report compares every
/// other configuration with.
pub const BASELINE: GridConfig = GridConfig::Preset(Preset::Baseline);

/// One configuration of the paper.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    strum::VariantArray,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[serde(rename_all = "kebab-case")]
#[strum(serialize_all = "kebab-case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum Preset {
    /// ESP with burst mutation discarding all sub-populations (Table 1).
    Baseline,
    /// Systematic sampling (Table 4).
    Systematic,
    /// Max credit (Table 5).
    MaxCredit,
    /// No lesion tests (Table 6).
    LesionOff,
    /// Erase the best network at every burst mutation (Table 6; `esp.erase_at`).
    EraseBest,
    /// The hill-climber (Table 7).
    HillClimb,
    /// ESP as Gomez defined it, without the discard-all change.
    Gomez,
}

impl Preset {
    /// Whether the paper ran it: all but `gomez`.
    pub fn in_paper(self) -> bool {
        match self {
            Preset::Baseline
            | Preset::Systematic
            | Preset::MaxCredit
            | Preset::LesionOff
            | Preset::EraseBest
            | Preset::HillClimb => true,
            Preset::Gomez => false,
        }
    }

    /// The configuration: the baseline with this preset's one change.
    pub fn config(self) -> RunConfig {
        self.apply(RunConfig::base())
    }

    /// `config` with this preset's one change.
    pub fn apply(self, mut config: RunConfig) -> RunConfig {
        match self {
            Preset::Baseline => {}
            Preset::Systematic => config.esp.sampling = Sampling::Systematic,
            Preset::MaxCredit => config.esp.credit = Credit::Max,
            Preset::LesionOff => config.esp.topology = TopologyMode::Off,
            Preset::EraseBest => config.esp.erase_best = true,
            Preset::HillClimb => config.algorithm = Algorithm::HillClimb,
            Preset::Gomez => config.esp.burst = BurstMode::Gomez,
        }
        config
    }
}

impl Named for Preset {
    const WHAT: &'static str = "preset";
}

/// Overlays `overrides` onto `base`, table by table.
pub(super) fn merge(base: &mut toml::Table, overrides: toml::Table) {
    for (key, value) in overrides {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

impl RunConfig {
    /// Rejects out-of-range values, naming the setting.
    pub fn validate(&self) -> Result<()> {
        self.esp.validate().map_err(anyhow::Error::msg)?;
        self.hill_climb.validate().map_err(anyhow::Error::msg)?;
        self.problem.validate().context("problem")?;
        Ok(())
    }

    /// The baseline with the settings of a TOML document laid over it.
    pub fn baseline_with(toml_text: &str) -> Result<RunConfig> {
        RunConfig::base().with_overrides(toml_text)
    }

    /// This configuration with the settings of a TOML document laid over it
    /// (after the earlier model it names, if any: [`crate::models`]);
    /// unknown keys and out-of-range values are errors naming the key.
    pub fn with_overrides(&self, toml_text: &str) -> Result<RunConfig> {
        let overrides = crate::models::configuration_table(toml_text)?;
        let mut table = toml::Table::try_from(self)?;
        merge(&mut table, overrides);
        let config: RunConfig = table.try_into()?;
        config.validate()?;
        Ok(config)
    }

    /// [`RunConfig::with_overrides`] with the contents of a file.
    pub fn with_overrides_from(&self, path: &Path) -> Result<RunConfig> {
        let text = psa_sim::io::read_input(path, "configuration")?;
        self.with_overrides(&text)
            .with_context(|| format!("configuration {}", path.display()))
    }

    /// The dotted keys (`problem.noise.input_sd`) a configuration file
    /// sets, whatever their values (those of the model it names included).
    pub fn keys_set_by(path: &Path) -> Result<Vec<String>> {
        let text = psa_sim::io::read_input(path, "configuration")?;
        let table =
            crate::models::configuration_table(&text).with_context(|| format!("configuration {}", path.display()))?;
        let mut leaves = Vec::new();
        crate::grid::leaves(&table, "", &mut leaves);
        Ok(leaves.into_iter().map(|(key, _)| key).collect())
    }

    /// The configuration as TOML.
    pub fn to_toml(&self) -> Result<String> {
        Ok(toml::to_string(self)?)
    }

    /// Overrides the generations (ESP) or cycles (hill-climber).
    pub fn set_generations(&mut self, generations: usize) -> Result<()> {
        if !(1..=MAX_GENERATIONS).contains(&generations) {
            bail!("--generations must be in [1, {MAX_GENERATIONS}], got {generations}");
        }
        self.esp.generations = generations;
        self.hill_climb.cycles = generations;
        Ok(())
    }

    /// Generations (or cycles) of the configured algorithm.
    pub fn generations(&self) -> usize {
        match self.algorithm {
            Algorithm::Esp => self.esp.generations,
            Algorithm::HillClimb => self.hill_climb.cycles,
        }
    }
}

/// One configuration of the replication grid: a preset of the paper's
/// Tables 1 and 4-7 (and Gomez's ESP), or one of Table 3's two, evolved
/// under input noise or random initialisation.
/// [`GridConfigKind`] lists its variants, so that a new one must be placed
/// in [`GridConfig::all`] to compile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, strum::EnumDiscriminants)]
#[strum_discriminants(name(GridConfigKind), derive(strum::VariantArray))]
#[serde(try_from = "String", into = "String")]
pub enum GridConfig {
    /// A preset.
    Preset(Preset),
    /// Baseline ESP evolved under input noise sd 0.05, each network evaluated 3 times (Table 3).
    InputNoise,
    /// Baseline ESP evolved with random initial conditions, each network evaluated 3 times (Table 3; tasks 1 and 3).
    RandomInit,
}

/// Input noise of Table 3's evolution and of the robustness tests. `[paper]` 0.05
pub const PAPER_NOISE_SD: f64 = 0.05;
/// Trials per evaluation under noise or random initialisation. `[paper]` 3
pub const PAPER_NOISY_TRIALS: usize = 3;

impl GridConfig {
    /// Every configuration of the grid, in report order: every preset,
    /// then Table 3's two.
    pub fn all() -> Vec<GridConfig> {
        GridConfigKind::VARIANTS
            .iter()
            .flat_map(|kind| match kind {
                GridConfigKind::Preset => Preset::VARIANTS.iter().map(|&p| GridConfig::Preset(p)).collect(),
                GridConfigKind::InputNoise => vec![GridConfig::InputNoise],
                GridConfigKind::RandomInit => vec![GridConfig::RandomInit],
            })
            .collect()
    }

    /// Whether the paper ran it: all but `gomez`. The paper's configurations
    /// are a grid's default; `gomez` joins when named.
    pub fn in_paper(self) -> bool {
        match self {
            GridConfig::Preset(p) => p.in_paper(),
            GridConfig::InputNoise | GridConfig::RandomInit => true,
        }
    }

    /// The configuration's name (folder and command-line name).
    pub fn name(self) -> &'static str {
        match self {
            GridConfig::Preset(p) => p.name(),
            GridConfig::InputNoise => "input-noise",
            GridConfig::RandomInit => "random-init",
        }
    }

    /// The run configuration.
    pub fn config(self) -> RunConfig {
        self.apply(RunConfig::base())
    }

    /// `base` (a configuration of the baseline, such as one with a file's
    /// settings laid over it) with this configuration's change.
    pub fn apply(self, base: RunConfig) -> RunConfig {
        match self {
            GridConfig::Preset(p) => p.apply(base),
            GridConfig::InputNoise => {
                let mut c = base;
                c.problem.noise.input_sd = PAPER_NOISE_SD;
                c.problem.trials = PAPER_NOISY_TRIALS;
                c
            }
            GridConfig::RandomInit => {
                let mut c = base;
                c.problem.random_init = true;
                c.problem.trials = PAPER_NOISY_TRIALS;
                c
            }
        }
    }

    /// Whether the configuration applies to `task` (random initialisation: tasks 1 and 3 only).
    pub fn applies_to(self, task: psa_sim::psa::Task) -> bool {
        self != GridConfig::RandomInit || task.has_random_init()
    }
}

impl fmt::Display for GridConfig {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for GridConfig {
    type Err = String;
    fn from_str(s: &str) -> Result<GridConfig, String> {
        GridConfig::all().into_iter().find(|c| c.name() == s).ok_or_else(|| {
            let names: Vec<&str> = GridConfig::all().into_iter().map(GridConfig::name).collect();
            format!("unknown configuration {s:?} (expected one of {})", names.join(", "))
        })
    }
}

impl TryFrom<String> for GridConfig {
    type Error = String;
    fn try_from(s: String) -> Result<GridConfig, String> {
        s.parse()
    }
}

impl From<GridConfig> for String {
    fn from(c: GridConfig) -> String {
        c.name().to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::sweep::SweepMode;
    use crate::grid::GridPreset;
    use crate::report::{Part, ReportFormat};

    /// The names of earlier builds, which folders, `grid.json`,
    /// `sweep.json`, reports and command lines hold: a new variant adds its
    /// name, none changes, so old results read as before.
    #[test]
    fn the_names_are_those_of_earlier_builds() {
        let grid: Vec<&str> = GridConfig::all().into_iter().map(GridConfig::name).collect();
        assert_eq!(
            grid,
            [
                "baseline",
                "systematic",
                "max-credit",
                "lesion-off",
                "erase-best",
                "hill-climb",
                "gomez",
                "input-noise",
                "random-init"
            ]
        );
        assert_eq!(Preset::names(), grid[..7]);
        assert_eq!(GridPreset::names(), ["quick", "paper"]);
        assert_eq!(SweepMode::names(), ["combinations", "one-at-a-time"]);
        assert_eq!(ReportFormat::names(), ["md", "csv", "json"]);
        assert_eq!(Part::names(), ["means", "spreads", "burst ratio"]);
    }

    #[test]
    fn every_name_reads_back_and_an_unknown_one_is_named() {
        for config in GridConfig::all() {
            assert_eq!(config.name().parse::<GridConfig>(), Ok(config));
            assert_eq!(serde_json::to_string(&config).unwrap(), format!("\"{config}\""));
        }
        for &preset in Preset::VARIANTS {
            assert_eq!(preset.to_string().parse::<Preset>(), Ok(preset));
            assert_eq!(serde_json::to_string(&preset).unwrap(), format!("\"{preset}\""));
        }
        assert!("gomes"
            .parse::<GridConfig>()
            .unwrap_err()
            .contains("expected one of baseline,"));
        assert_eq!(
            "best".parse::<Preset>(),
            Err("unknown preset \"best\" (expected one of baseline, systematic, max-credit, lesion-off, erase-best, hill-climb, gomez)".to_string())
        );
    }

    /// The paper's configurations are a grid's default: all but `gomez`.
    #[test]
    fn the_paper_ran_all_configurations_but_gomez() {
        let not_in_paper: Vec<GridConfig> = GridConfig::all().into_iter().filter(|c| !c.in_paper()).collect();
        assert_eq!(not_in_paper, [GridConfig::Preset(Preset::Gomez)]);
    }
}
