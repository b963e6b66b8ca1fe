//! The report's content: the grid, what is missing, the tables beside the
//! paper's, the burst counts and the findings.

use super::distance::Distance;
use std::collections::BTreeMap;
use strum::VariantArray;

use serde::Serialize;

use super::findings::{findings, Finding};
use super::paper::{paper_bursts, paper_cell, PaperCell};
use super::uncertainty::{grid_uncertainty, mean_interval, sd_interval, Against, GridUncertainty, Interval, RESAMPLES};
use super::{GridResults, Metric, Problem};
use crate::grid::{GridPreset, GridSpec, RunStatus};
use crate::results::stats::{mean_sd, welch};
use crate::BASELINE;
use crate::{GridConfig, Preset};
use psa_sim::provenance::BuildInfo;
use psa_sim::psa::Task;

/// One row of a table: a configuration's champions on a task (or All).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// The configuration whose champions these are.
    pub config: GridConfig,
    /// What is measured.
    pub metric: Metric,
    /// "1", "2", "3" or "All" (the grid's tasks pooled).
    pub task: String,
    /// Champions counted here.
    pub n: usize,
    /// Mean here (% of the theoretical maximum; NaN when n = 0).
    pub mean: f64,
    /// Sample sd here (NaN when n < 2).
    pub sd: f64,
    /// The 95 % t interval of the mean here (`None` when n < 2).
    pub mean_interval: Option<Interval>,
    /// The 95 % chi-square interval of the sd here (`None` when n < 2).
    pub sd_interval: Option<Interval>,
    /// Welch p here against the table's reference (NaN when n < 2 on either side).
    pub p: Option<f64>,
    /// The paper's cell, if it has one.
    pub paper: Option<PaperCell>,
}

/// A table of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Table {
    /// Short id: "1", "4"-"7", "2", "3" or "gomez".
    pub id: String,
    /// Title.
    pub title: String,
    /// What p is against, when the table has p.
    pub p_against: Option<String>,
    /// The rows.
    pub rows: Vec<Row>,
}

/// Burst mutations of one configuration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BurstRow {
    /// The configuration.
    pub config: GridConfig,
    /// Runs counted.
    pub runs: usize,
    /// Total burst mutations.
    pub total: usize,
    /// Mean per run.
    pub per_run: f64,
    /// Sample sd per run.
    pub sd: f64,
    /// The 95 % t interval of the mean per run (`None` with fewer than 2 runs).
    pub per_run_interval: Option<Interval>,
    /// The paper's total over its 90 runs, if given.
    pub paper_total: Option<usize>,
}

/// The missing and unfinished runs of one (configuration, task).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MissingCell {
    /// The configuration.
    pub config: GridConfig,
    /// The task.
    pub task: Task,
    /// Runs not started.
    pub missing: usize,
    /// Runs started but not finished.
    pub unfinished: usize,
    /// A few of their folders.
    pub examples: Vec<String>,
}

/// A figure, linked relative to the grid directory.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureLink {
    /// Caption.
    pub title: String,
    /// PNG path relative to the grid directory.
    pub png: String,
    /// SVG path relative to the grid directory.
    pub svg: String,
}

/// Runs from one build.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BuildCount {
    /// The build.
    pub build: BuildInfo,
    /// Runs made with it.
    pub runs: usize,
}

/// The whole report (what `report.json` holds).
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The grid's definition.
    pub grid: GridSpec,
    /// How the grid falls short of the paper's protocol (empty: it does not).
    pub reduced: Vec<String>,
    /// The builds that made the counted runs.
    pub builds: Vec<BuildCount>,
    /// The readings of the inputs and the fitness the runs flew, from the
    /// first counted run's own configuration (a grid of an earlier build
    /// flew its build's defaults); empty without a counted run.
    pub readings: Vec<String>,
    /// Where counted runs of one configuration and task flew different
    /// models (a setting their task reads differs: runs written by builds
    /// with other defaults), one line per such setting with how many runs
    /// flew each value; empty when every cell flew one model.
    pub mixed_models: Vec<String>,
    /// Wall-clock seconds of the counted runs, added up.
    pub compute_seconds: f64,
    /// Runs of the grid.
    pub runs_expected: usize,
    /// Runs counted.
    pub runs_counted: usize,
    /// Missing and unfinished runs per (configuration, task).
    pub missing: Vec<MissingCell>,
    /// Damaged or foreign run folders (not counted).
    pub problems: Vec<Problem>,
    /// Tables 1, 4, 5, 6, 7, Gomez's ESP (when the grid runs it), then 2
    /// and 3.
    pub tables: Vec<Table>,
    /// Burst mutations per configuration.
    pub bursts: Vec<BurstRow>,
    /// The paper's findings, judged here.
    pub findings: Vec<Finding>,
    /// The distance to the paper (`docs/model.md`).
    pub distance: Distance,
    /// D's intervals and the findings' replication rates, from resampling
    /// the grid's seeds ([`super::uncertainty`]).
    pub uncertainty: GridUncertainty,
    /// D against another grid's on the same seeds, paired by seed (`report
    /// --against`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub against: Option<Against>,
    /// The figures written.
    pub figures: Vec<FigureLink>,
    /// Figures that could not be drawn.
    pub figure_problems: Vec<String>,
}

