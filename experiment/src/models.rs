//! Earlier models by name: the defaults of an earlier build, derived from
//! the table of defaults (`psa::settings::defaults`), so that a model
//! outlives every later change of a default without being written out.
//!
//! A configuration (a `--config` file, a grid's overrides, Python's
//! `config`) that sets `model = "NAME"` at its top level flies that model:
//! every setting of the table at the value the model's builds used, then
//! the configuration's own settings laid over it. The table's rows are
//! only ever appended, so a name gives the same settings on every build.

use anyhow::{bail, Context, Result};
use psa_sim::named::Named;
use psa_sim::psa::settings::defaults::{value_at, Placement, CHANGES};

/// The key of a configuration that names its model.
pub const MODEL_KEY: &str = "model";

/// An earlier model: the defaults of the builds before one change of the
/// defaults. Kept so that their runs repeat byte for byte (each has a file
/// under `configs/` and golden records under `tests/golden/`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, strum::VariantArray, strum::IntoStaticStr, strum::Display, strum::EnumString,
)]
#[strum(serialize_all = "kebab-case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum EarlierModel {
    /// The guessed model before the fit to the paper's evidence.
    PreviousDefaults,
    /// Before the fitness readings: champions scored on the incremental
    /// fitness they evolved on, read from the true state.
    FittedIncremental,
    /// Before the start quaternion was normalised: the first grid scored on
    /// the original fitness through the sensors.
    ScoredOnOriginal,
    /// Before the heading input was wrapped to [0, 2 pi) and b went to 50.
    SymmetricHeading,
    /// Before ESP's readings of the text: erase-best on a topology change,
    /// the hill-climber's first mutation.
    PositiveHeading,
    /// Before task 2 started clockwise: task 2 at 1.0 rad/s, towards its target.
    Task2TowardsTarget,
    /// Before the sensor scales were halved and task 2 started at -0.75 rad/s.
    ClockwiseStart,
    /// Before input noise reached the bias unit.
    NoiselessBias,
    /// Before the heading input went back to (-pi, pi].
    PositiveWrap,
    /// Before the heading input became the heading itself: the heading
    /// error (the defaults confirmed by S50).
    HeadingError,
    /// Before the sensor scales went back to the text's reading: the
    /// scales halved (the defaults of the full grid of S51).
    HalvedScales,
}

impl Named for EarlierModel {
    const WHAT: &'static str = "model";
}

impl EarlierModel {
    /// Where the model's builds stand in the table of defaults.
    pub fn placement(self) -> Placement {
        use EarlierModel::*;
        let before_row = |key, value| Placement::before_row(key, value).expect("a row of the table");
        match self {
            PreviousDefaults => before_commit("95ee59b"),
            FittedIncremental => before_commit("d497677"),
            ScoredOnOriginal => before_commit("a1ccaad"),
            SymmetricHeading => before_commit("a70d696"),
            PositiveHeading => before_commit("8cf59c9"),
            Task2TowardsTarget => before_row("problem.tasks.task2_spin", "-1.5"),
            ClockwiseStart => before_row("problem.tasks.task2_spin", "-0.75"),
            NoiselessBias => before_row("problem.noise.on_bias", "true"),
            PositiveWrap => before_row("problem.sensors.heading_wrap", r#""symmetric""#),
            HeadingError => before_row("problem.sensors.heading_input", r#""absolute""#),
            HalvedScales => before_row("problem.sensors.position_scale", "10.0"),
        }
    }

    /// Every setting of the table of defaults at the model's value, as the
    /// tables of a configuration.
    pub fn settings(self) -> Result<toml::Table> {
        defaults_at(&self.placement())
    }
}

/// Every setting of the table of defaults at the value the builds at
/// `placement` used, as the tables of a configuration; an error naming the
/// key when they cannot be placed.
pub fn defaults_at(placement: &Placement) -> Result<toml::Table> {
    let mut table = toml::Table::new();
    for row in CHANGES {
        if let Some(value) = value_at(row.key, placement).map_err(anyhow::Error::msg)? {
            set_leaf(&mut table, row.key, serde_json::from_value(value)?);
        }
    }
    Ok(table)
}

/// The builds before `commit`, a commit of the project's history.
fn before_commit(commit: &str) -> Placement {
    Placement::before_commit(commit).expect("a commit of the history of defaults")
}

/// Parses a configuration's TOML text; a `model = "NAME"` at its top level
/// is replaced by that model's settings, under the text's own.
pub fn configuration_table(text: &str) -> Result<toml::Table> {
    let mut table: toml::Table = toml::from_str(text)?;
    let Some(name) = table.remove(MODEL_KEY) else {
        return Ok(table);
    };
    let Some(name) = name.as_str() else {
        bail!(
            "{MODEL_KEY} = {name}: a model is named by a string (one of {})",
            EarlierModel::names().join(", ")
        );
    };
    let model: EarlierModel = name.parse().map_err(anyhow::Error::msg)?;
    let mut settings = model.settings().with_context(|| format!("{MODEL_KEY} = {name:?}"))?;
    crate::config::merge(&mut settings, table);
    Ok(settings)
}

/// Sets the dotted `key` of `table` to `value`, making its tables.
fn set_leaf(table: &mut toml::Table, key: &str, value: toml::Value) {
    let mut parts: Vec<&str> = key.split('.').collect();
    let Some(last) = parts.pop() else {
        return;
    };
    let mut at = table;
    for part in parts {
        let entry = at
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let Some(inner) = entry.as_table_mut() else {
            return;
        };
        at = inner;
    }
    at.insert(last.to_string(), value);
}

#[cfg(test)]
mod tests {
    use super::*;
    use strum::VariantArray;

    #[test]
    fn every_model_is_placed_and_sets_every_key_of_the_table() {
        let keys: std::collections::BTreeSet<&str> = CHANGES.iter().map(|row| row.key).collect();
        for model in EarlierModel::VARIANTS {
            let mut set = Vec::new();
            crate::grid::leaves(&model.settings().unwrap(), "", &mut set);
            let set: std::collections::BTreeSet<&str> = set.iter().map(|(key, _)| key.as_str()).collect();
            assert_eq!(set, keys, "{model}");
        }
    }

    #[test]
    fn a_model_is_laid_under_the_texts_own_settings_and_a_bad_name_is_named() {
        let table = configuration_table("model = \"positive-wrap\"\n[esp]\nstagnation = 5\n").unwrap();
        assert_eq!(table["esp"]["stagnation"].as_integer(), Some(5));
        assert_eq!(table["problem"]["sensors"]["heading_wrap"].as_str(), Some("positive"));
        assert_eq!(table["problem"]["sensors"]["position_scale"].as_float(), Some(5.0));
        let previous = configuration_table("model = \"previous-defaults\"").unwrap();
        assert_eq!(previous["esp"]["stagnation"].as_integer(), Some(20));
        assert_eq!(previous["esp"]["stagnation_rule"].as_str(), Some("all_time_best"));
        let err = format!("{:#}", configuration_table("model = \"positive\"").unwrap_err());
        assert!(err.contains("\"positive\"") && err.contains("positive-wrap"), "{err}");
        let err = format!("{:#}", configuration_table("model = 3").unwrap_err());
        assert!(err.contains("model = 3") && err.contains("previous-defaults"), "{err}");
    }
}
