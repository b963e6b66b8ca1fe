//! The paper's findings and the explicit rules that judge each one, here
//! and (as a check of the rules) on the paper's own numbers.

use serde::Serialize;

use super::paper::{
    paper_bursts_per_run, paper_cell, PAPER_BURST_RUNS, PAPER_RUNS_ALL, PAPER_RUNS_PER_TASK, PAPER_TASKS,
};
use super::{GridResults, Metric};
use crate::results::stats::{mean_sd, welch};
use crate::BASELINE;
use crate::{GridConfig, Preset};
use psa_sim::named::Named;
use psa_sim::psa::Task;

/// Significance level of the Welch rules.
pub const ALPHA: f64 = 0.05;
/// "Collapse": the robust mean is below this fraction of the clean mean.
pub const COLLAPSE_FRACTION: f64 = 0.5;
/// "Roughly doubling": the evolved-under-noise mean is at least this many
/// times the evolved-clean mean under the same test.
pub const DOUBLING_RATIO: f64 = 1.5;

/// How a finding is judged from two means `a` (the claim's subject) and `b`
/// (its reference) and Welch's p of `a` against `b`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rule {
    /// Higher mean and p < [`ALPHA`].
    Better,
    /// Not (lower mean and p < [`ALPHA`]).
    NoWorse,
    /// p >= [`ALPHA`].
    AboutAsGood,
    /// a < [`COLLAPSE_FRACTION`] x b.
    Collapse,
    /// a >= [`DOUBLING_RATIO`] x b.
    Doubling,
    /// a < b (p is shown, not used).
    Fewer,
}

impl Rule {
    /// The rule in words, as the report states it.
    pub fn definition(self) -> String {
        match self {
            Rule::Better => format!("\"better\" = higher mean and Welch p < {ALPHA}"),
            Rule::NoWorse => format!("\"no worse\" = not (lower mean and Welch p < {ALPHA})"),
            Rule::AboutAsGood => format!("\"about as good\" = Welch p >= {ALPHA}"),
            Rule::Collapse => format!(
                "\"collapse\" = robust mean < {:.0} % of the clean mean",
                COLLAPSE_FRACTION * 100.0
            ),
            Rule::Doubling => format!(
                "\"roughly doubling\" = mean evolved under noise >= {DOUBLING_RATIO} x mean evolved clean, on each task"
            ),
            Rule::Fewer => "\"fewer\" = lower mean number per run".into(),
        }
    }

    /// Whether the rule holds; `None` when it cannot be decided (a mean or,
    /// for the Welch rules, p is NaN: too few runs).
    pub fn holds(self, a: f64, b: f64, p: f64) -> Option<bool> {
        if a.is_nan() || b.is_nan() {
            return None;
        }
        let welch = matches!(self, Rule::Better | Rule::NoWorse | Rule::AboutAsGood);
        if welch && p.is_nan() {
            return None;
        }
        Some(match self {
            Rule::Better => a > b && p < ALPHA,
            Rule::NoWorse => !(a < b && p < ALPHA),
            Rule::AboutAsGood => p >= ALPHA,
            Rule::Collapse => a < COLLAPSE_FRACTION * b,
            Rule::Doubling => a >= DOUBLING_RATIO * b,
            Rule::Fewer => a < b,
        })
    }
}

/// Whether a finding holds here.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// The rule holds on every comparison.
    Reproduced,
    /// The rule fails on a comparison.
    NotReproduced,
    /// Too few runs to decide.
    NotTestable,
}

impl Verdict {
    /// The verdict in words.
    pub fn describe(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::NotReproduced => "not reproduced",
            Verdict::NotTestable => "not testable (too few runs)",
        }
    }
}

/// One comparison of a finding: mean `a` against mean `b`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// "All", "task 1", "tasks 1 and 3".
    pub label: String,
    /// Runs behind `a`.
    pub n_a: usize,
    /// Runs behind `b`.
    pub n_b: usize,
    /// The subject's mean.
    pub a: f64,
    /// The reference's mean.
    pub b: f64,
    /// Welch p of a against b (NaN when not available).
    pub p: f64,
}

