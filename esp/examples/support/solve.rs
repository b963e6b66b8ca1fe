//! Runs ESP to a goal for many seeds and sums up the evaluations it took.

use esp_neuroevolution::{Ending, Esp, EspSettings, Evaluator, StopAt};

/// How one seed went: the evaluation that reached the goal, or none within
/// the budget.
pub struct Seed {
    /// The evaluation (from 1) whose network reached the goal.
    pub solved_at: Option<u64>,
    /// The champion's fitness.
    pub best: f64,
    /// The champion's hidden neurons.
    pub hidden: usize,
}

/// Runs seeds `1..=seeds` of ESP with `settings` on `evaluator` until the
/// champion's fitness reaches `goal` or `budget` evaluations are spent,
/// printing a line per seed unless `quiet`.
pub fn solve(
    settings: &EspSettings,
    evaluator: &impl Evaluator,
    seeds: u64,
    goal: f64,
    budget: u64,
    quiet: bool,
) -> Result<Vec<Seed>, Box<dyn std::error::Error>> {
    let stop = StopAt {
        goal: Some(goal),
        evaluations: Some(budget),
    };
    let mut outcomes = Vec::new();
    for seed in 1..=seeds {
        let result = Esp::new(settings.clone(), seed)?.stop_at(stop).run(evaluator, |_| {})?;
        let champion = &result.champion;
        let outcome = Seed {
            solved_at: (result.ending == Ending::Goal).then_some(champion.evaluation),
            best: champion.fitness,
            hidden: champion.network.hidden(),
        };
        if !quiet {
            match outcome.solved_at {
                Some(evaluation) => println!(
                    "seed {seed:>3}: solved at evaluation {evaluation:>7} (generation {}, {} hidden neurons)",
                    champion.generation, outcome.hidden
                ),
                None => println!(
                    "seed {seed:>3}: not solved in {} evaluations (best {})",
                    result.evaluations(),
                    outcome.best
                ),
            }
        }
        outcomes.push(outcome);
    }
    Ok(outcomes)
}

/// The evaluations to solve of the seeds that solved: how many, their
/// mean, standard deviation and median (`None` when none solved).
pub fn summary(outcomes: &[Seed]) -> Option<(usize, f64, f64, f64)> {
    let mut solved: Vec<f64> = outcomes.iter().filter_map(|o| o.solved_at).map(|e| e as f64).collect();
    if solved.is_empty() {
        return None;
    }
    let n = solved.len() as f64;
    let mean = solved.iter().sum::<f64>() / n;
    let sd = (solved.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    solved.sort_by(f64::total_cmp);
    let middle = solved.len() / 2;
    let median = if solved.len() % 2 == 1 {
        solved[middle]
    } else {
        (solved[middle - 1] + solved[middle]) / 2.0
    };
    Some((solved.len(), mean, sd, median))
}
