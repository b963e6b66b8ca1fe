//! A generation of ESP: its networks asked, then, once scored, the
//! champion and the search's best updated and the stagnation count kept;
//! then either recombination or stagnation (`stagnation.rs`).

use serde::{Deserialize, Serialize};

use super::population::State;
use super::{Esp, StagnationRule};
use crate::ask::{AskPurpose, Asked, Networks};
use crate::network::{Network, NetworkSet};
use crate::run::{Advance, Search};
use crate::subpop::Picks;
use crate::{best_of, min_and_mean, purpose, Champion, GenerationRecord, LesionOutcome, RunError, StopAt};

/// Where a generation stands while its networks are out for evaluation.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum Step {
    /// The generation's networks are asked.
    Evaluate(Picks),
    /// A lesion test's networks are asked: before the burst mutation
    /// (`before_burst`) or after discard-all rebuilt the sub-populations.
    Lesion {
        variants: Vec<Network>,
        before_burst: bool,
        stats: Stats,
    },
}

impl Step {
    /// Checks a restored step against the state: picks of neurons that
    /// exist, lesion variants of the state's shape.
    pub(crate) fn check(&self, state: &State) -> Result<(), RunError> {
        let fits = match self {
            Step::Evaluate(picks) => {
                picks.subpops == state.subpops.len()
                    && picks.flat.len() % picks.subpops.max(1) == 0
                    && state
                        .subpops
                        .iter()
                        .enumerate()
                        .all(|(i, subpop)| picks.networks().all(|pick| pick[i] < subpop.len()))
            }
            // The whole network, then each of its neurons lesioned.
            Step::Lesion { variants, .. } => variants.first().is_some_and(|whole| {
                variants.len() == whole.hidden() + 1
                    && variants
                        .iter()
                        .all(|v| (v.inputs(), v.outputs(), v.hidden()) == (state.inputs, state.outputs, whole.hidden()))
            }),
        };
        if fits {
            Ok(())
        } else {
            Err(RunError::Restore(
                "the asked networks do not fit the sub-populations".into(),
            ))
        }
    }
}

/// A generation's fitness statistics, kept for its record while its
/// lesion tests run.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub(crate) struct Stats {
    pub(super) min: f64,
    pub(super) mean: f64,
    pub(super) max: f64,
}

impl Search for Esp {
    type State = State;
    type Step = Step;

    fn generations(&self) -> usize {
        self.settings.generations
    }

    fn stop_at(&self) -> StopAt {
        self.stop
    }

    fn check(&self, state: &State, step: Option<&Step>) -> Result<(), RunError> {
        self.settings.validate()?;
        self.stop.validate()?;
        state.check(&self.settings)?;
        step.map_or(Ok(()), |step| step.check(state))
    }

    /// Generation `generation`'s first step: its networks; fails if a
    /// weight of any sub-population is not finite.
    fn begin(&self, state: &State, generation: usize) -> Result<Step, RunError> {
        let picks = self.sample(generation, state.subpops.len());
        state.networks(&picks)?;
        Ok(Step::Evaluate(picks))
    }

    /// The networks `step` asks for, with their streams.
    fn asked<'a>(&self, state: &'a State, step: &'a Step, generation: usize) -> Asked<'a> {
        let g = generation as u64;
        match step {
            Step::Evaluate(picks) => Asked::new(
                Networks::Set(state.assembled(picks)),
                AskPurpose::Generation(generation),
                self.seed,
                [purpose::EVALUATE, g],
            ),
            Step::Lesion { variants, .. } => Asked::new(
                Networks::List(variants),
                AskPurpose::LesionTest(generation),
                self.seed,
                [purpose::LESION, g],
            ),
        }
    }

