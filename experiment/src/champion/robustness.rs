//! The robustness stage (Tables 2 and 3): a champion flown many times under
//! input noise and, for tasks 1 and 3, from random initial conditions.

use anyhow::Result;
use serde::{Deserialize, Serialize};

use crate::PAPER_NOISE_SD;
use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::stream;
use psa_sim::evaluator::{trial_scores, EvalPath};
use psa_sim::psa::{mean_of_trials, NoiseSettings, PsaSettings, Task};

/// Stream keys of the robustness tests (the evolution's own keys are below 100).
const CLEAN: u64 = 101;
const INPUT_NOISE: u64 = 102;
const RANDOM_INIT: u64 = 103;

/// Mean and sample standard deviation of a champion's fitness over trials (%).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrialSummary {
    /// Mean fitness (% of the theoretical maximum).
    pub mean: f64,
    /// Sample standard deviation over the trials.
    pub sd: f64,
}

impl TrialSummary {
    /// The summary of `values` (sd 0 for a single value).
    pub fn of(values: &[f64]) -> TrialSummary {
        let (mean, sd) = crate::results::stats::mean_sd(values);
        TrialSummary {
            mean,
            sd: if values.len() > 1 { sd } else { 0.0 },
        }
    }
}

/// What `robustness.json` holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Robustness {
    /// Trials of each test.
    pub trials: usize,
    /// The input noise of the noise test (sd). `[paper]` 0.05
    pub input_noise_sd: f64,
    /// The champion flown once without noise from the task's standard start.
    pub clean: f64,
    /// Under Gaussian input noise.
    pub input_noise: TrialSummary,
    /// From random initial conditions (tasks 1 and 3; none for task 2).
    pub random_init: Option<TrialSummary>,
    /// Whether the champion is scored apart from its evolution: with
    /// another fitness than evolution's (`problem.fitness.scoring`), or
    /// re-tested by `psa-esp rescore`. Its reported score (Tables 1 and
    /// 4-7) is then `clean`, not the run's champion fitness.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub rescored: bool,
}

/// The settings of a champion's clean test under `problem` on `task`:
/// scored with its scoring fitness, without noise (but for where noise
/// would enter and whether it would reach the bias), from the task's start, one trial. The noisy and
/// random-start tests are these with the paper's noise, random starts and
/// the test's trials; so two problems with the same tested settings give
/// the same robustness results.
pub fn tested_settings(problem: &PsaSettings, task: Task) -> Result<PsaSettings> {
    let scored = problem.scoring_for(task)?;
    Ok(PsaSettings {
        noise: NoiseSettings {
            on_bias: problem.noise.on_bias,
            stage: problem.noise.stage,
            ..NoiseSettings::default()
        },
        random_init: false,
        trials: 1,
        ..scored
    })
}

/// Runs the robustness tests of `champion` on `task`. `problem` is the
/// run's control problem, scored with its scoring fitness
/// ([`PsaSettings::scoring_for`]); its noise, random initialisation and
/// trials are replaced by each test's own (the input noise keeps whether it
/// reaches the bias). Each test's trials fly on `path`
/// ([`trial_scores`]): on `native`'s batched path side by side, one trial
/// per lane; on a kernel (the GPU with `--backend cuda`) in one launch;
/// else one after another. The same scores on every path.
pub fn test_robustness(
    champion: &Network,
    task: Task,
    problem: &PsaSettings,
    trials: usize,
    seed: u64,
    path: &EvalPath,
) -> Result<Robustness> {
    let base = tested_settings(problem, task)?;
    let scores =
        |settings: &PsaSettings, key: u64| trial_scores(settings, task, champion, &mut stream(seed, &[key]), path);
    let clean = mean_of_trials(&scores(&base, CLEAN)?);
    let noisy = PsaSettings {
        noise: NoiseSettings {
            input_sd: PAPER_NOISE_SD,
            ..base.noise
        },
        trials,
        ..base.clone()
    };
    let input_noise = TrialSummary::of(&scores(&noisy, INPUT_NOISE)?);
    let random_init = if task.has_random_init() {
        let random = PsaSettings {
            random_init: true,
            trials,
            ..base
        };
        Some(TrialSummary::of(&scores(&random, RANDOM_INIT)?))
    } else {
        None
    };
    Ok(Robustness {
        trials,
        input_noise_sd: PAPER_NOISE_SD,
        clean,
        input_noise,
        random_init,
        rescored: problem.rescored(task),
    })
}
