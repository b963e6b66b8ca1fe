//! `runs.csv`: one row per finished run of a grid, for pandas, R or a
//! spreadsheet. Seeds are written as whole numbers, exactly (a reader that
//! must not round them reads the column as integers or text, e.g. pandas'
//! `dtype={"run_seed": "uint64"}`).

use std::fmt::Write as _;

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
        let r = &run.robustness;
        let (init_mean, init_sd) = r.random_init.map_or((String::new(), String::new()), |s| {
            (s.mean.to_string(), s.sd.to_string())
        });
        let _ = writeln!(
            csv,
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
        );
    }
    csv
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
}
