//! The ODE check of a grid run on `native`: the champion flown again on
//! `ode`, where its fitness and its robustness results must come out bit
//! for bit as on `native` (the `native` backend integrates ODE's
//! `dWorldStep` rule for this body operation for operation). It makes a
//! grid run on the fast backend as faithful as one run on ODE.

use std::collections::BTreeMap;

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

use crate::champion::robustness::{test_robustness, Robustness};
use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::stream;
use psa_sim::evaluator::EvalPath;
use psa_sim::physics::BackendKind;
use psa_sim::psa::{PsaSettings, Task, TrialRunner};

/// Stream key of the champion's fitness in the check (beside the
/// robustness tests' keys).
const CHECK_FITNESS: u64 = 104;

/// One quantity on both backends.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Compared {
    /// Its value on `native`.
    pub native: f64,
    /// Its value on `ode`.
    pub ode: f64,
}

impl Compared {
    /// Whether both values are the same, bit for bit.
    pub fn identical(&self) -> bool {
        self.native.to_bits() == self.ode.to_bits()
    }
}

/// What `run.json` records of the check (under `ode_check`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OdeCheck {
    /// The champion's fitness under the run's own problem (its noise,
    /// random starts and trials), both backends on the same random stream.
    pub fitness: Compared,
    /// The robustness results, by name (`clean`, `input_noise_mean`,
    /// `input_noise_sd`, and for tasks 1 and 3 `random_init_mean`,
    /// `random_init_sd`).
    pub robustness: BTreeMap<String, Compared>,
    /// Whether every value is the same on both backends, bit for bit.
    pub identical: bool,
}

/// The named values of a robustness result.
fn robustness_values(r: &Robustness) -> Vec<(&'static str, f64)> {
    let mut values = vec![
        ("clean", r.clean),
        ("input_noise_mean", r.input_noise.mean),
        ("input_noise_sd", r.input_noise.sd),
    ];
    if let Some(random) = &r.random_init {
        values.extend([("random_init_mean", random.mean), ("random_init_sd", random.sd)]);
    }
    values
}

impl OdeCheck {
    /// The check of the results `native` (the run's robustness tests on
    /// `native`) and `ode` (the same on `ode`), and of the champion's
    /// fitness on both.
    pub fn new(fitness: Compared, native: &Robustness, ode: &Robustness) -> OdeCheck {
        let ode_values = robustness_values(ode);
        let robustness: BTreeMap<String, Compared> = robustness_values(native)
            .into_iter()
            .map(|(name, value)| {
                let other = ode_values
                    .iter()
                    .find(|(n, _)| *n == name)
                    .map_or(f64::NAN, |(_, v)| *v);
                (
                    name.to_string(),
                    Compared {
                        native: value,
                        ode: other,
                    },
                )
            })
            .collect();
        let identical = fitness.identical()
            && ode_values.len() == robustness.len()
            && robustness.iter().all(|(_, c)| c.identical());
        OdeCheck {
            fitness,
            robustness,
            identical,
        }
    }

    /// Every quantity, by name, fitness first.
    pub fn quantities(&self) -> impl Iterator<Item = (&str, &Compared)> {
        std::iter::once(("fitness", &self.fitness)).chain(self.robustness.iter().map(|(n, c)| (n.as_str(), c)))
    }

    /// An error naming `run`, the first quantity that differs and both its
    /// values, unless every value is identical.
    pub fn verify(&self, run: &str) -> Result<()> {
        if let Some((name, c)) = self.quantities().find(|(_, c)| !c.identical()) {
            bail!(
                "run {run}: the ODE check failed: the champion's {name} is {:?} on native but {:?} on ode (they must be bit-identical)",
                c.native,
                c.ode
            );
        }
        if !self.identical {
            bail!("run {run}: the ODE check failed: the robustness tests on native and ode gave different sets of results");
        }
        Ok(())
    }
}

