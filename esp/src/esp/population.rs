//! ESP's population: the sub-populations and the search's memory between
//! generations, how a generation's networks are sampled from them, and how
//! the neurons are ranked and bred once the networks are scored.

use rand::seq::SliceRandom;
use rand::RngExt;
use serde::{Deserialize, Serialize};

use super::{BurstMode, Credit, Esp, EspSettings, Sampling};
use crate::network::Network;
use crate::operators::{crossover, mutate_one_gene};
use crate::purpose;
use crate::rng::stream;
use crate::subpop::{Assembled, Picks, Subpop};
use crate::{Champion, LesionOutcome, RunError};

/// The search's state between generations.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct State {
    pub(super) inputs: usize,
    pub(super) outputs: usize,
    /// The sub-populations, one per hidden neuron.
    pub(super) subpops: Vec<Subpop>,
    /// The search's best network and its fitness (what burst mutation builds on).
    pub(super) best: Option<(Network, f64)>,
    /// The best network ever evaluated.
    pub(super) champion: Option<Champion>,
    /// Generations without improvement, as the stagnation rule counts them.
    pub(super) since_improvement: usize,
    /// The best network fitness since the phase began (the last burst
    /// mutation or topology change; the run's start), if any yet.
    pub(super) phase_best: Option<f64>,
    /// Burst mutations since the search's best last improved.
    pub(super) bursts_since_improvement: usize,
    /// Discard-all: the topology change to apply again after each burst.
    pub(super) pending: Option<LesionOutcome>,
    /// Erasing at every burst ([`EraseAt::Burst`](super::EraseAt)): the
    /// fitness of the best network forgotten, which a network must beat
    /// for the burst count towards a lesion test to restart (§3.2: a
    /// lesion test follows when "maximum fitness still does not
    /// improve"). Absent in states saved before the setting existed.
    #[serde(default)]
    pub(super) erased: Option<f64>,
    /// Burst mutations so far.
    pub(super) bursts: usize,
    /// Networks evaluated so far, lesion tests included.
    pub(super) evaluations: u64,
}

impl State {
    /// The state before the first generation.
    pub(super) fn new(inputs: usize, outputs: usize, subpops: Vec<Subpop>) -> State {
        State {
            inputs,
            outputs,
            subpops,
            best: None,
            champion: None,
            since_improvement: 0,
            phase_best: None,
            bursts_since_improvement: 0,
            pending: None,
            erased: None,
            bursts: 0,
            evaluations: 0,
        }
    }

    /// Checks a restored state against `settings`: sub-populations of
    /// `subpop_size` neurons of the networks' shape, a best network of
    /// that shape.
    pub(super) fn check(&self, settings: &EspSettings) -> Result<(), RunError> {
        let per = self.inputs + self.outputs;
        let subpops_fit = !self.subpops.is_empty()
            && self.inputs > 0
            && self.outputs > 0
            && self.subpops.iter().all(|subpop| {
                subpop.genes_per_neuron() == per && subpop.is_whole() && subpop.len() == settings.subpop_size
            });
        // Gomez's burst rebuilds the sub-populations of the best network's
        // neurons; discard-all's may keep one more neuron than there are
        // sub-populations (a removal applied after the burst).
        let most_hidden = match settings.burst {
            BurstMode::Gomez => self.subpops.len(),
            BurstMode::DiscardAll => self.subpops.len() + 1,
        };
        let best_fits = self.best.as_ref().is_none_or(|(best, _)| {
            (best.inputs(), best.outputs()) == (self.inputs, self.outputs) && best.hidden() <= most_hidden
        });
        if subpops_fit && best_fits {
            Ok(())
        } else {
            Err(RunError::Restore(format!(
                "the sub-populations or the best network do not fit {} inputs, {} outputs and {} neurons a \
                 sub-population",
                self.inputs, self.outputs, settings.subpop_size
            )))
        }
    }

    /// The networks `picks` form (pick[i]: the neuron taken from
    /// sub-population i), read in place from the sub-populations; fails
    /// if any weight of any sub-population is not finite.
    pub(super) fn networks<'a>(&'a self, picks: &'a Picks) -> Result<Assembled<'a>, RunError> {
        // Checked here once, so that the networks' neurons need no check.
        for (i, subpop) in self.subpops.iter().enumerate() {
            if let Some((k, gene)) = subpop.first_non_finite() {
                return Err(RunError::NonFiniteWeight {
                    subpop: i,
                    neuron: k,
                    gene,
                    value: subpop.neuron(k)[gene],
                });
            }
        }
        Ok(self.assembled(picks))
    }

    /// The networks `picks` form, unchecked (checked by
    /// [`State::networks`] when the picks were made).
    pub(super) fn assembled<'a>(&'a self, picks: &'a Picks) -> Assembled<'a> {
        Assembled {
            inputs: self.inputs,
            outputs: self.outputs,
            subpops: &self.subpops,
            picks,
        }
    }
}