    /// The generation after `step`'s networks scored `fitness` (as many,
    /// all finite).
    fn advance(&self, state: &mut State, step: Step, fitness: &[f64], generation: usize) -> Advance<Step> {
        match step {
            Step::Evaluate(picks) => {
                let (top, top_fitness) = best_of(fitness);
                let top_evaluation = state.evaluations + top as u64 + 1;
                let top = state.assembled(&picks).network(top).into_owned();
                self.conclude_step(state, &picks, fitness, (top, top_fitness, top_evaluation), generation)
            }
            Step::Lesion {
                variants,
                before_burst,
                stats,
            } => {
                let outcome = self.judge_lesion(state, &variants, fitness);
                if before_burst {
                    self.burst(state, Some(outcome), stats, generation)
                } else {
                    Advance::Record(self.after_burst(state, Some(outcome), stats, generation))
                }
            }
        }
    }

    fn champion(state: &State) -> Option<&Champion> {
        state.champion.as_ref()
    }

    fn into_champion(state: State) -> Option<Champion> {
        state.champion
    }
}

impl Esp {
    /// The generation after its evaluation, given its best network, that
    /// network's fitness and evaluation number: champion and best, then
    /// burst mutation (which may first ask for a lesion test) or credit and
    /// recombination.
    pub(super) fn conclude_step(
        &self,
        state: &mut State,
        picks: &Picks,
        fitness: &[f64],
        (top, top_fitness, top_evaluation): (Network, f64, u64),
        generation: usize,
    ) -> Advance<Step> {
        let s = &self.settings;
        state.evaluations += picks.count() as u64;

        // The generation's best network updates the champion and the search's best.
        if state.champion.as_ref().is_none_or(|c| top_fitness > c.fitness) {
            state.champion = Some(Champion {
                network: top.clone(),
                fitness: top_fitness,
                generation,
                evaluation: top_evaluation,
            });
        }
        // Progress for the stagnation count: a rise of more than the
        // minimum improvement over the best the rule follows.
        let followed = match s.stagnation_rule {
            StagnationRule::AllTimeBest => state.best.as_ref().map(|(_, f)| *f),
            StagnationRule::PhaseBest => state.phase_best,
        };
        let progressed = followed.is_none_or(|best| top_fitness > best + s.stagnation_min_improvement);
        if state.best.as_ref().is_none_or(|(_, f)| top_fitness > *f) {
            state.best = Some((top, top_fitness));
            // After an erasure at a burst, only a network better than the
            // one forgotten is an improvement of the search.
            if state.erased.is_none_or(|erased| top_fitness > erased) {
                state.erased = None;
                state.bursts_since_improvement = 0;
                state.pending = None;
            }
        }
        state.phase_best = Some(state.phase_best.map_or(top_fitness, |best| best.max(top_fitness)));
        if progressed {
            state.since_improvement = 0;
        } else {
            state.since_improvement += 1;
        }

        let (min, mean) = min_and_mean(fitness);
        let stats = Stats {
            min,
            mean,
            max: top_fitness,
        };
        if state.since_improvement >= s.stagnation {
            state.since_improvement = 0;
            state.phase_best = None;
            return self.stagnate_step(state, stats, generation);
        }
        self.assign_credit(state, picks, fitness);
        for (i, subpop) in state.subpops.iter_mut().enumerate() {
            self.recombine(subpop, generation, i);
        }
        Advance::Record(self.record(state, stats, generation, false, None))
    }

    /// The generation's record.
    pub(super) fn record(
        &self,
        state: &State,
        stats: Stats,
        generation: usize,
        burst: bool,
        lesion: Option<LesionOutcome>,
    ) -> GenerationRecord {
        GenerationRecord {
            generation,
            min: stats.min,
            mean: stats.mean,
            max: stats.max,
            best: state.best.as_ref().map(|(_, f)| *f),
            champion: state.champion.as_ref().map_or(f64::NAN, |c| c.fitness),
            evaluations: state.evaluations,
            subpops: state.subpops.len(),
            burst,
            bursts: state.bursts,
            lesion,
        }
    }
}