/// One of the paper's findings, judged.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Finding {
    /// The claim, e.g. "max credit is clearly better than the baseline".
    pub claim: String,
    /// What `a` and `b` are, e.g. "max credit vs baseline, champion fitness (%)".
    pub measure: String,
    /// The rule that judges it.
    pub rule: Rule,
    /// The comparisons on the paper's numbers.
    pub paper: Vec<Comparison>,
    /// The comparisons here.
    pub here: Vec<Comparison>,
    /// Whether the rule holds on the paper's numbers (a check of the rule).
    pub holds_in_paper: bool,
    /// The verdict here.
    pub verdict: Verdict,
    /// The share of seed resamples of the grid on which the rule gives
    /// the same verdict ([`super::uncertainty`]); `None` until measured,
    /// and for a finding not testable here.
    pub replication: Option<f64>,
}

impl Finding {
    fn new(claim: &str, measure: &str, rule: Rule, paper: Vec<Comparison>, here: Vec<Comparison>) -> Finding {
        let judge = |cs: &[Comparison]| -> Verdict {
            let holds: Option<Vec<bool>> = cs.iter().map(|c| rule.holds(c.a, c.b, c.p)).collect();
            match holds {
                None => Verdict::NotTestable,
                Some(h) if h.iter().all(|&x| x) => Verdict::Reproduced,
                Some(_) => Verdict::NotReproduced,
            }
        };
        Finding {
            claim: claim.into(),
            measure: measure.into(),
            rule,
            holds_in_paper: judge(&paper) == Verdict::Reproduced,
            verdict: judge(&here),
            replication: None,
            paper,
            here,
        }
    }
}

/// A comparison of two samples here, with Welch's p.
fn compare(label: &str, a: &[f64], b: &[f64]) -> Comparison {
    Comparison {
        label: label.into(),
        n_a: a.len(),
        n_b: b.len(),
        a: mean_sd(a).0,
        b: mean_sd(b).0,
        p: welch(a, b).p,
    }
}

/// A comparison of the paper's means.
fn paper(label: &str, n: usize, a: f64, b: f64, p: f64) -> Comparison {
    Comparison {
        label: label.into(),
        n_a: n,
        n_b: n,
        a,
        b,
        p,
    }
}

/// The paper's mean of `config`'s champions under `metric` over `tasks`
/// (equal runs per task, so the mean of the task means).
fn paper_mean(config: GridConfig, metric: Metric, tasks: &[Task]) -> f64 {
    let means: Vec<f64> = tasks
        .iter()
        .map(|&t| paper_cell(config, metric, Some(t)).map_or(f64::NAN, |c| c.mean))
        .collect();
    means.iter().sum::<f64>() / means.len() as f64
}

/// Every finding of the paper, judged on `results`.
pub fn findings(results: &GridResults) -> Vec<Finding> {
    let tasks = &results.spec.tasks;
    let champions = |config: GridConfig| results.values(config, tasks, Metric::Champion);
    let base = champions(BASELINE);
    let all = PAPER_RUNS_ALL;
    let mut out: Vec<Finding> = [
        (
            Preset::MaxCredit,
            "max credit is clearly better than the baseline",
            Rule::Better,
        ),
        (
            Preset::Systematic,
            "systematic sampling is no worse than the baseline",
            Rule::NoWorse,
        ),
        (
            Preset::EraseBest,
            "erasing the best network is better than the baseline",
            Rule::Better,
        ),
        (
            Preset::LesionOff,
            "switching lesion tests off is no worse than the baseline",
            Rule::NoWorse,
        ),
        (
            Preset::HillClimb,
            "hill-climbing is about as good as baseline ESP",
            Rule::AboutAsGood,
        ),
    ]
    .into_iter()
    .map(|(preset, claim, rule)| {
        let config = GridConfig::Preset(preset);
        let cell = paper_cell(config, Metric::Champion, None).expect("the paper has All for Tables 4-7");
        let base_all = paper_cell(BASELINE, Metric::Champion, None).expect("Table 1 has All");
        Finding::new(
            claim,
            &format!("{} vs baseline, champion fitness (%), all tasks", preset.name()),
            rule,
            vec![paper("All", all, cell.mean, base_all.mean, cell.p.unwrap_or(f64::NAN))],
            vec![compare("All", &champions(config), &base)],
        )
    })
    .collect();
    out.extend(robustness_findings(results));
    let bursts = |config: GridConfig| results.values(config, tasks, Metric::Bursts);
    let max_credit = GridConfig::Preset(Preset::MaxCredit);
    out.push(Finding::new(
        "max credit needs fewer burst mutations than the baseline",
        "max-credit vs baseline, burst mutations per run, all tasks",
        Rule::Fewer,
        vec![paper(
            "All",
            PAPER_BURST_RUNS,
            paper_bursts_per_run(max_credit).unwrap_or(f64::NAN),
            paper_bursts_per_run(BASELINE).unwrap_or(f64::NAN),
            f64::NAN,
        )],
        vec![compare("All", &bursts(max_credit), &bursts(BASELINE))],
    ));
    out
}

