//! `runs.csv`: one row per finished run of a grid (or of every variant of
//! a sweep), for pandas, R or a spreadsheet. Seeds are written as whole numbers, exactly (a reader that
//! must not round them reads the column as integers or text, e.g. pandas'
//! `dtype={"run_seed": "uint64"}`).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use psa_sim::named::Named;

use crate::grid::run_dir;
use crate::results::columns::{csv_field, header, row, Column};
use crate::results::RunData;
use crate::RunFiles;

/// The file name, in the grid directory.
pub const RUNS_CSV: &str = "runs.csv";

/// The columns of `runs.csv`, one row per finished run; fitness in % of
/// the task's theoretical maximum, each number as the run's files hold it
/// (the shortest form that reads back to the same double).
pub const RUN_COLUMNS: [Column<RunData>; 18] = [
    Column {
        name: "configuration",
        doc: "the configuration (`baseline`, `max-credit`, ...)",
        value: |run| run.key.config.name().to_string(),
    },
    Column {
        name: "task",
        doc: "the task, 1 to 3",
        value: |run| run.key.task.to_string(),
    },
    Column {
        name: "seed",
        doc: "the grid seed, 1..N",
        value: |run| run.key.seed.to_string(),
    },
    Column {
        name: "run_seed",
        doc: "the 64-bit seed the run used, as in `run.json` (`evolve --seed` with it repeats the run)",
        value: |run| run.summary.seed.to_string(),
    },
    Column {
        name: "champion_fitness",
        doc: "the champion's fitness",
        value: |run| run.summary.champion_fitness.to_string(),
    },
    Column {
        name: "champion_generation",
        doc: "the generation (cycle) the champion was found in",
        value: |run| run.summary.champion_generation.to_string(),
    },
    Column {
        name: "evaluations",
        doc: "network evaluations, lesion tests included",
        value: |run| run.summary.evaluations.to_string(),
    },
    Column {
        name: "bursts",
        doc: "burst mutations",
        value: |run| run.summary.bursts.to_string(),
    },
    Column {
        name: "champion_hidden",
        doc: "hidden neurons of the champion",
        value: |run| run.summary.champion_hidden.to_string(),
    },
    Column {
        name: "clean",
        doc: "the champion flown once without noise from the standard start",
        value: |run| run.robustness.clean.to_string(),
    },
    Column {
        name: "input_noise_mean",
        doc: "its mean fitness under input noise",
        value: |run| run.robustness.input_noise.mean.to_string(),
    },
    Column {
        name: "input_noise_sd",
        doc: "the standard deviation of that fitness",
        value: |run| run.robustness.input_noise.sd.to_string(),
    },
    Column {
        name: "random_init_mean",
        doc: "its mean fitness from random initial conditions (empty for task 2)",
        value: |run| run.robustness.random_init.map_or(String::new(), |s| s.mean.to_string()),
    },
    Column {
        name: "random_init_sd",
        doc: "the standard deviation of that fitness (empty for task 2)",
        value: |run| run.robustness.random_init.map_or(String::new(), |s| s.sd.to_string()),
    },
    Column {
        name: "backend",
        doc: "the physics backend",
        value: |run| run.summary.backend.name().to_string(),
    },
    Column {
        name: "tool_version",
        doc: "the version of psa-esp that made the run",
        value: |run| csv_field(&run.summary.build.tool_version),
    },
    Column {
        name: "git_commit",
        doc: "its git commit (`-dirty` for uncommitted changes)",
        value: |run| csv_field(&run.summary.build.git_commit),
    },
    Column {
        name: "seconds",
        doc: "the run's wall time",
        value: |run| run.summary.seconds.to_string(),
    },
];

/// `runs.csv` for `runs` ([`RUN_COLUMNS`]).
pub fn runs_csv(runs: &[RunData]) -> String {
    let mut csv = header(&RUN_COLUMNS) + "\n";
    for run in runs {
        csv.push_str(&row(&RUN_COLUMNS, run));
        csv.push('\n');
    }
    csv
}

/// One variant of a sweep and its finished runs, for [`sweep_runs_csv`].
pub struct VariantRuns<'a> {
    /// The variant's folder name.
    pub name: &'a str,
    /// Its grid folder (the runs' `config.toml` files are read from it).
    pub dir: &'a Path,
    /// Its finished runs.
    pub runs: &'a [RunData],
}

/// `runs.csv` of a sweep: a column `variant` (the variant's folder name),
/// then one column per varied setting in `keys` holding the value the run
/// was made with (read from its `config.toml`, so a setting a variant
/// leaves at the base value shows that value), then the grid's columns.
pub fn sweep_runs_csv(keys: &[String], variants: &[VariantRuns]) -> Result<String> {
    let mut csv = String::from("variant");
    for key in keys {
        csv.push(',');
        csv.push_str(&csv_field(key));
    }
    let _ = writeln!(csv, ",{}", header(&RUN_COLUMNS));
    for variant in variants {
        for run in variant.runs {
            let path = RunFiles::in_dir(&run_dir(variant.dir, &run.key)).config;
            let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {}", path.display()))?;
            let config: toml::Table = text
                .parse()
                .with_context(|| format!("{} is not TOML", path.display()))?;
            csv.push_str(&csv_field(variant.name));
            for key in keys {
                csv.push(',');
                csv.push_str(&csv_field(&setting_text(&config, key)));
            }
            let _ = writeln!(csv, ",{}", row(&RUN_COLUMNS, run));
        }
    }
    Ok(csv)
}

/// The value of the dotted `key` in `config` as text (a string without
/// its quotes, anything else in TOML form); empty when `config` lacks it.
fn setting_text(config: &toml::Table, key: &str) -> String {
    let mut parts = key.split('.');
    let first = parts.next().and_then(|p| config.get(p));
    match parts
        .try_fold(first, |value, part| Some(value?.as_table()?.get(part)))
        .flatten()
    {
        Some(toml::Value::String(text)) => text.clone(),
        Some(value) => value.to_string(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dotted_key_reads_its_value_in_toml_form_and_a_missing_one_is_empty() {
        let config: toml::Table =
            "[esp]\nstagnation = 40\nstagnation_rule = \"phase_best\"\n[problem.tasks]\ntask2_velocity = [0.2, 0.0]\n"
                .parse()
                .unwrap();
        assert_eq!(setting_text(&config, "esp.stagnation"), "40");
        assert_eq!(setting_text(&config, "esp.stagnation_rule"), "phase_best");
        assert_eq!(setting_text(&config, "problem.tasks.task2_velocity"), "[0.2, 0.0]");
        assert_eq!(setting_text(&config, "problem.tasks.nothing"), "");
        assert_eq!(setting_text(&config, "esp.stagnation.deeper"), "");
    }
}
