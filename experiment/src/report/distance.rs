//! The distance to the paper: how far a grid's results lie from the
//! published numbers the model is fitted to, in the paper's own standard
//! errors (`docs/model.md`).
//!
//! D = sum over the terms of ((here - paper) / se)^2, in three parts:
//! - the means: Table 1's task means (baseline champions, tasks 1-3),
//!   Table 2's means (the baseline champions under input noise, tasks 1-3,
//!   and from random initial conditions, tasks 1 and 3) and the two burst
//!   totals (baseline 2448, max credit 1868 over 90 runs). A mean's se is
//!   the paper's sd / sqrt(30); a total's is sqrt(total) (a count). Here, a
//!   total is the mean bursts per run times 90, so a grid with fewer seeds
//!   is comparable;
//! - the spreads: the standard deviations of the same Table 1 and Table 2
//!   cells, the se of a sample sd being sd / sqrt(2 (n - 1)) with the
//!   paper's n = 30;
//! - the burst ratio: max credit's bursts over the baseline's (the paper
//!   1868 / 2448), its se that of a ratio of two counts, ratio x sqrt(1 /
//!   2448 + 1 / 1868).

use serde::Serialize;

use super::paper::{paper_bursts, paper_cell, PAPER_BURST_RUNS, PAPER_RUNS_PER_TASK, PAPER_TASKS};
use super::{GridResults, Metric};
use crate::results::stats::mean_sd;
use crate::BASELINE;
use crate::{GridConfig, Preset};
use psa_sim::named::Named;
use psa_sim::psa::Task;

/// Max credit, the paper's second burst total.
const MAX_CREDIT: GridConfig = GridConfig::Preset(Preset::MaxCredit);

/// Which part of the distance a term belongs to; reports print the parts
/// in this order, by their names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, strum::VariantArray, strum::IntoStaticStr)]
#[serde(rename_all = "snake_case")]
pub enum Part {
    /// Table 1's and Table 2's means and the burst totals.
    #[strum(serialize = "means")]
    Mean,
    /// Table 1's and Table 2's standard deviations.
    #[strum(serialize = "spreads")]
    Spread,
    /// Max credit's bursts over the baseline's.
    #[strum(serialize = "burst ratio")]
    BurstRatio,
}

impl Named for Part {
    const WHAT: &'static str = "part";
}

/// One term of the distance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Term {
    /// What it compares, e.g. "Table 1 task 2".
    pub label: String,
    /// The part of D it belongs to.
    pub part: Part,
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
    /// The sum over the terms of [`Part::Mean`]: D as defined before the
    /// spreads joined it.
    pub means: f64,
    /// The sum over the terms of [`Part::Spread`].
    pub spreads: f64,
    /// The term of [`Part::BurstRatio`] (0 when missing).
    pub burst_ratio: f64,
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
        let mut add = |part: Part, label: String, here: Option<f64>, paper: f64, se: f64| match here {
            Some(here) => terms.push(Term {
                z: (here - paper) / se,
                label,
                part,
                here,
                paper,
                se,
            }),
            None => missing.push(label),
        };
        let n = PAPER_RUNS_PER_TASK as f64;
        let table2 = [
            ("Table 2 input noise", Metric::InputNoise),
            ("Table 2 random init", Metric::RandomInit),
        ];
        let cells: Vec<(&str, Metric, Task)> = [("Table 1", Metric::Champion)]
            .into_iter()
            .chain(table2)
            .flat_map(|(label, metric)| PAPER_TASKS.map(|task| (label, metric, task)))
            .collect();
        for &(label, metric, task) in &cells {
            if let Some(cell) = paper_cell(BASELINE, metric, Some(task)) {
                let values = results.values(BASELINE, &[task], metric);
                let (mean, _) = mean_sd(&values);
                add(
                    Part::Mean,
                    format!("{label} task {task}"),
                    mean.is_finite().then_some(mean),
                    cell.mean,
                    cell.sd / n.sqrt(),
                );
            }
        }
        // Bursts per run over all three tasks (the paper's totals are over
        // its three tasks: only a grid with all of them compares).
        let bursts_per_run = |config: GridConfig| {
            let runs: Vec<f64> = results.values(config, &PAPER_TASKS, Metric::Bursts);
            let all_tasks = PAPER_TASKS
                .iter()
                .all(|&t| results.runs_of(config, &[t]).next().is_some());
            (all_tasks && !runs.is_empty()).then(|| runs.iter().sum::<f64>() / runs.len() as f64)
        };
        for config in [BASELINE, MAX_CREDIT] {
            let paper = paper_bursts(config).expect("the paper gives both burst totals") as f64;
            let here = bursts_per_run(config).map(|per_run| per_run * PAPER_BURST_RUNS as f64);
            add(
                Part::Mean,
                format!("bursts {config} (90 runs)"),
                here,
                paper,
                paper.sqrt(),
            );
        }
        for &(label, metric, task) in &cells {
            if let Some(cell) = paper_cell(BASELINE, metric, Some(task)) {
                let (_, sd) = mean_sd(&results.values(BASELINE, &[task], metric));
                add(
                    Part::Spread,
                    format!("{label} task {task} sd"),
                    sd.is_finite().then_some(sd),
                    cell.sd,
                    cell.sd / (2.0 * (n - 1.0)).sqrt(),
                );
            }
        }
        let (base, max) = (
            paper_bursts(BASELINE).expect("the paper gives both burst totals") as f64,
            paper_bursts(MAX_CREDIT).expect("the paper gives both burst totals") as f64,
        );
        let paper_ratio = max / base;
        let here = bursts_per_run(BASELINE)
            .zip(bursts_per_run(MAX_CREDIT))
            .filter(|(base, _)| *base > 0.0)
            .map(|(base, max)| max / base);
        add(
            Part::BurstRatio,
            "bursts max-credit / baseline".to_string(),
            here,
            paper_ratio,
            paper_ratio * (1.0 / base + 1.0 / max).sqrt(),
        );
        // Folded from +0.0: a sum of no terms is 0, not the -0.0 of `Sum`.
        let part = |part: Part| {
            terms
                .iter()
                .filter(|t| t.part == part)
                .fold(0.0, |sum, t| sum + t.z * t.z)
        };
        Distance {
            total: terms.iter().fold(0.0, |sum, t| sum + t.z * t.z),
            means: part(Part::Mean),
            spreads: part(Part::Spread),
            burst_ratio: part(Part::BurstRatio),
            terms,
            missing,
        }
    }
}