/// The champion tables: id, title, configurations.
const CHAMPION_TABLES: [(&str, &str, &[GridConfig]); 6] = [
    (
        "1",
        "Table 1: baseline ESP (burst mutation discards all sub-populations)",
        &[BASELINE],
    ),
    (
        "4",
        "Table 4: systematic sampling",
        &[GridConfig::Preset(Preset::Systematic)],
    ),
    ("5", "Table 5: max credit", &[GridConfig::Preset(Preset::MaxCredit)]),
    (
        "6",
        "Table 6: lesion tests off; erase the best network",
        &[
            GridConfig::Preset(Preset::LesionOff),
            GridConfig::Preset(Preset::EraseBest),
        ],
    ),
    ("7", "Table 7: hill-climbing", &[GridConfig::Preset(Preset::HillClimb)]),
    (
        "gomez",
        "Gomez's ESP (burst mutation keeps sub-populations added since the best network was found; not in the paper)",
        &[GridConfig::Preset(Preset::Gomez)],
    ),
];

/// Table 3's configurations, each with the test its champions are
/// compared with the baseline's on. Every other configuration has its
/// table in [`CHAMPION_TABLES`] (a test checks that each has one).
const TABLE3_CONFIGS: [(GridConfig, Metric); 2] = [
    (GridConfig::InputNoise, Metric::InputNoise),
    (GridConfig::RandomInit, Metric::RandomInit),
];

/// The readings of the first counted run of `results`, from its own files
/// ([`crate::grid::run_folder_config`]), under the grid's rescoring.
fn readings(results: &GridResults) -> Vec<String> {
    let Some(run) = results.runs.first() else {
        return Vec::new();
    };
    let folder = crate::grid::run_dir(&results.dir, &run.key);
    let Ok(config) = crate::grid::run_folder_config(&folder) else {
        return Vec::new();
    };
    let scoring = match &results.spec.rescoring {
        Some(text) => match config.with_overrides(text) {
            Ok(scoring) => scoring,
            Err(_) => return Vec::new(),
        },
        None => config.clone(),
    };
    config.problem.describe_readings(&scoring.problem, &results.spec.tasks)
}

/// [`Report::mixed_models`]: for each configuration and task, every
/// setting its task reads in which its counted runs (each by its own
/// files, [`crate::grid::run_folder_config`]) differ, and how many flew
/// each value.
fn mixed_models(results: &GridResults) -> Vec<String> {
    type Cell = (Task, Vec<(u64, crate::RunConfig)>);
    let mut cells: BTreeMap<(String, String), Cell> = BTreeMap::new();
    for run in &results.runs {
        let folder = crate::grid::run_dir(&results.dir, &run.key);
        if let Ok(config) = crate::grid::run_folder_config(&folder) {
            cells
                .entry((run.key.config.name().to_string(), run.key.task.to_string()))
                .or_insert_with(|| (run.key.task, Vec::new()))
                .1
                .push((run.key.seed, config));
        }
    }
    let mut lines = Vec::new();
    for ((config, _), (task, runs)) in cells {
        let mut keys: Vec<String> = Vec::new();
        for (_, run) in &runs[1..] {
            for (key, _, _) in crate::grid::differences_read_by(task, run, &runs[0].1).unwrap_or_default() {
                if !keys.contains(&key) {
                    keys.push(key);
                }
            }
        }
        for key in keys {
            // Each value with the seeds of the runs that flew it.
            let mut seeds: BTreeMap<String, Vec<String>> = BTreeMap::new();
            for (seed, run) in &runs {
                let value = crate::grid::leaf(run, &key)
                    .ok()
                    .flatten()
                    .map_or("nothing".to_string(), |v| v.to_string());
                seeds.entry(value).or_default().push(seed.to_string());
            }
            let shown: Vec<String> = seeds
                .iter()
                .map(|(v, s)| format!("{v} in {} (seeds {})", s.len(), s.join(" ")))
                .collect();
            lines.push(format!("{config} task {task}: `{key}` = {}", shown.join(", ")));
        }
    }
    lines
}

