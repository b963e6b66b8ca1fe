//! Høverstad's parallel stochastic hill-climber (`algorithms.md` §3).

use rand::RngExt;
use serde::{Deserialize, Serialize};

use super::ask::{check_told, drive, AskPurpose, AskTell, Asked, Networks};
use super::operators::{cauchy, random_genes};
use super::{
    best_of, check_cauchy_limit, check_count, check_positive, check_probability, min_and_mean, purpose,
    MAX_GENERATIONS, MAX_HIDDEN, MAX_NETWORKS_PER_GENERATION,
};
use super::{
    Champion, Control, Ending, Evaluator, GenerationRecord, RunError, RunResult, SettingsError, StopAt,
    RECORDS_RESERVED,
};
use crate::network::Network;
use crate::rng::{stream, Stream};

/// Every setting of the hill-climber (`[chosen]` defaults give it ESP's budget).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HillClimbSettings {
    /// Hidden neurons of the network. `[chosen]` 5
    pub hidden: usize,
    /// Candidates per cycle (K). `[chosen]` 400
    pub candidates: usize,
    /// Cycles. `[chosen]` 2000
    pub cycles: usize,
    /// Initial weights are uniform in (-range, range). `[paper]` 6
    pub init_range: f64,
    /// Probability that a weight gets Cauchy noise. `[chosen]` 0.2
    pub p_noise: f64,
    /// Scale of that noise (alpha). `[chosen]` 1.0
    pub alpha: f64,
    /// Probability that a weight then changes sign. `[chosen]` 0.05
    pub p_flip: f64,
    /// p_noise is multiplied by this after every cycle. `[chosen]` 0.999
    pub anneal_noise: f64,
    /// alpha is multiplied by this after every cycle. `[chosen]` 0.999
    pub anneal_alpha: f64,
    /// p_flip is multiplied by this after every cycle. `[chosen]` 0.999
    pub anneal_flip: f64,
    /// Keep the base unless a candidate is at least as good (reported worse). `[paper]` false
    pub elitist: bool,
    /// Cauchy draws larger than this in magnitude are drawn again. `[chosen]` 10, as ESP
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
            alpha: 1.0,
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

/// A hill-climbing run: settings, seed and when to stop early.
#[derive(Debug, Clone)]
pub struct HillClimb {
    settings: HillClimbSettings,
    seed: u64,
    stop: StopAt,
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

    /// This run, ending early when `stop` says so.
    pub fn stop_at(self, stop: StopAt) -> HillClimb {
        HillClimb { stop, ..self }
    }