impl Credit {
    /// Each neuron's credit from a generation's networks and their
    /// fitness: neuron k of sub-population i at index `i subpop_size + k`,
    /// `None` for a neuron that joined no network. `picks` gives each
    /// network's neuron of every sub-population ([`Asked::picks`](crate::Asked::picks)),
    /// in the order of `fitness`. The credit ESP ranks and breeds by; each
    /// neuron's sum is taken in network order.
    pub fn neuron_credits<'p>(
        self,
        subpops: usize,
        subpop_size: usize,
        picks: impl IntoIterator<Item = &'p [usize]>,
        fitness: &[f64],
    ) -> Vec<Option<f64>> {
        let n = subpop_size;
        let neurons = n * subpops;
        let (mut sum, mut count, mut max) = (
            vec![0.0; neurons],
            vec![0usize; neurons],
            vec![f64::NEG_INFINITY; neurons],
        );
        for (pick, &f) in picks.into_iter().zip(fitness) {
            for (i, &k) in pick.iter().enumerate() {
                let j = i * n + k;
                sum[j] += f;
                count[j] += 1;
                max[j] = max[j].max(f);
            }
        }
        (0..neurons)
            .map(|j| match (count[j], self) {
                (0, _) => None,
                (c, Credit::Mean) => Some(sum[j] / c as f64),
                (_, Credit::Max) => Some(max[j]),
            })
            .collect()
    }
}

impl Esp {
    /// Which neuron of each sub-population every network takes.
    pub(super) fn sample(&self, generation: usize, subpops: usize) -> Picks {
        let s = &self.settings;
        let n = s.subpop_size;
        let mut rng = stream(self.seed, &[purpose::SAMPLE, generation as u64]);
        let mut picks = Vec::with_capacity(s.networks_per_generation() * subpops);
        match s.sampling {
            Sampling::Random => {
                for _ in 0..s.networks_per_generation() * subpops {
                    picks.push(rng.random_range(0..n));
                }
            }
            Sampling::Systematic => {
                for _ in 0..s.trials_per_neuron {
                    let orders: Vec<Vec<usize>> = (0..subpops)
                        .map(|_| {
                            let mut order: Vec<usize> = (0..n).collect();
                            order.shuffle(&mut rng);
                            order
                        })
                        .collect();
                    picks.extend((0..n).flat_map(|k| orders.iter().map(move |order| order[k])));
                }
            }
        }
        Picks { subpops, flat: picks }
    }

    /// Neuron fitness from the networks', then each sub-population sorted
    /// best first (stable). A neuron that joined no network (random
    /// sampling) has no credit and ranks below every neuron that joined
    /// one, whatever the fitness's sign: adding a constant to every
    /// fitness leaves the order as it is.
    pub(super) fn assign_credit(&self, state: &mut State, picks: &Picks, fitness: &[f64]) {
        let n = self.settings.subpop_size;
        let credit = self
            .settings
            .credit
            .neuron_credits(state.subpops.len(), n, picks.networks(), fitness);
        let mut order = Vec::with_capacity(n);
        for (subpop, credit) in state.subpops.iter_mut().zip(credit.chunks_exact(n)) {
            order.clear();
            order.extend(0..n);
            order.sort_by(|&a, &b| match (credit[a], credit[b]) {
                (Some(x), Some(y)) => y.total_cmp(&x),
                (x, y) => y.is_some().cmp(&x.is_some()),
            });
            subpop.reorder(&order);
        }
    }

    /// Crossover of the top quarter into the bottom half, then mutation of
    /// the children (`subpop` sorted best first).
    pub(super) fn recombine(&self, subpop: &mut Subpop, generation: usize, index: usize) {
        let s = &self.settings;
        let n = subpop.len();
        let breeders = n / 4;
        let mut rng = stream(self.seed, &[purpose::BREED, generation as u64, index as u64]);
        let genes = subpop.genes_per_neuron();
        let (mut first, mut second) = (vec![0.0; genes], vec![0.0; genes]);
        for i in 0..breeders {
            // The best mates with any of the top quarter, the others with a higher-ranked one.
            let mate = if i == 0 {
                rng.random_range(0..breeders)
            } else {
                rng.random_range(0..i)
            };
            crossover(&mut rng, subpop.neuron(i), subpop.neuron(mate), &mut first, &mut second);
            subpop.neuron_mut(n - 1 - 2 * i).copy_from_slice(&first);
            subpop.neuron_mut(n - 2 - 2 * i).copy_from_slice(&second);
        }
        for child in n - 2 * breeders..n {
            let genes = subpop.neuron_mut(child);
            mutate_one_gene(&mut rng, genes, s.mutation_rate, s.mutation_scale, s.cauchy_limit);
        }
    }
}
