//! What the integration tests share: a problem that stagnates often, small
//! settings, and a run's result as bits.

use esp_neuroevolution::network::Network;
use esp_neuroevolution::rand::RngExt;
use esp_neuroevolution::rng::Stream;
use esp_neuroevolution::{EspSettings, Evaluator, FnEvaluator, RunResult};

/// A noisy function to fit: output 0 should be x^2 at 8 points x in [0, 1]
/// drawn from the evaluation's stream (inputs x and a bias), so a network
/// evaluated with another stream scores differently; the error is
/// rounded to steps of 0.25, so the search stagnates often.
pub fn problem() -> impl Evaluator<Worker = ()> {
    FnEvaluator::new(2, 1, |net: &Network, rng: &mut Stream| {
        let mut out = [0.0];
        let mut error = 0.0;
        for _ in 0..8 {
            let x: f64 = rng.random();
            net.activate(&[x, 1.0], &mut out);
            error += (out[0] - x * x).powi(2);
        }
        Ok(-(error * 4.0).round() / 4.0)
    })
}

/// Settings that stagnate often: bursts and lesion tests (both kinds for
/// discard-all) within a few dozen generations.
pub fn small(settings: EspSettings) -> EspSettings {
    EspSettings {
        subpop_size: 8,
        trials_per_neuron: 2,
        initial_hidden: 2,
        generations: 80,
        stagnation: 3,
        bursts_before_lesion: 1,
        ..settings
    }
}

/// Every bit of a result: records, ending and champion (Debug prints
/// every f64 exactly).
pub fn bits(result: &RunResult) -> String {
    format!("{:?} {:?} {:?}", result.records, result.ending, result.champion)
}
