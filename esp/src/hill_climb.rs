//! Høverstad's parallel stochastic hill-climber: every cycle, mutate the
//! base network into candidates, evaluate them, and take the best as the
//! next base (elitist: only when at least as good).

use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::ask::{AskPurpose, Asked, Networks};
use crate::limits::{
    check_cauchy_limit, check_count, check_positive, check_probability, MAX_GENERATIONS, MAX_HIDDEN,
    MAX_NETWORKS_PER_GENERATION,
};
use crate::network::Network;
use crate::operators::{cauchy, random_genes};
use crate::rng::{stream, Stream};
use crate::run::{drive, public_run, Advance, Driver, Search};
use crate::{
    best_of, min_and_mean, purpose, Champion, Control, Evaluator, GenerationRecord, RunError, RunResult, SettingsError,
    StopAt,
};

/// Every setting of the hill-climber, named in configuration files as
/// `hill_climb.<field>`. Høverstad's paper gives the algorithm but few
/// numbers: the defaults marked `[chosen]` are chosen here (they give it
/// ESP's budget of 400 networks a cycle for 2000 cycles), those marked
/// `[paper]` are his. Bounds are checked by [`HillClimbSettings::validate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HillClimbSettings {
    /// Hidden neurons of the network. Default 5 `[chosen]`, as ESP's
    /// start. Bounds: 1 to 100.
    pub hidden: usize,
    /// Candidates per cycle (K). Default 400 `[chosen]`, ESP's networks a
    /// generation. Bounds: 1 to 100,000.
    pub candidates: usize,
    /// Cycles. Default 2000 `[chosen]`, ESP's generations. Bounds: 1 to
    /// 1,000,000.
    pub cycles: usize,
    /// Initial weights are uniform in (-range, range). Default 6 `[paper]`,
    /// as ESP. Bounds: (0, 1e6].
    pub init_range: f64,
    /// Probability that a weight gets Cauchy noise. Default 0.2 `[chosen]`.
    /// Bounds: [0, 1].
    pub p_noise: f64,
    /// Scale of that noise (alpha). Default 0.3 `[chosen]`, ESP's own
    /// Cauchy scale (the paper's parallel; psa-esp's docs/sweeps/s26-hill-climber.md).
    /// Bounds: (0, 1e6].
    pub alpha: f64,
    /// Probability that a weight then changes sign. Default 0.05
    /// `[chosen]`. Bounds: [0, 1].
    pub p_flip: f64,
    /// p_noise is multiplied by this after every cycle. Default 0.999
    /// `[chosen]`. Bounds: (0, 1e6].
    pub anneal_noise: f64,
    /// alpha is multiplied by this after every cycle. Default 0.999
    /// `[chosen]`. Bounds: (0, 1e6].
    pub anneal_alpha: f64,
    /// p_flip is multiplied by this after every cycle (the product capped
    /// at 1). Default 0.999 `[chosen]`. Bounds: (0, 1e6].
    pub anneal_flip: f64,
    /// Keep the base unless a candidate is at least as good (Høverstad
    /// reports it worse). Default false `[paper]`.
    pub elitist: bool,
    /// Cauchy draws larger than this in magnitude are drawn again. Default
    /// 10 `[chosen]`, as ESP. Bounds: (0, 1e6] and at least 0.1 x the
    /// largest annealed alpha.
    pub cauchy_limit: f64,
}

impl Default for HillClimbSettings {
    fn default() -> Self {
        HillClimbSettings {
            hidden: 5,
            candidates: 400,
            cycles: 2000,
            init_range: 6.0,
            p_noise: 0.2,
            alpha: 0.3,
            p_flip: 0.05,
            anneal_noise: 0.999,
            anneal_alpha: 0.999,
            anneal_flip: 0.999,
            elitist: false,
            cauchy_limit: 10.0,
        }
    }
}

