//! The replication report: reads a grid directory, puts its results beside
//! the paper's Tables 1-7 (Welch's test against the baseline, as the paper
//! does), judges each of the paper's findings by explicit rules, draws the
//! fitness curves, and writes `report.md`, `runs.csv` (and `report.csv` or
//! `report.json`) into the grid directory.
//!
//! A run counts only when it is finished and all its files parse. Missing
//! and unfinished runs are listed (a partial grid is reported, not an
//! error); a damaged folder or one holding another configuration is listed
//! under "Problems" with its path and not counted.

mod distance;
mod figures;
mod findings;
mod paper;
mod render;
mod sweep;
mod tables;
#[cfg(test)]
mod tests;
pub mod uncertainty;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::Serialize;

use crate::grid::{judge_run, run_dir, GridSpec, Judge, RunKey, RunStatus};
use crate::results::runs_table::{runs_csv, RUNS_CSV};
use crate::results::{load_run, GenerationRow, RunData};
use crate::GridConfig;
use psa_sim::named::Named;
use psa_sim::psa::Task;

pub use distance::{Distance, Part, Term};
pub use findings::{Finding, Rule, Verdict, ALPHA, COLLAPSE_FRACTION, DOUBLING_RATIO};
pub use paper::{
    paper_bursts, paper_bursts_per_run, paper_cell, PaperCell, PAPER_BURSTS, PAPER_BURST_RUNS, PAPER_RUNS_ALL,
    PAPER_RUNS_PER_TASK, PAPER_TASKS,
};
pub use sweep::{write_sweep_report, SweepReport};
pub use tables::{BurstRow, FigureLink, MissingCell, Report, Row, Table};

/// Which files `psa-esp report` writes besides `report.md`.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Serialize,
    strum::VariantArray,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum ReportFormat {
    /// `report.md` only (the Markdown is also printed).
    Md,
    /// `report.md` and `report.csv` (one row per table cell).
    Csv,
    /// `report.md` and `report.json` (the whole report).
    Json,
}

impl Named for ReportFormat {
    const WHAT: &'static str = "report format";
}

/// What a table row measures, per champion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Metric {
    /// The champion's reported score: its fitness as evolution measured it (`run.json`), or its clean test under the scoring fitness where it is scored apart (`robustness.json`'s `rescored`).
    Champion,
    /// The champion flown once without noise from the standard start (`robustness.json`).
    Clean,
    /// Its mean fitness under input noise (`robustness.json`).
    InputNoise,
    /// Its mean fitness from random initial conditions (`robustness.json`; tasks 1 and 3).
    RandomInit,
    /// Burst mutations of the run (`run.json`).
    Bursts,
}

impl Metric {
    /// A short name for tables.
    pub fn describe(self) -> &'static str {
        match self {
            Metric::Champion => "champion",
            Metric::Clean => "clean",
            Metric::InputNoise => "input noise",
            Metric::RandomInit => "random init",
            Metric::Bursts => "bursts",
        }
    }
}

impl RunData {
    /// The run's value of `metric`, if it has one (random init: tasks 1 and 3).
    pub fn value(&self, metric: Metric) -> Option<f64> {
        match metric {
            Metric::Champion => Some(if self.robustness.rescored {
                self.robustness.clean
            } else {
                self.summary.champion_fitness
            }),
            Metric::Clean => Some(self.robustness.clean),
            Metric::InputNoise => Some(self.robustness.input_noise.mean),
            Metric::RandomInit => self.robustness.random_init.map(|r| r.mean),
            Metric::Bursts => Some(self.summary.bursts as f64),
        }
    }
}

/// A run that is not (yet) finished: missing or unfinished.
#[derive(Debug, Clone)]
pub struct Incomplete {
    /// The run.
    pub key: RunKey,
    /// Missing or unfinished.
    pub status: RunStatus,
    /// Its folder.
    pub folder: PathBuf,
}

/// A run folder that is damaged or holds another configuration; not counted.
#[derive(Debug, Clone, Serialize)]
pub struct Problem {
    /// The folder.
    pub folder: PathBuf,
    /// What is wrong, naming the file.
    pub message: String,
}

/// Everything read from a grid directory.
#[derive(Debug, Clone)]
pub struct GridResults {
    /// The grid directory.
    pub dir: PathBuf,
    /// Its definition.
    pub spec: GridSpec,
    /// The runs that count.
    pub runs: Vec<RunData>,
    /// Missing and unfinished runs.
    pub incomplete: Vec<Incomplete>,
    /// Damaged or foreign run folders.
    pub problems: Vec<Problem>,
}