    /// The rates of cycle `cycle` (from 1): each initial rate times its
    /// annealing constant to the power `cycle - 1`.
    pub fn rates(&self, cycle: usize) -> MutationRates {
        let s = &self.settings;
        let k = (cycle - 1) as i32;
        MutationRates {
            p_noise: s.p_noise * s.anneal_noise.powi(k),
            alpha: s.alpha * s.anneal_alpha.powi(k),
            p_flip: (s.p_flip * s.anneal_flip.powi(k)).min(1.0),
        }
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
    /// Fails on a size of 0.
    pub fn start(&self, inputs: usize, outputs: usize) -> Result<HillClimbRun, RunError> {
        let s = &self.settings;
        let mut rng = stream(self.seed, &[purpose::INIT]);
        let base = Network::from_genes(
            inputs,
            outputs,
            random_genes(&mut rng, s.hidden * (inputs + outputs), s.init_range),
        )?;
        // The base's fitness matters only to elitist acceptance.
        let phase = if s.elitist { Phase::Base } else { Phase::Next };
        Ok(HillClimbRun {
            hill_climb: self.clone(),
            base,
            base_fitness: f64::NEG_INFINITY,
            evaluations: 0,
            champion: None,
            records: Vec::with_capacity(s.cycles.min(RECORDS_RESERVED)),
            cycle: 1,
            phase,
            stop_requested: false,
        })
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
        let rates = self.rates(cycle);
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
}

/// A run of [`HillClimb`] under way: [`AskTell::ask`] gives the networks
/// to evaluate next (elitist: the base first; then each cycle's
/// candidates), [`AskTell::tell`] their fitness. Made by
/// [`HillClimb::start`]; the same run, bit for bit, as [`HillClimb::run`].
pub struct HillClimbRun {
    hill_climb: HillClimb,
    base: Network,
    base_fitness: f64,
    evaluations: u64,
    champion: Option<Champion>,
    records: Vec<GenerationRecord>,
    /// The cycle under way, or the last one recorded.
    cycle: usize,
    phase: Phase,
    /// [`AskTell::stop`] was called.
    stop_requested: bool,
}

/// Where a hill-climbing run stands.
enum Phase {
    /// The base is asked (elitist acceptance, before cycle 1).
    Base,
    /// Cycle `cycle` is next: its candidates are not made yet.
    Next,
    /// Cycle `cycle`'s candidates are asked.
    Asking(Vec<Network>),
    /// Cycle `cycle` is recorded; the goal or the budget ended the run
    /// there if this says so.
    Recorded(Option<Ending>),
    /// The run has ended.
    Ended(Ending),
}

impl HillClimbRun {
    /// The run's settings and stop conditions.
    pub fn hill_climb(&self) -> &HillClimb {
        &self.hill_climb
    }

    /// The result of the ended run; [`RunError::NotEnded`] before.
    pub fn into_result(self) -> Result<RunResult, RunError> {
        let ending = self.ending().ok_or(RunError::NotEnded)?;
        Ok(RunResult {
            champion: self.champion.expect("every cycle has a champion"),
            records: self.records,
            ending,
        })
    }

    /// How the run ends after cycle `cycle`, recorded with the goal's or
    /// budget's `decision`.
    fn decide(&self, decision: Option<Ending>) -> Option<Ending> {
        decision
            .or(self.stop_requested.then_some(Ending::Stopped))
            .or((self.cycle == self.hill_climb.settings.cycles).then_some(Ending::Completed))
    }

    /// Moves on to the next networks to ask for, or to the end.
    fn prepare(&mut self) -> Result<(), RunError> {
        loop {
            match self.phase {
                Phase::Recorded(decision) => {
                    self.phase = match self.decide(decision) {
                        Some(ending) => Phase::Ended(ending),
                        None => {
                            self.cycle += 1;
                            Phase::Next
                        }
                    }
                }
                Phase::Next => self.phase = Phase::Asking(self.hill_climb.candidates(&self.base, self.cycle)?),
                Phase::Base | Phase::Asking(_) | Phase::Ended(_) => return Ok(()),
            }
        }
    }

    /// The cycle after its candidates scored `fitness`: champion, base, record.
    fn conclude(&mut self, candidates: Vec<Network>, fitness: &[f64]) -> GenerationRecord {
        let s = &self.hill_climb.settings;
        let cycle = self.cycle;
        let (top, top_fitness) = best_of(fitness);
        if self.champion.as_ref().is_none_or(|c| top_fitness > c.fitness) {
            self.champion = Some(Champion {
                network: candidates[top].clone(),
                fitness: top_fitness,
                generation: cycle,
                evaluation: self.evaluations + top as u64 + 1,
            });
        }
        self.evaluations += candidates.len() as u64;
        if !s.elitist || top_fitness >= self.base_fitness {
            self.base = candidates.into_iter().nth(top).expect("the best is a candidate");
            self.base_fitness = top_fitness;
        }
        let (min, mean) = min_and_mean(fitness);
        GenerationRecord {
            generation: cycle,
            min,
            mean,
            max: top_fitness,
            best: Some(self.base_fitness),
            champion: self.champion.as_ref().map_or(f64::NAN, |c| c.fitness),
            evaluations: self.evaluations,
            subpops: s.hidden,
            burst: false,
            bursts: 0,
            lesion: None,
        }
    }
}

impl AskTell for HillClimbRun {
    fn ask(&mut self) -> Result<Option<Asked<'_>>, RunError> {
        self.prepare()?;
        let seed = self.hill_climb.seed;
        Ok(match &self.phase {
            Phase::Base => Some(Asked::new(
                Networks::List(std::slice::from_ref(&self.base)),
                AskPurpose::Base,
                seed,
                [purpose::EVALUATE, 0],
            )),
            Phase::Asking(candidates) => Some(Asked::new(
                Networks::List(candidates),
                AskPurpose::Generation(self.cycle),
                seed,
                [purpose::EVALUATE, self.cycle as u64],
            )),
            _ => None,
        })
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<Option<&GenerationRecord>, RunError> {
        self.prepare()?;
        let expected = match &self.phase {
            Phase::Base => 1,
            Phase::Asking(candidates) => candidates.len(),
            _ => return Err(RunError::Ended),
        };
        check_told(fitness, expected)?;
        match std::mem::replace(&mut self.phase, Phase::Next) {
            Phase::Base => {
                self.evaluations += 1;
                self.base_fitness = fitness[0];
                Ok(None)
            }
            Phase::Asking(candidates) => {
                let record = self.conclude(candidates, fitness);
                self.phase = Phase::Recorded(self.hill_climb.stop.decide(&record, Control::Continue));
                self.records.push(record);
                Ok(self.records.last())
            }
            _ => unreachable!("checked above"),
        }
    }

    fn stop(&mut self) {
        self.stop_requested = true;
    }

    fn ending(&self) -> Option<Ending> {
        match self.phase {
            Phase::Ended(ending) => Some(ending),
            Phase::Recorded(decision) => self.decide(decision),
            Phase::Base | Phase::Next | Phase::Asking(_) => None,
        }
    }

    fn records(&self) -> &[GenerationRecord] {
        &self.records
    }

    fn result(&self) -> Result<RunResult, RunError> {
        let ending = self.ending().ok_or(RunError::NotEnded)?;
        Ok(RunResult {
            champion: self.champion.clone().expect("every cycle has a champion"),
            records: self.records.clone(),
            ending,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FnEvaluator;

    #[test]
    fn noise_and_sign_flips_happen_at_the_configured_rates() {
        let hc = HillClimb::new(HillClimbSettings::default(), 1).unwrap();
        let rates = MutationRates {
            p_noise: 0.2,
            alpha: 1.0,
            p_flip: 0.0,
        };
        let mut genes = vec![0.0; 50_000];
        hc.mutate(&mut genes, rates, &mut stream(1, &[]));
        let noisy = genes.iter().filter(|g| **g != 0.0).count();
        assert!((9_600..10_400).contains(&noisy), "{noisy} of 50000, expected 10000");
        let rates = MutationRates {
            p_noise: 0.0,
            alpha: 1.0,
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
            anneal_noise: 0.9,
            anneal_alpha: 0.5,
            anneal_flip: 0.99,
            ..HillClimbSettings::default()
        };
        let hc = HillClimb::new(settings, 1).unwrap();
        assert_eq!(
            hc.rates(1),
            MutationRates {
                p_noise: 0.2,
                alpha: 1.0,
                p_flip: 0.05
            }
        );
        let r = hc.rates(11);
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