impl Report {
    /// The report of `results` (figures not yet drawn).
    pub fn from_results(results: &GridResults) -> Report {
        let spec = &results.spec;
        // The paper's tables always (a grid without their runs shows them
        // missing); another configuration's only when the grid runs it.
        let shown = |configs: &[GridConfig]| {
            configs.iter().all(|c| c.in_paper()) || configs.iter().any(|c| spec.configs.contains(c))
        };
        let mut tables: Vec<Table> = CHAMPION_TABLES
            .iter()
            .filter(|(_, _, configs)| shown(configs))
            .map(|(id, title, configs)| champion_table(results, id, title, configs))
            .collect();
        tables.extend(robustness_tables(results));
        let mut judged = findings(results);
        Report {
            grid: spec.clone(),
            reduced: reductions(spec),
            builds: builds(results),
            readings: readings(results),
            mixed_models: mixed_models(results),
            compute_seconds: results.runs.iter().map(|r| r.summary.seconds).sum(),
            runs_expected: spec.runs().len(),
            runs_counted: results.runs.len(),
            missing: missing_cells(results),
            problems: results.problems.clone(),
            tables,
            bursts: burst_rows(results),
            uncertainty: grid_uncertainty(results, &mut judged, RESAMPLES),
            findings: judged,
            against: None,
            distance: Distance::of(results),
            figures: Vec::new(),
            figure_problems: Vec::new(),
        }
    }

    /// Missing and unfinished runs in all.
    pub fn incomplete_runs(&self) -> (usize, usize) {
        self.missing
            .iter()
            .fold((0, 0), |(m, u), c| (m + c.missing, u + c.unfinished))
    }
}

/// The task columns: each task alone, then All (the grid's tasks pooled).
fn task_columns(spec: &GridSpec) -> Vec<(String, Vec<Task>, Option<Task>)> {
    let mut columns: Vec<_> = Task::VARIANTS
        .iter()
        .map(|&t| (t.number().to_string(), vec![t], Some(t)))
        .collect();
    columns.push(("All".into(), spec.tasks.clone(), None));
    columns
}

/// A row: `config`'s `metric` on `tasks`, with p against `reference`'s `reference_metric`.
fn row(
    results: &GridResults,
    config: GridConfig,
    metric: Metric,
    (label, tasks, paper_task): &(String, Vec<Task>, Option<Task>),
    reference: Option<(GridConfig, Metric)>,
) -> Row {
    let values = results.values(config, tasks, metric);
    let (mean, sd) = mean_sd(&values);
    let p = reference.map(|(c, m)| welch(&values, &results.values(c, tasks, m)).p);
    Row {
        config,
        metric,
        task: label.clone(),
        n: values.len(),
        mean,
        sd,
        mean_interval: mean_interval(&values),
        sd_interval: sd_interval(&values),
        p,
        paper: paper_cell(config, metric, *paper_task),
    }
}

fn champion_table(results: &GridResults, id: &str, title: &str, configs: &[GridConfig]) -> Table {
    let reference = (configs != [BASELINE]).then_some((BASELINE, Metric::Champion));
    let rows = configs
        .iter()
        .flat_map(|&config| {
            task_columns(&results.spec)
                .iter()
                .map(|column| row(results, config, Metric::Champion, column, reference))
                .collect::<Vec<_>>()
        })
        .collect();
    Table {
        id: id.into(),
        title: title.into(),
        p_against: reference.map(|_| "baseline (Table 1)".into()),
        rows,
    }
}

/// The rows of `config`'s champions under `metric`: tasks 1-3 and All, or
/// for random initialisation tasks 1 and 3 only (as in the paper).
fn robustness_rows(
    results: &GridResults,
    config: GridConfig,
    metric: Metric,
    reference: Option<(GridConfig, Metric)>,
) -> Vec<Row> {
    task_columns(&results.spec)
        .iter()
        .filter(|(_, tasks, task)| metric != Metric::RandomInit || (task.is_some() && tasks[0].has_random_init()))
        .map(|column| row(results, config, metric, column, reference))
        .collect()
}