impl HillClimbSettings {
    /// Rejects out-of-range values, naming the setting.
    pub fn validate(&self) -> Result<(), SettingsError> {
        check_count("hill_climb.hidden", self.hidden, 1, MAX_HIDDEN)?;
        check_count("hill_climb.candidates", self.candidates, 1, MAX_NETWORKS_PER_GENERATION)?;
        check_count("hill_climb.cycles", self.cycles, 1, MAX_GENERATIONS)?;
        check_positive("hill_climb.init_range", self.init_range)?;
        check_positive("hill_climb.alpha", self.alpha)?;
        check_positive("hill_climb.cauchy_limit", self.cauchy_limit)?;
        check_probability("hill_climb.p_noise", self.p_noise)?;
        check_probability("hill_climb.p_flip", self.p_flip)?;
        for (name, c) in [
            ("hill_climb.anneal_noise", self.anneal_noise),
            ("hill_climb.anneal_alpha", self.anneal_alpha),
            ("hill_climb.anneal_flip", self.anneal_flip),
        ] {
            check_positive(name, c)?;
        }
        // alpha is annealed every cycle: the largest scale is the first
        // cycle's or (annealing upwards) the last's.
        let last = self.alpha * self.anneal_alpha.powi(self.cycles as i32 - 1);
        check_cauchy_limit(
            "hill_climb.cauchy_limit",
            self.cauchy_limit,
            "the largest annealed hill_climb.alpha",
            self.alpha.max(last),
        )
    }
}

/// The mutation parameters of one cycle, after annealing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MutationRates {
    /// Probability of Cauchy noise per weight.
    pub p_noise: f64,
    /// Its scale.
    pub alpha: f64,
    /// Probability of a sign change per weight.
    pub p_flip: f64,
}

/// A hill-climbing run: settings, seed and when to stop early. Read from
/// JSON it is checked as [`HillClimb::new`] checks it; the seed is written
/// as a string (a number is read too).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "UncheckedHillClimb")]
pub struct HillClimb {
    settings: HillClimbSettings,
    #[serde(with = "crate::rng::u64_string")]
    seed: u64,
    stop: StopAt,
}

/// A [`HillClimb`] as read, before its settings are checked.
#[derive(Deserialize)]
struct UncheckedHillClimb {
    settings: HillClimbSettings,
    #[serde(with = "crate::rng::u64_string")]
    seed: u64,
    stop: StopAt,
}

impl TryFrom<UncheckedHillClimb> for HillClimb {
    type Error = SettingsError;
    fn try_from(raw: UncheckedHillClimb) -> Result<HillClimb, SettingsError> {
        Ok(HillClimb::new(raw.settings, raw.seed)?.stop_at(raw.stop))
    }
}

impl HillClimb {
    /// A run with `settings` and `seed`; fails on invalid settings.
    pub fn new(settings: HillClimbSettings, seed: u64) -> Result<HillClimb, SettingsError> {
        settings.validate()?;
        Ok(HillClimb {
            settings,
            seed,
            stop: StopAt::NEVER,
        })
    }

    /// This run, ending early when `stop` says so (checked when the run
    /// starts: [`StopAt::validate`]).
    pub fn stop_at(self, stop: StopAt) -> HillClimb {
        HillClimb { stop, ..self }
    }

    /// The settings.
    pub fn settings(&self) -> &HillClimbSettings {
        &self.settings
    }

    /// The rates of cycle `cycle` (from 1): each initial rate times its
    /// annealing constant to the power `cycle - 1`. Cycle 0 does not exist
    /// ([`SettingsError::TooFew`]).
    pub fn rates(&self, cycle: usize) -> Result<MutationRates, SettingsError> {
        check_count("cycle", cycle, 1, usize::MAX)?;
        let s = &self.settings;
        let k = i32::try_from(cycle - 1).unwrap_or(i32::MAX);
        Ok(MutationRates {
            p_noise: s.p_noise * s.anneal_noise.powi(k),
            alpha: s.alpha * s.anneal_alpha.powi(k),
            p_flip: (s.p_flip * s.anneal_flip.powi(k)).min(1.0),
        })
    }

    /// Mutates every weight: Cauchy noise with probability `p_noise`, then a
    /// sign change with probability `p_flip`.
    pub fn mutate(&self, genes: &mut [f64], rates: MutationRates, rng: &mut Stream) {
        for w in genes {
            if rng.random::<f64>() < rates.p_noise {
                *w += cauchy(rng, rates.alpha, self.settings.cauchy_limit);
            }
            if rng.random::<f64>() < rates.p_flip {
                *w = -*w;
            }
        }
    }

