//! The paper's numbers (Høverstad 2007, Tables 1-7), as printed: fitness in
//! % of the theoretical maximum, mean and sd over 30 champions per task and
//! 90 for "All", p of Welch's test against Table 1.

use serde::Serialize;

use super::Metric;
use crate::{GridConfig, Preset};
use psa_sim::psa::Task;

/// One cell of a paper table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PaperCell {
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub sd: f64,
    /// p against the baseline (Tables 4-7 only).
    pub p: Option<f64>,
}

/// The paper's tasks, in the order of its tables' columns (then All).
/// [`Task::in_paper`] holds exactly these.
pub const PAPER_TASKS: [Task; 3] = [Task::StopRotation, Task::Turn, Task::StopAtPosition];
/// Champions per task in the paper.
pub const PAPER_RUNS_PER_TASK: usize = 30;
/// Champions over all of the paper's tasks (its "All" column).
pub const PAPER_RUNS_ALL: usize = PAPER_RUNS_PER_TASK * PAPER_TASKS.len();
/// Burst mutations over the paper's 90 runs (3 tasks x 30 seeds): baseline, max credit.
pub const PAPER_BURSTS: [(GridConfig, usize); 2] = [
    (GridConfig::Preset(Preset::Baseline), 2448),
    (GridConfig::Preset(Preset::MaxCredit), 1868),
];
/// The runs the paper's burst totals are over.
pub const PAPER_BURST_RUNS: usize = 90;

const fn c(mean: f64, sd: f64, p: f64) -> Option<PaperCell> {
    Some(PaperCell {
        mean,
        sd,
        p: if p < 0.0 { None } else { Some(p) },
    })
}

/// No p (the baseline itself, and the robustness tables).
const N: f64 = -1.0;

/// Champion fitness, the [`PAPER_TASKS`] and All (Tables 1 and 4-7).
const CHAMPIONS: [(Preset, [Option<PaperCell>; 4]); 6] = [
    (
        Preset::Baseline,
        [c(42.4, 12.8, N), c(44.0, 20.7, N), c(11.9, 8.1, N), c(32.8, 20.8, N)],
    ),
    (
        Preset::Systematic,
        [
            c(41.6, 10.3, 0.8),
            c(48.4, 19.0, 0.4),
            c(17.8, 21.7, 0.2),
            c(35.9, 21.9, 0.3),
        ],
    ),
    (
        Preset::MaxCredit,
        [
            c(56.7, 14.8, 1.8e-4),
            c(60.9, 16.5, 9.2e-4),
            c(21.0, 17.5, 1.4e-2),
            c(46.2, 24.2, 9.5e-5),
        ],
    ),
    (
        Preset::LesionOff,
        [
            c(40.0, 14.1, 0.5),
            c(44.8, 18.9, 0.9),
            c(27.5, 24.7, 2e-4),
            c(37.4, 20.8, 0.1),
        ],
    ),
    (
        Preset::EraseBest,
        [
            c(51.3, 13.8, 1.3e-2),
            c(53.9, 20.8, 6.9e-2),
            c(17.6, 22.7, 0.2),
            c(40.9, 25.5, 2e-2),
        ],
    ),
    (
        Preset::HillClimb,
        [
            c(38.2, 18.4, 0.3),
            c(52.2, 22.2, 0.2),
            c(15.5, 16.4, 0.3),
            c(35.3, 24.3, 0.5),
        ],
    ),
];

/// Robustness (Tables 2 and 3): the configuration whose champions are
/// tested, the test, the [`PAPER_TASKS`] and All.
const ROBUSTNESS: [(GridConfig, Metric, [Option<PaperCell>; 4]); 4] = [
    (
        GridConfig::Preset(Preset::Baseline),
        Metric::InputNoise,
        [c(5.8, 4.8, N), c(2.5, 3.1, N), c(2.7, 0.6, N), c(3.7, 3.6, N)],
    ),
    (
        GridConfig::Preset(Preset::Baseline),
        Metric::RandomInit,
        [c(3.9, 5.9, N), None, c(7.8, 6.1, N), None],
    ),
    (
        GridConfig::InputNoise,
        Metric::InputNoise,
        [c(14.5, 6.7, N), c(10.0, 6.1, N), c(2.4, 1.0, N), c(8.9, 7.3, N)],
    ),
    (
        GridConfig::RandomInit,
        Metric::RandomInit,
        [c(10.0, 9.9, N), None, c(6.2, 3.0, N), None],
    ),
];

/// The paper's cell for `config`'s champions under `metric` on `task`
/// (`None` for All), if the paper has one: none for a task the paper did
/// not run.
pub fn paper_cell(config: GridConfig, metric: Metric, task: Option<Task>) -> Option<PaperCell> {
    let column = match task {
        None => PAPER_TASKS.len(),
        Some(task) => PAPER_TASKS.iter().position(|&t| t == task)?,
    };
    let row = match (config, metric) {
        // Table 1 is also the clean fitness of the baseline champions (Table 2).
        (GridConfig::Preset(p), Metric::Champion) | (GridConfig::Preset(p @ Preset::Baseline), Metric::Clean) => {
            CHAMPIONS.iter().find(|(q, _)| *q == p).map(|(_, r)| r)
        }
        _ => ROBUSTNESS
            .iter()
            .find(|(c, m, _)| *c == config && *m == metric)
            .map(|(_, _, r)| r),
    }?;
    row.get(column).copied().flatten()
}

/// The paper's burst total over [`PAPER_BURST_RUNS`] runs for `config`.
pub fn paper_bursts(config: GridConfig) -> Option<usize> {
    PAPER_BURSTS.iter().find(|(c, _)| *c == config).map(|(_, n)| *n)
}

/// The paper's burst total per run for `config`, for the report's text.
pub fn paper_bursts_per_run(config: GridConfig) -> Option<f64> {
    paper_bursts(config).map(|n| n as f64 / PAPER_BURST_RUNS as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use strum::VariantArray;

    #[test]
    fn the_papers_tasks_are_those_the_task_says_are_in_the_paper() {
        let in_paper: Vec<Task> = Task::VARIANTS.iter().copied().filter(|t| t.in_paper()).collect();
        assert_eq!(in_paper, PAPER_TASKS);
        assert_eq!(PAPER_BURST_RUNS, PAPER_RUNS_ALL);
    }
}
