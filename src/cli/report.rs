//! `psa-esp report`: a grid's results beside the paper's tables.

use std::path::PathBuf;

use anyhow::Result;

use super::choice::choice;
use psa_experiment::report::{write_report_against, ReportFormat};

/// Arguments of `report`.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    /// The grid directory written by `psa-esp replicate` (holds grid.json),
    /// or a sweep's directory (holds sweep.json: writes sweep-report.md and .json).
    pub dir: PathBuf,
    /// md: write report.md and print it; csv: also report.csv (one row per
    /// table cell); json: also report.json (the whole report). The figures
    /// go to DIR/figures/ in every case.
    #[arg(long, value_parser = choice::<ReportFormat>(), default_value_t = ReportFormat::Md)]
    pub format: ReportFormat,
    /// Another grid on the same seeds (a rescored copy, another --config):
    /// D here minus D there, paired by seed, with its 95 % interval.
    #[arg(long, value_name = "GRID")]
    pub against: Option<PathBuf>,
}

/// Runs `report`: exit code 0, or 1 when a run folder is damaged or holds
/// another configuration (the report is written all the same, without it).
/// A directory that is not a grid is an error (exit code 2).
pub fn run(args: ReportArgs) -> Result<i32> {
    if psa_experiment::grid::sweep::sweep_file(&args.dir).exists() {
        if args.against.is_some() {
            anyhow::bail!(
                "--against compares two grids; {} is a sweep, whose report compares its variants paired by seed itself",
                args.dir.display()
            );
        }
        let (_, markdown, written) = psa_experiment::report::write_sweep_report(&args.dir)?;
        say!("{}", markdown.trim_end());
        for path in written {
            eprintln!("wrote {}", path.display());
        }
        return Ok(0);
    }
    let outcome = write_report_against(&args.dir, args.format, args.against.as_deref())?;
    if args.format == ReportFormat::Md {
        say!("{}", outcome.markdown.trim_end());
    }
    // With the Markdown on standard output, the paths go to standard error.
    let mut lines: Vec<String> = outcome
        .written
        .iter()
        .map(|p| format!("wrote {}", p.display()))
        .collect();
    if let Some(folder) = outcome.figures.first().and_then(|p| p.parent()) {
        lines.push(format!(
            "wrote {} figure files (SVG and PNG) in {}",
            outcome.figures.len(),
            folder.display()
        ));
    }
    for line in lines {
        if args.format == ReportFormat::Md {
            eprintln!("{line}");
        } else {
            say!("{line}");
        }
    }
    eprintln!(
        "{} of {} runs counted{}",
        outcome.counted,
        outcome.expected,
        if outcome.counted < outcome.expected {
            " (partial grid: see \"Missing runs\" and \"Problems\" in report.md)"
        } else {
            ""
        }
    );
    for mixed in &outcome.mixed_models {
        eprintln!("warning: mixed models, averaged together: {mixed} (see report.md)");
    }
    for problem in &outcome.figure_problems {
        eprintln!("warning: figure not drawn: {problem}");
    }
    for problem in &outcome.problems {
        eprintln!("problem: {problem}");
    }
    if !outcome.problems.is_empty() {
        eprintln!(
            "error: {} run folder(s) damaged or holding another configuration; not counted",
            outcome.problems.len()
        );
    }
    Ok(outcome.exit_code())
}