    /// Starts the run on networks of `inputs` inputs (the bias included)
    /// and `outputs` outputs, to be driven by ask and tell ([`AskTell`](crate::AskTell)).
    /// Fails on a size of 0 and on stop conditions out of range.
    pub fn start(&self, inputs: usize, outputs: usize) -> Result<HillClimbRun, RunError> {
        self.stop.validate()?;
        let s = &self.settings;
        let mut rng = stream(self.seed, &[purpose::INIT]);
        let base = Network::from_genes(
            inputs,
            outputs,
            random_genes(&mut rng, s.hidden * (inputs + outputs), s.init_range),
        )?;
        let state = State {
            base,
            base_fitness: None,
            evaluations: 0,
            champion: None,
        };
        Ok(HillClimbRun(Driver::new(self.clone(), state)))
    }

    /// Runs the cycles on the current rayon pool, calling `on_cycle` after
    /// each, until the last, or until the stop conditions
    /// ([`HillClimb::stop_at`]) or `on_cycle` (returning [`Control::Stop`])
    /// end the run. A loop over [`HillClimb::start`]'s ask, evaluate and
    /// tell.
    pub fn run<E: Evaluator, C: Into<Control>>(
        &self,
        evaluator: &E,
        on_cycle: impl FnMut(&GenerationRecord) -> C,
    ) -> Result<RunResult, RunError> {
        let mut run = self.start(evaluator.inputs(), evaluator.outputs())?;
        drive(&mut run, evaluator, on_cycle)?;
        run.into_result()
    }

    /// Cycle `cycle`'s candidates: the base mutated with the cycle's
    /// rates, candidate `j` with its own stream.
    fn candidates(&self, base: &Network, cycle: usize) -> Result<Vec<Network>, RunError> {
        let rates = self.rates(cycle)?;
        let (inputs, outputs) = (base.inputs(), base.outputs());
        (0..self.settings.candidates)
            .map(|j| {
                let mut genes = base.genes().to_vec();
                self.mutate(
                    &mut genes,
                    rates,
                    &mut stream(self.seed, &[purpose::MUTATE, cycle as u64, j as u64]),
                );
                Ok(Network::from_genes(inputs, outputs, genes)?)
            })
            .collect()
    }

    /// The cycle after its candidates scored `fitness`: champion, base, record.
    fn conclude(&self, state: &mut State, candidates: Vec<Network>, fitness: &[f64], cycle: usize) -> GenerationRecord {
        let s = &self.settings;
        let (top, top_fitness) = best_of(fitness);
        if state.champion.as_ref().is_none_or(|c| top_fitness > c.fitness) {
            state.champion = Some(Champion {
                network: candidates[top].clone(),
                fitness: top_fitness,
                generation: cycle,
                evaluation: state.evaluations + top as u64 + 1,
            });
        }
        state.evaluations += candidates.len() as u64;
        if !s.elitist || state.base_fitness.is_none_or(|base| top_fitness >= base) {
            state.base = candidates.into_iter().nth(top).expect("the best is a candidate");
            state.base_fitness = Some(top_fitness);
        }
        let (min, mean) = min_and_mean(fitness);
        GenerationRecord {
            generation: cycle,
            min,
            mean,
            max: top_fitness,
            best: state.base_fitness,
            champion: state.champion.as_ref().map_or(f64::NAN, |c| c.fitness),
            evaluations: state.evaluations,
            subpops: s.hidden,
            burst: false,
            bursts: 0,
            lesion: None,
        }
    }
}

/// A hill-climbing run's state between cycles.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct State {
    /// The network the candidates are mutated from.
    base: Network,
    /// Its fitness, once evaluated (elitist: before cycle 1; else as the
    /// best candidate of the last cycle).
    base_fitness: Option<f64>,
    /// Networks evaluated so far.
    evaluations: u64,
    /// The best network ever evaluated.
    champion: Option<Champion>,
}

/// What a hill-climbing run asks for.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum Step {
    /// The base, for elitist acceptance, before cycle 1.
    Base,
    /// A cycle's candidates.
    Candidates(Vec<Network>),
}

impl Search for HillClimb {
    type State = State;
    type Step = Step;

    fn generations(&self) -> usize {
        self.settings.cycles
    }

    fn stop_at(&self) -> StopAt {
        self.stop
    }

