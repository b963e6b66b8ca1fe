//! The distance to the paper: how far a grid's results lie from the
//! published numbers the model is fitted to, in the paper's own standard
//! errors (`docs/model.md`).
//!
//! D = sum over the terms of ((here - paper) / se)^2, where the terms are
//! Table 1's task means (baseline champions, tasks 1-3), Table 2's means
//! (the baseline champions under input noise, tasks 1-3, and from random
//! initial conditions, tasks 1 and 3) and the two burst totals (baseline
//! 2448, max credit 1868 over 90 runs). A mean's se is the paper's sd /
//! sqrt(30); a total's is sqrt(total) (a count). Here, a total is the mean
//! bursts per run times 90, so a grid with fewer seeds is comparable.

use serde::Serialize;

use super::paper::{paper_bursts, paper_cell, PAPER_BURST_RUNS, PAPER_RUNS_PER_TASK, PAPER_TASKS};
use super::{GridResults, Metric};
use crate::psa::Task;
use crate::BASELINE;
use crate::{GridConfig, Preset};

/// One term of the distance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Term {
    /// What it compares, e.g. "Table 1 task 2".
    pub label: String,
    /// The value here.
    pub here: f64,
    /// The paper's value.
    pub paper: f64,
    /// The paper's standard error.
    pub se: f64,
    /// (here - paper) / se.
    pub z: f64,
}

/// The distance to the paper and its terms.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Distance {
    /// The sum of the squared standardised differences over `terms`.
    pub total: f64,
    /// The terms this grid has runs for.
    pub terms: Vec<Term>,
    /// The terms it lacks (no runs of that configuration and task).
    pub missing: Vec<String>,
}

impl Distance {
    /// The distance of `results` to the paper.
    pub fn of(results: &GridResults) -> Distance {
        let mut terms = Vec::new();
        let mut missing = Vec::new();
        let mut add = |label: String, here: Option<f64>, paper: f64, se: f64| match here {
            Some(here) => terms.push(Term {
                z: (here - paper) / se,
                label,
                here,
                paper,
                se,
            }),
            None => missing.push(label),
        };
        let mean_of = |config: GridConfig, task: Task, metric: Metric| {
            let values = results.values(config, &[task], metric);
            (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
        };
        let n = (PAPER_RUNS_PER_TASK as f64).sqrt();
        let table2 = [
            ("Table 2 input noise", Metric::InputNoise),
            ("Table 2 random init", Metric::RandomInit),
        ];
        for (label, metric) in [("Table 1", Metric::Champion)].into_iter().chain(table2) {
            for task in PAPER_TASKS {
                if let Some(cell) = paper_cell(BASELINE, metric, Some(task)) {
                    add(
                        format!("{label} task {task}"),
                        mean_of(BASELINE, task, metric),
                        cell.mean,
                        cell.sd / n,
                    );
                }
            }
        }
        for config in [BASELINE, GridConfig::Preset(Preset::MaxCredit)] {
            let paper = paper_bursts(config).expect("the paper gives both burst totals") as f64;
            // The paper's total is over its three tasks: only a grid with all of them compares.
            let runs: Vec<f64> = results.values(config, &PAPER_TASKS, Metric::Bursts);
            let all_tasks = PAPER_TASKS
                .iter()
                .all(|&t| results.runs_of(config, &[t]).next().is_some());
            let here = (all_tasks && !runs.is_empty())
                .then(|| runs.iter().sum::<f64>() / runs.len() as f64 * PAPER_BURST_RUNS as f64);
            add(format!("bursts {config} (90 runs)"), here, paper, paper.sqrt());
        }
        Distance {
            total: terms.iter().map(|t| t.z * t.z).sum(),
            terms,
            missing,
        }
    }
}