/// Flies `champion` (evolved on `native` with the control problem
/// `problem`) again on `ode`: its fitness under `problem` on both backends
/// with the same stream (from `seed`), and the robustness tests of
/// [`test_robustness`] (`trials`, `seed`) on `ode`, compared with their
/// results on `native`, `native_robustness`.
pub fn check_on_ode(
    champion: &Network,
    task: Task,
    problem: &PsaSettings,
    trials: usize,
    seed: u64,
    native_robustness: &Robustness,
) -> Result<OdeCheck> {
    let on = |backend| PsaSettings {
        backend,
        ..problem.clone()
    };
    let (native, ode) = (on(BackendKind::Native), on(BackendKind::Ode));
    let fitness = |settings: &PsaSettings| -> Result<f64> {
        Ok(TrialRunner::new(settings, task)?.evaluate(champion, &mut stream(seed, &[CHECK_FITNESS]))?)
    };
    let fitness = Compared {
        native: fitness(&native)?,
        ode: fitness(&ode)?,
    };
    let ode_robustness = test_robustness(champion, task, &ode, trials, seed, &EvalPath::Fastest)?;
    Ok(OdeCheck::new(fitness, native_robustness, &ode_robustness))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random network whose input-noise robustness mean on task 3 depends
    /// on the noise drawn (most random networks score 0 whatever the draw).
    fn champion() -> Network {
        use rand::RngExt;
        (0..)
            .map(|k| {
                let mut rng = stream(k, &[7]);
                let genes = (0..5 * 11).map(|_| rng.random_range(-3.0..3.0)).collect();
                Network::from_genes(7, 4, genes).unwrap()
            })
            .find(|network| {
                let mean = |seed| {
                    test_robustness(network, Task::StopAtPosition, &native(), 4, seed, &EvalPath::Fastest)
                        .unwrap()
                        .input_noise
                        .mean
                };
                mean(5) != mean(6)
            })
            .expect("some network")
    }

    fn native() -> PsaSettings {
        PsaSettings {
            backend: BackendKind::Native,
            steps: 200,
            ..PsaSettings::default()
        }
    }

    #[test]
    fn the_same_flights_on_both_backends_are_identical() {
        let (task, seed) = (Task::StopAtPosition, 5);
        let robustness = test_robustness(&champion(), task, &native(), 4, seed, &EvalPath::Fastest).unwrap();
        let check = check_on_ode(&champion(), task, &native(), 4, seed, &robustness).unwrap();
        assert!(check.identical, "{check:?}");
        assert_eq!(check.robustness.len(), 5);
        check.verify("runs/x").unwrap();
    }

    #[test]
    fn a_difference_names_the_run_the_quantity_and_both_values() {
        // Real flights that differ: the native results of another seed
        // (another noise draw) against the ode results of this one.
        let (task, seed) = (Task::StopAtPosition, 5);
        let other = test_robustness(&champion(), task, &native(), 4, seed + 1, &EvalPath::Fastest).unwrap();
        let check = check_on_ode(&champion(), task, &native(), 4, seed, &other).unwrap();
        assert!(!check.identical);
        let on_ode = PsaSettings {
            backend: BackendKind::Ode,
            ..native()
        };
        let ode = test_robustness(&champion(), task, &on_ode, 4, seed, &EvalPath::Fastest).unwrap();
        // The clean flight draws nothing: the same; the noisy mean differs.
        assert!(check.robustness["clean"].identical());
        let (native_mean, ode_mean) = (other.input_noise.mean, ode.input_noise.mean);
        assert_ne!(native_mean, ode_mean);
        let err = check.verify("runs/baseline/task3/seed1").unwrap_err().to_string();
        for part in [
            "runs/baseline/task3/seed1".to_string(),
            "input_noise_mean".to_string(),
            format!("{native_mean:?} on native"),
            format!("{ode_mean:?} on ode"),
        ] {
            assert!(err.contains(&part), "{part:?} missing from {err}");
        }
        // A single bit is a difference.
        let fitness = Compared {
            native: 50.0,
            ode: f64::from_bits(50f64.to_bits() + 1),
        };
        let check = OdeCheck::new(fitness, &other, &other);
        assert!(!check.identical);
        assert!(check.verify("r").unwrap_err().to_string().contains("fitness"));
    }
}
