//! Stagnation and topology: burst mutation around the search's best
//! network, and the lesion tests that add or remove a sub-population.

use super::generation::{Stats, Step};
use super::population::State;
use super::{BurstMode, EraseAt, Esp, Relesion, TopologyMode};
use crate::network::Network;
use crate::operators::cauchy;
use crate::purpose;
use crate::rng::stream;
use crate::run::Advance;
use crate::subpop::Subpop;
use crate::{best_of, GenerationRecord, LesionOutcome};

impl Esp {
    /// Stagnation: a lesion test when bursts have failed often enough
    /// (asked first), then a burst mutation.
    pub(super) fn stagnate_step(&self, state: &mut State, stats: Stats, generation: usize) -> Advance<Step> {
        let s = &self.settings;
        if s.topology == TopologyMode::Lesion && state.bursts_since_improvement >= s.bursts_before_lesion {
            state.bursts_since_improvement = 0;
            return Advance::Ask(Step::Lesion {
                variants: lesion_variants(state),
                before_burst: true,
                stats,
            });
        }
        self.burst(state, None, stats, generation)
    }

    /// Burst mutation, after the lesion test that gave `outcome`, if any;
    /// discard-all with a pending change asks for a new lesion test first.
    pub(super) fn burst(
        &self,
        state: &mut State,
        outcome: Option<LesionOutcome>,
        stats: Stats,
        generation: usize,
    ) -> Advance<Step> {
        let s = &self.settings;
        let (best, _) = state
            .best
            .clone()
            .expect("the search has a best network when it stagnates");
        let mut rng = stream(self.seed, &[purpose::BURST, generation as u64]);
        match s.burst {
            BurstMode::Gomez => {
                if let Some(change) = outcome {
                    self.apply_change(state, change, generation, true);
                }
                let best = state.best.as_ref().map_or(best, |(b, _)| b.clone());
                for k in 0..best.hidden() {
                    state.subpops[k] = self.around(best.neuron(k), &mut rng);
                }
            }
            BurstMode::DiscardAll => {
                state.subpops = (0..best.hidden())
                    .map(|k| self.around(best.neuron(k), &mut rng))
                    .collect();
                let relesion = match s.relesion {
                    Relesion::Pending => state.pending.is_some(),
                    Relesion::EveryBurst => true,
                };
                if outcome.is_none() && s.topology == TopologyMode::Lesion && relesion {
                    // The change is decided again by a new lesion test.
                    return Advance::Ask(Step::Lesion {
                        variants: lesion_variants(state),
                        before_burst: false,
                        stats,
                    });
                }
            }
        }
        Advance::Record(self.after_burst(state, outcome, stats, generation))
    }

    /// The end of a burst mutation: discard-all's topology change, erasing
    /// the best, the counts; returns the generation's record.
    pub(super) fn after_burst(
        &self,
        state: &mut State,
        outcome: Option<LesionOutcome>,
        stats: Stats,
        generation: usize,
    ) -> GenerationRecord {
        let s = &self.settings;
        if let (BurstMode::DiscardAll, Some(change)) = (s.burst, outcome) {
            state.pending = Some(change);
            self.apply_change(state, change, generation, false);
        }
        let forget = s.erase_best
            && match s.erase_at {
                EraseAt::Burst => true,
                EraseAt::TopologyChange => outcome.is_some(),
            };
        if forget {
            let forgotten = state.best.take().map(|(_, fitness)| fitness);
            if s.erase_at == EraseAt::Burst {
                // The level a network must beat to count as the search's improvement.
                state.erased = match (state.erased, forgotten) {
                    (Some(erased), Some(fitness)) => Some(erased.max(fitness)),
                    (erased, fitness) => erased.or(fitness),
                };
            }
        }
        state.bursts += 1;
        state.bursts_since_improvement += 1;
        self.record(state, stats, generation, true, outcome)
    }

    /// A sub-population of copies of `neuron`, Cauchy noise on every gene.
    fn around(&self, neuron: &[f64], rng: &mut crate::rng::Stream) -> Subpop {
        let s = &self.settings;
        let copies = (0..s.subpop_size).map(|_| {
            neuron
                .iter()
                .map(|w| w + cauchy(rng, s.burst_scale, s.cauchy_limit))
                .collect::<Vec<f64>>()
        });
        Subpop::from_neurons(neuron.len(), copies)
    }

    /// A lesion test's verdict from the fitness of [`lesion_variants`]: a
    /// neuron is redundant when the network keeps `lesion_threshold` of its
    /// fitness without it. Counts the evaluations.
    pub(super) fn judge_lesion(&self, state: &mut State, variants: &[Network], fitness: &[f64]) -> LesionOutcome {
        state.evaluations += variants.len() as u64;
        let whole = fitness[0];
        let (neuron, kept) = best_of(&fitness[1..]);
        // For positive fitness this is kept >= threshold x whole.
        let redundant = kept >= whole - (1.0 - self.settings.lesion_threshold) * whole.abs();
        if variants[0].hidden() > 1 && redundant {
            LesionOutcome::Remove { neuron }
        } else {
            LesionOutcome::Add
        }
    }

    /// Adds a sub-population of random neurons, or removes one. In Gomez's
    /// form (`prune_best`) a removed neuron leaves the best network too.
    pub(super) fn apply_change(&self, state: &mut State, change: LesionOutcome, generation: usize, prune_best: bool) {
        let s = &self.settings;
        match change {
            LesionOutcome::Add => {
                let mut rng = stream(self.seed, &[purpose::NEW_SUBPOP, generation as u64]);
                let genes = state.inputs + state.outputs;
                state
                    .subpops
                    .push(Subpop::random(&mut rng, s.subpop_size, genes, s.init_range));
            }
            LesionOutcome::Remove { neuron } => {
                state.subpops.remove(neuron);
                if prune_best {
                    if let Some((best, _)) = &mut state.best {
                        let kept: Vec<Vec<f64>> = (0..best.hidden())
                            .filter(|&k| k != neuron)
                            .map(|k| best.neuron(k).to_vec())
                            .collect();
                        *best = Network::from_neurons(state.inputs, state.outputs, &kept)
                            .expect("a network minus one of >= 2 neurons is valid");
                    }
                }
            }
        }
    }
}

/// The networks of a lesion test: the search's best network whole, then
/// with each hidden neuron lesioned in turn.
pub(super) fn lesion_variants(state: &State) -> Vec<Network> {
    let (best, _) = state
        .best
        .as_ref()
        .expect("the search has a best network when it stagnates");
    let mut variants = vec![best.clone()];
    for k in 0..best.hidden() {
        let mut lesioned = best.clone();
        lesioned.set_lesioned(k, true);
        variants.push(lesioned);
    }
    variants
}