    fn check(&self, state: &State, step: Option<&Step>) -> Result<(), RunError> {
        self.settings.validate()?;
        self.stop.validate()?;
        let shape = (state.base.inputs(), state.base.outputs(), state.base.hidden());
        let fits = |network: &Network| (network.inputs(), network.outputs(), network.hidden()) == shape;
        let candidates_fit = match step {
            Some(Step::Candidates(candidates)) => {
                candidates.len() == self.settings.candidates && candidates.iter().all(fits)
            }
            Some(Step::Base) | None => true,
        };
        if state.base.hidden() == self.settings.hidden && candidates_fit {
            Ok(())
        } else {
            Err(RunError::Restore(format!(
                "the base or the candidates do not fit {} hidden neurons and {} candidates",
                self.settings.hidden, self.settings.candidates
            )))
        }
    }

    /// Cycle `cycle`'s networks: the base first where elitist acceptance
    /// needs its fitness, else the candidates.
    fn begin(&self, state: &State, cycle: usize) -> Result<Step, RunError> {
        if self.settings.elitist && state.base_fitness.is_none() {
            return Ok(Step::Base);
        }
        Ok(Step::Candidates(self.candidates(&state.base, cycle)?))
    }

    fn asked<'a>(&self, state: &'a State, step: &'a Step, cycle: usize) -> Asked<'a> {
        match step {
            Step::Base => Asked::new(
                Networks::List(std::slice::from_ref(&state.base)),
                AskPurpose::Base,
                self.seed,
                [purpose::EVALUATE, 0],
            ),
            Step::Candidates(candidates) => Asked::new(
                Networks::List(candidates),
                AskPurpose::Generation(cycle),
                self.seed,
                [purpose::EVALUATE, cycle as u64],
            ),
        }
    }

    fn advance(&self, state: &mut State, step: Step, fitness: &[f64], cycle: usize) -> Advance<Step> {
        match step {
            Step::Base => {
                state.evaluations += 1;
                state.base_fitness = Some(fitness[0]);
                Advance::Begin
            }
            Step::Candidates(candidates) => Advance::Record(self.conclude(state, candidates, fitness, cycle)),
        }
    }

    fn champion(state: &State) -> Option<&Champion> {
        state.champion.as_ref()
    }

    fn into_champion(state: State) -> Option<Champion> {
        state.champion
    }
}

/// A run of [`HillClimb`] under way: [`AskTell::ask`](crate::AskTell::ask)
/// gives the networks to evaluate next (elitist: the base first; then each
/// cycle's candidates), [`AskTell::tell`](crate::AskTell::tell) their
/// fitness. Made by [`HillClimb::start`]; the same run, bit for bit, as
/// [`HillClimb::run`]. Saved and restored by serde, as [`EspRun`](crate::EspRun).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(transparent)]
pub struct HillClimbRun(Driver<HillClimb>);

public_run!(HillClimbRun);