/// The collapse of the baseline champions and the gain from evolving under noise.
fn robustness_findings(results: &GridResults) -> Vec<Finding> {
    let tasks = &results.spec.tasks;
    let random_tasks: Vec<Task> = tasks.iter().copied().filter(|t| t.has_random_init()).collect();
    let v = |config: GridConfig, tasks: &[Task], metric: Metric| results.values(config, tasks, metric);
    let all = PAPER_RUNS_ALL;
    let paper_random: Vec<Task> = PAPER_TASKS.into_iter().filter(|t| t.has_random_init()).collect();
    let noise_all = paper_cell(BASELINE, Metric::InputNoise, None).map_or(f64::NAN, |c| c.mean);
    let clean_all = paper_cell(BASELINE, Metric::Clean, None).map_or(f64::NAN, |c| c.mean);
    // Tasks 1 and 2, both tested under input noise.
    let source = Metric::InputNoise;
    let (paper_doubling, here_doubling) = {
        [Task::StopRotation, Task::Turn]
            .iter()
            .map(|&t| {
                let label = format!("task {t}");
                let (a, b) = (
                    paper_cell(GridConfig::InputNoise, source, Some(t)),
                    paper_cell(BASELINE, source, Some(t)),
                );
                let here = compare(
                    &label,
                    &v(GridConfig::InputNoise, &[t], source),
                    &v(BASELINE, &[t], source),
                );
                let paper = paper(
                    &label,
                    PAPER_RUNS_PER_TASK,
                    a.map_or(f64::NAN, |c| c.mean),
                    b.map_or(f64::NAN, |c| c.mean),
                    f64::NAN,
                );
                (paper, here)
            })
            .unzip::<_, _, Vec<_>, Vec<_>>()
    };
    vec![
        Finding::new(
            "baseline champions collapse under input noise",
            "baseline champions under input noise (sd 0.05) vs flown clean, all tasks",
            Rule::Collapse,
            vec![paper("All", all, noise_all, clean_all, f64::NAN)],
            vec![compare(
                "All",
                &v(BASELINE, tasks, Metric::InputNoise),
                &v(BASELINE, tasks, Metric::Clean),
            )],
        ),
        Finding::new(
            "baseline champions collapse under random initialisation",
            "baseline champions from random initial conditions vs flown clean, tasks 1 and 3",
            Rule::Collapse,
            vec![paper(
                "tasks 1 and 3",
                PAPER_RUNS_PER_TASK * paper_random.len(),
                paper_mean(BASELINE, Metric::RandomInit, &paper_random),
                paper_mean(BASELINE, Metric::Clean, &paper_random),
                f64::NAN,
            )],
            vec![compare(
                "tasks 1 and 3",
                &v(BASELINE, &random_tasks, Metric::RandomInit),
                &v(BASELINE, &random_tasks, Metric::Clean),
            )],
        ),
        Finding::new(
            "evolving under input noise roughly doubles the noisy scores on tasks 1 and 2",
            "input-noise vs baseline champions, both tested under input noise (Table 3 vs Table 2)",
            Rule::Doubling,
            paper_doubling,
            here_doubling,
        ),
    ]
}