fn robustness_tables(results: &GridResults) -> [Table; 2] {
    let mut table2 = robustness_rows(results, BASELINE, Metric::Clean, None);
    table2.extend(robustness_rows(results, BASELINE, Metric::InputNoise, None));
    table2.extend(robustness_rows(results, BASELINE, Metric::RandomInit, None));
    let table3 = TABLE3_CONFIGS
        .iter()
        .flat_map(|&(config, test)| robustness_rows(results, config, test, Some((BASELINE, test))))
        .collect();
    [
        Table {
            id: "2".into(),
            title: "Table 2: baseline champions flown clean, under input noise and from random initial conditions".into(),
            p_against: None,
            rows: table2,
        },
        Table {
            id: "3".into(),
            title: "Table 3: champions evolved under input noise (tested under input noise) and under random initialisation (tested from random initial conditions)".into(),
            p_against: Some("the baseline champions under the same test (Table 2)".into()),
            rows: table3,
        },
    ]
}

fn burst_rows(results: &GridResults) -> Vec<BurstRow> {
    let spec = &results.spec;
    spec.configs
        .iter()
        .map(|&config| {
            let values = results.values(config, &spec.tasks, Metric::Bursts);
            let (per_run, sd) = mean_sd(&values);
            BurstRow {
                config,
                runs: values.len(),
                total: values.iter().sum::<f64>() as usize,
                per_run,
                sd,
                per_run_interval: mean_interval(&values),
                paper_total: paper_bursts(config),
            }
        })
        .collect()
}

/// How `spec` falls short of the paper's protocol.
pub(super) fn reductions(spec: &GridSpec) -> Vec<String> {
    let paper = GridSpec::from_preset(GridPreset::Paper);
    let mut reduced = Vec::new();
    let mut less = |what: &str, here: usize, there: usize| {
        if here < there {
            reduced.push(format!("{here} {what} instead of {there}"));
        }
    };
    less(
        "seeds per configuration and task",
        spec.seeds as usize,
        paper.seeds as usize,
    );
    less("generations per run", spec.generations, paper.generations);
    less(
        "trials per robustness test",
        spec.robustness_trials,
        paper.robustness_trials,
    );
    let absent: Vec<&str> = paper
        .configs
        .iter()
        .filter(|c| !spec.configs.contains(c))
        .map(|c| c.name())
        .collect();
    if !absent.is_empty() {
        reduced.push(format!("configurations left out: {}", absent.join(", ")));
    }
    let absent: Vec<String> = paper
        .tasks
        .iter()
        .filter(|t| !spec.tasks.contains(t))
        .map(|t| t.to_string())
        .collect();
    if !absent.is_empty() {
        reduced.push(format!("tasks left out: {}", absent.join(", ")));
    }
    reduced
}

fn builds(results: &GridResults) -> Vec<BuildCount> {
    let mut counts: BTreeMap<&BuildInfo, usize> = BTreeMap::new();
    for run in &results.runs {
        *counts.entry(&run.summary.build).or_default() += 1;
    }
    counts
        .into_iter()
        .map(|(build, runs)| BuildCount {
            build: build.clone(),
            runs,
        })
        .collect()
}

/// Examples of folders listed per (configuration, task).
const MISSING_EXAMPLES: usize = 2;

fn missing_cells(results: &GridResults) -> Vec<MissingCell> {
    let mut cells: Vec<MissingCell> = Vec::new();
    for run in &results.incomplete {
        let (config, task) = (run.key.config, run.key.task);
        let index = match cells.iter().position(|c| c.config == config && c.task == task) {
            Some(i) => i,
            None => {
                cells.push(MissingCell {
                    config,
                    task,
                    missing: 0,
                    unfinished: 0,
                    examples: Vec::new(),
                });
                cells.len() - 1
            }
        };
        let cell = &mut cells[index];
        match run.status {
            RunStatus::Unfinished => cell.unfinished += 1,
            _ => cell.missing += 1,
        }
        if cell.examples.len() < MISSING_EXAMPLES {
            cell.examples.push(run.folder.display().to_string());
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A configuration added to the grid without a table would run and
    /// be missing from every report.
    #[test]
    fn every_configuration_has_one_table() {
        for config in GridConfig::all() {
            let champion = CHAMPION_TABLES
                .iter()
                .filter(|(_, _, configs)| configs.contains(&config))
                .count();
            let table3 = TABLE3_CONFIGS.iter().filter(|(c, _)| *c == config).count();
            assert_eq!(champion + table3, 1, "{config} has {} tables", champion + table3);
        }
    }
}
