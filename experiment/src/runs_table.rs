//! `runs.csv`: one row per finished run of a grid (or of every variant of
//! a sweep), for pandas, R or a spreadsheet. Seeds are written as whole numbers, exactly (a reader that
//! must not round them reads the column as integers or text, e.g. pandas'
//! `dtype={"run_seed": "uint64"}`).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};

use super::grid::run_dir;
use super::report::RunData;

/// The file name, in the grid directory.
pub const RUNS_CSV: &str = "runs.csv";

/// The header of `runs.csv`.
pub const RUNS_HEADER: &str = "configuration,task,seed,run_seed,champion_fitness,champion_generation,evaluations,bursts,\
champion_hidden,clean,input_noise_mean,input_noise_sd,random_init_mean,random_init_sd,backend,tool_version,git_commit,seconds";

/// `runs.csv` for `runs`: fitness in % of the theoretical maximum, each
/// number as written in the run's files (shortest round-trip form); the
/// random-initialisation columns are empty for task 2.
pub fn runs_csv(runs: &[RunData]) -> String {
    let mut csv = format!("{RUNS_HEADER}\n");
    for run in runs {
        csv.push_str(&run_row(run));
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
    let _ = writeln!(csv, ",{RUNS_HEADER}");
    for variant in variants {
        for run in variant.runs {
            let path = run_dir(variant.dir, &run.key).join("config.toml");
            let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {}", path.display()))?;
            let config: toml::Table = text
                .parse()
                .with_context(|| format!("{} is not TOML", path.display()))?;
            csv.push_str(&csv_field(variant.name));
            for key in keys {
                csv.push(',');
                csv.push_str(&csv_field(&setting_text(&config, key)));
            }
            let _ = writeln!(csv, ",{}", run_row(run));
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

/// The columns of [`RUNS_HEADER`] for one run.
fn run_row(run: &RunData) -> String {
    let r = &run.robustness;
    let (init_mean, init_sd) = r.random_init.map_or((String::new(), String::new()), |s| {
        (s.mean.to_string(), s.sd.to_string())
    });
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{},{init_mean},{init_sd},{},{},{},{}",
        run.key.config.name(),
        run.key.task,
        run.key.seed,
        run.run_seed,
        run.champion,
        run.champion_generation,
        run.evaluations,
        run.bursts,
        run.champion_hidden,
        r.clean,
        r.input_noise.mean,
        r.input_noise.sd,
        run.backend.name(),
        csv_field(&run.build.tool_version),
        csv_field(&run.build.git_commit),
        run.seconds,
    )
}

/// `text` as one CSV field: quoted when it holds a comma, quote or line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_with_commas_or_quotes_are_quoted() {
        assert_eq!(csv_field("abc123-dirty"), "abc123-dirty");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }

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