impl HillClimbRun {
    /// The run's settings and stop conditions.
    pub fn hill_climb(&self) -> &HillClimb {
        self.0.search()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Ending;
    use crate::FnEvaluator;

    #[test]
    fn noise_and_sign_flips_happen_at_the_configured_rates() {
        let hc = HillClimb::new(HillClimbSettings::default(), 1).unwrap();
        let rates = MutationRates {
            p_noise: 0.2,
            alpha: 0.3,
            p_flip: 0.0,
        };
        let mut genes = vec![0.0; 50_000];
        hc.mutate(&mut genes, rates, &mut stream(1, &[]));
        let noisy = genes.iter().filter(|g| **g != 0.0).count();
        assert!((9_600..10_400).contains(&noisy), "{noisy} of 50000, expected 10000");
        let rates = MutationRates {
            p_noise: 0.0,
            alpha: 0.3,
            p_flip: 0.05,
        };
        let mut genes = vec![1.0; 50_000];
        hc.mutate(&mut genes, rates, &mut stream(2, &[]));
        assert!(genes.iter().all(|g| g.abs() == 1.0), "a flip changes the sign only");
        let flipped = genes.iter().filter(|g| **g < 0.0).count();
        assert!((2_300..2_700).contains(&flipped), "{flipped} of 50000, expected 2500");
    }

    #[test]
    fn each_rate_is_annealed_by_its_own_constant() {
        let settings = HillClimbSettings {
            p_noise: 0.2,
            alpha: 1.0,
            p_flip: 0.05,
            anneal_noise: 0.9,
            anneal_alpha: 0.5,
            anneal_flip: 0.99,
            ..HillClimbSettings::default()
        };
        let hc = HillClimb::new(settings, 1).unwrap();
        assert_eq!(
            hc.rates(1).unwrap(),
            MutationRates {
                p_noise: 0.2,
                alpha: 1.0,
                p_flip: 0.05
            }
        );
        let r = hc.rates(11).unwrap();
        assert!((r.p_noise - 0.2 * 0.9f64.powi(10)).abs() < 1e-15);
        assert!((r.alpha - 0.5f64.powi(10)).abs() < 1e-15);
        assert!((r.p_flip - 0.05 * 0.99f64.powi(10)).abs() < 1e-15);
    }

    #[test]
    fn non_elitist_takes_the_best_candidate_even_when_worse_elitist_does_not() {
        // Fitness is pure noise: the best candidate is often worse than the base.
        let noise = FnEvaluator::new(2, 1, |_: &Network, rng: &mut Stream| Ok(rng.random::<f64>()));
        let settings = HillClimbSettings {
            candidates: 5,
            cycles: 60,
            ..HillClimbSettings::default()
        };
        let plain = HillClimb::new(settings.clone(), 3)
            .unwrap()
            .run(&noise, |_| {})
            .unwrap();
        for r in &plain.records {
            assert_eq!(r.best, Some(r.max), "the base is always the cycle's best candidate");
        }
        assert!(
            plain.records.windows(2).any(|w| w[1].best < w[0].best),
            "it accepted a worse base"
        );
        let elitist = HillClimb::new(
            HillClimbSettings {
                elitist: true,
                ..settings
            },
            3,
        )
        .unwrap()
        .run(&noise, |_| {})
        .unwrap();
        assert!(
            elitist.records.windows(2).all(|w| w[1].best >= w[0].best),
            "never worse"
        );
        assert!(
            elitist.records.iter().any(|r| r.best > Some(r.max)),
            "kept the base over worse candidates"
        );
        assert_eq!(
            elitist.records.last().unwrap().evaluations,
            1 + 5 * 60,
            "the base is evaluated once"
        );
        // The champion is the best network ever evaluated.
        let top = plain.records.iter().map(|r| r.max).fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(plain.champion.fitness, top);
    }

    #[test]
    fn a_run_stops_at_its_goal_or_budget_and_counts_the_champions_evaluation() {
        let noise = FnEvaluator::new(2, 1, |_: &Network, rng: &mut Stream| Ok(rng.random::<f64>()));
        let settings = HillClimbSettings {
            candidates: 7,
            cycles: 50,
            elitist: true,
            ..HillClimbSettings::default()
        };
        let whole = HillClimb::new(settings.clone(), 4)
            .unwrap()
            .run(&noise, |_| {})
            .unwrap();
        assert_eq!((whole.ending, whole.evaluations()), (Ending::Completed, 1 + 50 * 7));
        let goal = whole.records[20].champion;
        let stopped = HillClimb::new(settings.clone(), 4)
            .unwrap()
            .stop_at(StopAt {
                goal: Some(goal),
                ..StopAt::NEVER
            })
            .run(&noise, |_| {})
            .unwrap();
        let first = whole.records.iter().position(|r| r.champion >= goal).unwrap();
        assert_eq!(stopped.ending, Ending::Goal);
        assert_eq!(
            stopped.records[..],
            whole.records[..=first],
            "the same run up to the goal"
        );
        let champion = &stopped.champion;
        // The elitist base's evaluation comes first, then 7 per cycle.
        assert!(champion.evaluation > 1 + 7 * (champion.generation as u64 - 1));
        assert!(champion.evaluation <= 1 + 7 * champion.generation as u64);
        let budget = HillClimb::new(settings, 4)
            .unwrap()
            .stop_at(StopAt {
                evaluations: Some(100),
                ..StopAt::NEVER
            })
            .run(&noise, |_| {})
            .unwrap();
        // 1 + 7 x 15 = 106 is the first count of at least 100.
        assert_eq!(
            (budget.ending, budget.records.len(), budget.evaluations()),
            (Ending::Budget, 15, 106)
        );
    }
}