impl GridResults {
    /// Reads the grid in `dir`. Fails only when `dir` is not a readable
    /// grid directory; every run folder's trouble is recorded instead.
    pub fn load(dir: &Path) -> Result<GridResults> {
        if !dir.is_dir() {
            bail!(
                "{} is not a directory (expected a grid directory written by `psa-esp replicate`)",
                dir.display()
            );
        }
        let spec =
            GridSpec::load(dir).with_context(|| format!("{} is not a readable grid directory", dir.display()))?;
        let mut results = GridResults {
            dir: dir.to_path_buf(),
            spec: spec.clone(),
            runs: Vec::new(),
            incomplete: Vec::new(),
            problems: Vec::new(),
        };
        for key in spec.runs() {
            let folder = run_dir(dir, &key);
            let status = judge_run(dir, &spec, &key, Judge::Read).and_then(|status| match status {
                RunStatus::Finished => load_run(&folder, &key).map(Some),
                _ => {
                    results.incomplete.push(Incomplete {
                        key,
                        status,
                        folder: folder.clone(),
                    });
                    Ok(None)
                }
            });
            match status {
                Ok(Some(run)) => results.runs.push(run),
                Ok(None) => {}
                Err(e) => results.problems.push(Problem {
                    folder,
                    message: format!("{e:#}"),
                }),
            }
        }
        Ok(results)
    }

    /// The counted runs of `config` on any of `tasks`.
    pub fn runs_of(&self, config: GridConfig, tasks: &[Task]) -> impl Iterator<Item = &RunData> + '_ {
        let tasks = tasks.to_vec();
        self.runs
            .iter()
            .filter(move |r| r.key.config == config && tasks.contains(&r.key.task))
    }

    /// The values of `metric` over the counted runs of `config` on `tasks`.
    pub fn values(&self, config: GridConfig, tasks: &[Task], metric: Metric) -> Vec<f64> {
        self.runs_of(config, tasks).filter_map(|r| r.value(metric)).collect()
    }
}

/// What [`write_report`] did.
#[derive(Debug, Clone)]
pub struct ReportOutcome {
    /// The files written (report.md first, runs.csv, then report.csv or report.json).
    pub written: Vec<PathBuf>,
    /// The figures written (SVG and PNG).
    pub figures: Vec<PathBuf>,
    /// The Markdown report.
    pub markdown: String,
    /// The runs that count.
    pub counted: usize,
    /// The runs of the grid.
    pub expected: usize,
    /// Damaged or foreign run folders, each naming its path.
    pub problems: Vec<String>,
    /// Figures that could not be drawn (e.g. no font installed).
    pub figure_problems: Vec<String>,
    /// Where counted runs flew different models ([`Report::mixed_models`]).
    pub mixed_models: Vec<String>,
}

impl ReportOutcome {
    /// The exit code of `psa-esp report`: 1 when a run folder is damaged or
    /// foreign, else 0 (a partial grid is not an error).
    pub fn exit_code(&self) -> i32 {
        if self.problems.is_empty() {
            0
        } else {
            1
        }
    }
}

/// Reads the grid in `dir` and writes `report.md`, `runs.csv` (one row per
/// counted run), the figures in `dir/figures/`, and `report.csv` or
/// `report.json` per `format`.
///
/// Fails when `dir` is not a grid directory or a file cannot be written;
/// damaged runs and figures that cannot be drawn are reported in the
/// outcome (and the Markdown), not as errors.
pub fn write_report(dir: &Path, format: ReportFormat) -> Result<ReportOutcome> {
    write_report_against(dir, format, None)
}

/// [`write_report`], with D compared, paired by seed, with D of the grid
/// in `against` (which must fly the same seeds; [`uncertainty::Against`]).
pub fn write_report_against(dir: &Path, format: ReportFormat, against: Option<&Path>) -> Result<ReportOutcome> {
    let results = GridResults::load(dir)?;
    let reference = against
        .map(|path| GridResults::load(path).context("the grid of --against"))
        .transpose()?;
    let mut report = Report::from_results(&results);
    if let Some(reference) = &reference {
        report.against = Some(uncertainty::Against::of(
            &results,
            &report.uncertainty.samples,
            reference,
        )?);
    }
    // What an earlier report, killed while writing, left.
    psa_sim::io::remove_stale_temporaries(dir);
    psa_sim::io::remove_stale_temporaries(&dir.join("figures"));
    let (links, figures, figure_problems) = figures::write_figures(&results, &dir.join("figures"));
    report.figures = links;
    report.figure_problems = figure_problems.clone();
    let markdown = render::markdown(&report);
    let md_path = dir.join("report.md");
    psa_sim::io::write_atomic(&md_path, markdown.as_bytes())?;
    let runs_path = dir.join(RUNS_CSV);
    psa_sim::io::write_atomic(&runs_path, runs_csv(&results.runs).as_bytes())?;
    let mut written = vec![md_path, runs_path];
    match format {
        ReportFormat::Md => {}
        ReportFormat::Csv => {
            let path = dir.join("report.csv");
            psa_sim::io::write_atomic(&path, render::csv(&report).as_bytes())?;
            written.push(path);
        }
        ReportFormat::Json => {
            let path = dir.join("report.json");
            let mut json = serde_json::to_string_pretty(&report)?;
            json.push('\n');
            psa_sim::io::write_atomic(&path, json.as_bytes())?;
            written.push(path);
        }
    }
    Ok(ReportOutcome {
        written,
        figures,
        markdown,
        counted: results.runs.len(),
        expected: results.spec.runs().len(),
        problems: report.problems.iter().map(|p| p.message.clone()).collect(),
        figure_problems,
        mixed_models: report.mixed_models.clone(),
    })
}
