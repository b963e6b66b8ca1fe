//! Enforced Sub-Populations (Gomez & Miikkulainen), with Høverstad's
//! modifications as switches (`algorithms.md` §1-2).

use std::borrow::Cow;

use rand::seq::SliceRandom;
use rand::RngExt;
use serde::{Deserialize, Serialize};

use super::ask::{drive, AskPurpose, Asked, Networks};
use super::esp_run::EspRun;
use super::network::check_sizes;
use super::operators::{cauchy, crossover, mutate_one_gene};
use super::subpop::Subpop;
use super::{
    best_of, check_cauchy_limit, check_count, check_positive, check_probability, min_and_mean, purpose,
    MAX_GENERATIONS, MAX_HIDDEN, MAX_NETWORKS_PER_GENERATION, MAX_SUBPOP_SIZE, MAX_TRIALS_PER_NEURON,
};
use super::{
    Champion, Control, Evaluator, GenerationRecord, LesionOutcome, RunError, RunResult, SettingsError, StopAt,
};
use crate::network::{Network, NetworkSet};
use crate::rng::stream;
#[cfg(test)]
use crate::Ending;

/// How networks are formed from the sub-populations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// Each network takes a uniformly random neuron from every sub-population. `[paper, ESP]`
    Random,
    /// Høverstad's: per round, shuffle every sub-population and build network
    /// k from the k-th neurons; every neuron is evaluated exactly
    /// `trials_per_neuron` times. (Table 4)
    Systematic,
}

/// How a neuron's fitness is derived from its networks'.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Credit {
    /// The mean fitness of the networks it took part in. `[paper, ESP]`
    Mean,
    /// The highest. (Table 5)
    Max,
}

/// What burst mutation does with the sub-populations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BurstMode {
    /// Høverstad's default: discard all sub-populations, rebuild one per
    /// neuron of the best network, then apply a pending topology change
    /// again (lesion test, add or remove).
    DiscardAll,
    /// Gomez's original: rebuild the sub-populations of the best network's
    /// neurons; sub-populations added since it was found persist untouched.
    Gomez,
}

/// When the search has stagnated (`algorithms.md` §1; the paper's §3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StagnationRule {
    /// The paper's and Gomez's code's reading: the best network fitness of
    /// each generation is logged since the last burst mutation (the phase
    /// best, reset at every burst and topology change); stagnation is
    /// declared when it has not risen for `stagnation` generations. After a
    /// burst the population climbs back, and each rise postpones the next
    /// burst. `[paper]`
    PhaseBest,
    /// Generations since the search's best network (all-time) last
    /// improved: after a fruitless burst the next one follows exactly
    /// `stagnation` generations later. (This tool's first reading.)
    AllTimeBest,
}

/// Whether lesion tests change the topology.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TopologyMode {
    /// Lesion tests add or remove sub-populations. `[paper]`
    Lesion,
    /// No lesion tests, no topology change. (Table 6)
    Off,
}

/// Every setting of ESP. The default is Gomez's ESP ([`EspSettings::gomez`]);
/// each field's doc ends with its value in Høverstad's modified ESP
/// ([`EspSettings::hoverstad`]), tagged `[paper]` (the ESP papers and code,
/// or Høverstad's) or `[chosen]` (chosen here).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EspSettings {
    /// Neurons per sub-population. `[paper]` 40
    pub subpop_size: usize,
    /// Networks per generation = this x `subpop_size`. `[paper]` 10
    pub trials_per_neuron: usize,
    /// Sub-populations (hidden neurons) at the start. `[paper]` 5
    pub initial_hidden: usize,
    /// Generations. `[paper]` 2000
    pub generations: usize,
    /// Initial weights are uniform in (-range, range). `[paper]` 6
    pub init_range: f64,
    /// Network formation. `[paper]` random
    pub sampling: Sampling,
    /// Neuron credit. `[paper]` mean
    pub credit: Credit,
    /// Probability that a child gets Cauchy noise on one gene. `[paper]` 0.4
    pub mutation_rate: f64,
    /// Scale of that Cauchy noise. `[paper]` 0.3
    pub mutation_scale: f64,
    /// Cauchy draws larger than this in magnitude are drawn again. `[paper]` 10
    pub cauchy_limit: f64,
    /// Generations without improvement before a burst mutation (b).
    /// Gomez's code: 20 (the default); Høverstad gives no number (the PSA's
    /// fitted value is 40: psa-esp's docs/model.md)
    pub stagnation: usize,
    /// What "without improvement" means. Gomez's code and Høverstad's §3.2: phase_best
    pub stagnation_rule: StagnationRule,
    /// Scale of the Cauchy noise of burst mutation, on every gene. `[paper]` 0.3
    pub burst_scale: f64,
    /// Burst mutation's form. `[paper, Høverstad]` discard_all
    pub burst: BurstMode,
    /// Lesion tests after `bursts_before_lesion` fruitless burst mutations. `[paper]` lesion
    pub topology: TopologyMode,
    /// Burst mutations without improvement that trigger a lesion test. `[paper]` 2
    pub bursts_before_lesion: usize,
    /// A neuron is redundant when the network without it keeps this share of the fitness. `[chosen]` 0.9
    pub lesion_threshold: f64,
    /// Forget the search's best network whenever a sub-population is added or removed. (Table 6) `[paper]` false
    pub erase_best: bool,
}

impl Default for EspSettings {
    /// [`EspSettings::gomez`].
    fn default() -> Self {
        EspSettings::gomez()
    }
}

impl EspSettings {
    /// Gomez's ESP as his code defines it: burst mutation rebuilds the best
    /// network's sub-populations and keeps any added since
    /// ([`BurstMode::Gomez`]), one fruitless burst mutation brings a lesion
    /// test, and a neuron is redundant when the network keeps 80 % of its
    /// fitness without it. The population's shape (40 neurons per
    /// sub-population, 10 networks per neuron, 5 hidden neurons at first,
    /// initial weights in (-6, 6)) and the 2000 generations are common
    /// settings to change for a problem.
    pub fn gomez() -> EspSettings {
        EspSettings {
            burst: BurstMode::Gomez,
            bursts_before_lesion: 1,
            lesion_threshold: 0.8,
            ..EspSettings::hoverstad()
        }
    }

    /// Høverstad's modified ESP (his Table 1): burst mutation discards all
    /// sub-populations ([`BurstMode::DiscardAll`]), two fruitless burst
    /// mutations bring a lesion test, and the lesion threshold is 0.9.
    pub fn hoverstad() -> EspSettings {
        EspSettings {
            subpop_size: 40,
            trials_per_neuron: 10,
            initial_hidden: 5,
            generations: 2000,
            init_range: 6.0,
            sampling: Sampling::Random,
            credit: Credit::Mean,
            mutation_rate: 0.4,
            mutation_scale: 0.3,
            cauchy_limit: 10.0,
            stagnation: 20,
            stagnation_rule: StagnationRule::PhaseBest,
            burst_scale: 0.3,
            burst: BurstMode::DiscardAll,
            topology: TopologyMode::Lesion,
            bursts_before_lesion: 2,
            lesion_threshold: 0.9,
            erase_best: false,
        }
    }

    /// Rejects out-of-range values, naming the setting.
    pub fn validate(&self) -> Result<(), SettingsError> {
        check_count("esp.subpop_size", self.subpop_size, 4, MAX_SUBPOP_SIZE)?;
        check_count(
            "esp.trials_per_neuron",
            self.trials_per_neuron,
            1,
            MAX_TRIALS_PER_NEURON,
        )?;
        check_count("esp.initial_hidden", self.initial_hidden, 1, MAX_HIDDEN)?;
        check_count("esp.generations", self.generations, 1, MAX_GENERATIONS)?;
        check_count("esp.stagnation", self.stagnation, 1, usize::MAX)?;
        check_count("esp.bursts_before_lesion", self.bursts_before_lesion, 1, usize::MAX)?;
        check_positive("esp.init_range", self.init_range)?;
        check_positive("esp.mutation_scale", self.mutation_scale)?;
        check_positive("esp.cauchy_limit", self.cauchy_limit)?;
        check_positive("esp.burst_scale", self.burst_scale)?;
        check_probability("esp.mutation_rate", self.mutation_rate)?;
        check_probability("esp.lesion_threshold", self.lesion_threshold)?;
        let networks = self.networks_per_generation();
        if networks > MAX_NETWORKS_PER_GENERATION {
            return Err(SettingsError::TooManyNetworks {
                trials_per_neuron: self.trials_per_neuron,
                subpop_size: self.subpop_size,
                max: MAX_NETWORKS_PER_GENERATION,
            });
        }
        let (scale_name, scale) = if self.mutation_scale >= self.burst_scale {
            ("esp.mutation_scale", self.mutation_scale)
        } else {
            ("esp.burst_scale", self.burst_scale)
        };
        check_cauchy_limit("esp.cauchy_limit", self.cauchy_limit, scale_name, scale)
    }

    /// Networks evaluated per generation (lesion tests not counted).
    pub fn networks_per_generation(&self) -> usize {
        self.trials_per_neuron * self.subpop_size
    }
}

/// An ESP run: settings, seed and when to stop early.
#[derive(Debug, Clone)]
pub struct Esp {
    settings: EspSettings,
    seed: u64,
    stop: StopAt,
}

/// The search's state between generations.
pub(crate) struct State {
    inputs: usize,
    outputs: usize,
    /// The sub-populations, one per hidden neuron.
    subpops: Vec<Subpop>,
    /// The search's best network and its fitness (what burst mutation builds on).
    best: Option<(Network, f64)>,
    pub(crate) champion: Option<Champion>,
    /// Generations without improvement, as the stagnation rule counts them.
    since_improvement: usize,
    /// The best network fitness since the phase began (the last burst
    /// mutation or topology change; the run's start).
    phase_best: f64,
    bursts_since_improvement: usize,
    /// Discard-all: the topology change to apply again after each burst.
    pending: Option<LesionOutcome>,
    bursts: usize,
    evaluations: u64,
}

impl State {
    /// The state before the first generation.
    fn new(inputs: usize, outputs: usize, subpops: Vec<Subpop>) -> State {
        State {
            inputs,
            outputs,
            subpops,
            best: None,
            champion: None,
            since_improvement: 0,
            phase_best: f64::NEG_INFINITY,
            bursts_since_improvement: 0,
            pending: None,
            bursts: 0,
            evaluations: 0,
        }
    }

    /// The networks `picks` form (pick[i]: the neuron taken from
    /// sub-population i), read in place from the sub-populations; fails
    /// if any weight of any sub-population is not finite.
    fn networks<'a>(&'a self, picks: &'a Picks) -> Result<Assembled<'a>, RunError> {
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
    fn assembled<'a>(&'a self, picks: &'a Picks) -> Assembled<'a> {
        Assembled {
            inputs: self.inputs,
            outputs: self.outputs,
            subpops: &self.subpops,
            picks,
        }
    }
}

/// A generation's networks as its sub-populations and picks: what the
/// evaluator reads, neuron by neuron, without a copy of each network.
pub(crate) struct Assembled<'a> {
    inputs: usize,
    outputs: usize,
    subpops: &'a [Subpop],
    picks: &'a Picks,
}

impl NetworkSet for Assembled<'_> {
    fn len(&self) -> usize {
        self.picks.count()
    }
    fn shape(&self, _: usize) -> (usize, usize) {
        (self.inputs, self.outputs)
    }
    fn hidden(&self, _: usize) -> usize {
        self.subpops.len()
    }
    fn neuron(&self, j: usize, k: usize) -> &[f64] {
        self.subpops[k].neuron(self.picks.flat[j * self.picks.subpops + k])
    }
    fn is_lesioned(&self, _: usize, _: usize) -> bool {
        false
    }
    fn network(&self, j: usize) -> Cow<'_, Network> {
        let genes = (0..self.subpops.len())
            .flat_map(|k| self.neuron(j, k))
            .copied()
            .collect();
        Cow::Owned(
            Network::from_genes(self.inputs, self.outputs, genes)
                .expect("the sub-populations' weights were checked finite and their shape fits"),
        )
    }
}

/// Which neuron of each sub-population every network of a generation
/// takes, network after network in one flat list: network j takes neuron
/// `flat[j * subpops + i]` of sub-population i.
pub(crate) struct Picks {
    subpops: usize,
    flat: Vec<usize>,
}

impl Picks {
    /// The number of networks.
    fn count(&self) -> usize {
        self.flat.len() / self.subpops
    }

    /// Each network's picks, one per sub-population.
    fn networks(&self) -> std::slice::ChunksExact<'_, usize> {
        self.flat.chunks_exact(self.subpops)
    }
}

/// Where a generation stands while its networks are out for evaluation.
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
    /// The number of networks asked.
    pub(crate) fn count(&self) -> usize {
        match self {
            Step::Evaluate(picks) => picks.count(),
            Step::Lesion { variants, .. } => variants.len(),
        }
    }
}

/// A generation's fitness statistics, kept for its record while its
/// lesion tests run.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stats {
    min: f64,
    mean: f64,
    max: f64,
}

/// What a generation needs after a step: more networks evaluated, or
/// nothing (its record).
pub(crate) enum Advance {
    Ask(Step),
    Record(GenerationRecord),
}

impl Esp {
    /// An ESP run with `settings` and `seed`; fails on invalid settings.
    pub fn new(settings: EspSettings, seed: u64) -> Result<Esp, SettingsError> {
        settings.validate()?;
        Ok(Esp {
            settings,
            seed,
            stop: StopAt::NEVER,
        })
    }

    /// This run, ending early when `stop` says so.
    pub fn stop_at(self, stop: StopAt) -> Esp {
        Esp { stop, ..self }
    }

    /// The settings.
    pub fn settings(&self) -> &EspSettings {
        &self.settings
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// When the run ends early.
    pub fn stop(&self) -> StopAt {
        self.stop
    }

    /// Starts the run on networks of `inputs` inputs (the bias included)
    /// and `outputs` outputs, to be driven by ask and tell ([`AskTell`](crate::AskTell)).
    /// Fails on a size of 0.
    pub fn start(&self, inputs: usize, outputs: usize) -> Result<EspRun, RunError> {
        check_sizes(inputs, outputs)?;
        let s = &self.settings;
        let mut rng = stream(self.seed, &[purpose::INIT]);
        let subpops = (0..s.initial_hidden)
            .map(|_| Subpop::random(&mut rng, s.subpop_size, inputs + outputs, s.init_range))
            .collect();
        Ok(EspRun::new(self.clone(), State::new(inputs, outputs, subpops)))
    }

    /// Runs the generations on the current rayon pool, calling
    /// `on_generation` after each, until the last, or until the stop
    /// conditions ([`Esp::stop_at`]) or `on_generation` (returning
    /// [`Control::Stop`]) end the run. A loop over [`Esp::start`]'s ask,
    /// evaluate and tell.
    pub fn run<E: Evaluator, C: Into<Control>>(
        &self,
        evaluator: &E,
        on_generation: impl FnMut(&GenerationRecord) -> C,
    ) -> Result<RunResult, RunError> {
        let mut run = self.start(evaluator.inputs(), evaluator.outputs())?;
        drive(&mut run, evaluator, on_generation)?;
        run.into_result()
    }

    /// Which neuron of each sub-population every network takes.
    fn sample(&self, generation: usize, subpops: usize) -> Picks {
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

    /// Generation `generation`'s first step: its networks; fails if a
    /// weight of any sub-population is not finite.
    pub(crate) fn begin(&self, state: &State, generation: usize) -> Result<Step, RunError> {
        let picks = self.sample(generation, state.subpops.len());
        state.networks(&picks)?;
        Ok(Step::Evaluate(picks))
    }

    /// The networks `step` asks for, with their streams.
    pub(crate) fn asked<'a>(&self, state: &'a State, step: &'a Step, generation: usize) -> Asked<'a> {
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
    /// none NaN).
    pub(crate) fn advance(&self, state: &mut State, step: Step, fitness: &[f64], generation: usize) -> Advance {
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

    /// The generation after its evaluation, given its best network, that
    /// network's fitness and evaluation number: champion and best, then
    /// burst mutation (which may first ask for a lesion test) or credit and
    /// recombination.
    fn conclude_step(
        &self,
        state: &mut State,
        picks: &Picks,
        fitness: &[f64],
        (top, top_fitness, top_evaluation): (Network, f64, u64),
        generation: usize,
    ) -> Advance {
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
        let improved = state.best.as_ref().is_none_or(|(_, f)| top_fitness > *f);
        if improved {
            state.best = Some((top, top_fitness));
            state.bursts_since_improvement = 0;
            state.pending = None;
        }
        let progressed = match s.stagnation_rule {
            StagnationRule::AllTimeBest => improved,
            StagnationRule::PhaseBest => top_fitness > state.phase_best,
        };
        state.phase_best = state.phase_best.max(top_fitness);
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
            state.phase_best = f64::NEG_INFINITY;
            return self.stagnate_step(state, stats, generation);
        }
        self.assign_credit(state, picks, fitness);
        for (i, subpop) in state.subpops.iter_mut().enumerate() {
            self.recombine(subpop, generation, i);
        }
        Advance::Record(self.record(state, stats, generation, false, None))
    }

    /// The generation's record.
    fn record(
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

    /// Neuron fitness from the networks' (0 for a neuron in no network),
    /// then each sub-population sorted best first (stable).
    fn assign_credit(&self, state: &mut State, picks: &Picks, fitness: &[f64]) {
        let n = self.settings.subpop_size;
        // Neuron k of sub-population i at index i n + k; one pass over the
        // networks, each neuron's sum in network order.
        let neurons = n * state.subpops.len();
        let (mut sum, mut count, mut max) = (
            vec![0.0; neurons],
            vec![0usize; neurons],
            vec![f64::NEG_INFINITY; neurons],
        );
        for (pick, &f) in picks.networks().zip(fitness) {
            for (i, &k) in pick.iter().enumerate() {
                let j = i * n + k;
                sum[j] += f;
                count[j] += 1;
                max[j] = max[j].max(f);
            }
        }
        let credit: Vec<f64> = (0..neurons)
            .map(|j| match (count[j], self.settings.credit) {
                (0, _) => 0.0,
                (c, Credit::Mean) => sum[j] / c as f64,
                (_, Credit::Max) => max[j],
            })
            .collect();
        let mut order = Vec::with_capacity(n);
        for (subpop, credit) in state.subpops.iter_mut().zip(credit.chunks_exact(n)) {
            order.clear();
            order.extend(0..n);
            order.sort_by(|&a, &b| credit[b].total_cmp(&credit[a]));
            subpop.reorder(&order);
        }
    }

    /// Crossover of the top quarter into the bottom half, then mutation of
    /// the children (`subpop` sorted best first).
    fn recombine(&self, subpop: &mut Subpop, generation: usize, index: usize) {
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

    /// Stagnation: a lesion test when bursts have failed often enough
    /// (asked first), then a burst mutation.
    fn stagnate_step(&self, state: &mut State, stats: Stats, generation: usize) -> Advance {
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
    fn burst(&self, state: &mut State, outcome: Option<LesionOutcome>, stats: Stats, generation: usize) -> Advance {
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
                if outcome.is_none() && s.topology == TopologyMode::Lesion && state.pending.is_some() {
                    // The pending change is decided again by a new lesion test.
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
    fn after_burst(
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
        if outcome.is_some() && s.erase_best {
            state.best = None;
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
    fn judge_lesion(&self, state: &mut State, variants: &[Network], fitness: &[f64]) -> LesionOutcome {
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
    fn apply_change(&self, state: &mut State, change: LesionOutcome, generation: usize, prune_best: bool) {
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

    /// Steps generation `generation` on from `advance` with `evaluator`
    /// until its record.
    #[cfg(test)]
    fn finish<E: Evaluator>(
        &self,
        evaluator: &E,
        state: &mut State,
        mut advance: Advance,
        generation: usize,
    ) -> Result<GenerationRecord, RunError> {
        loop {
            match advance {
                Advance::Record(record) => return Ok(record),
                Advance::Ask(step) => {
                    let fitness = self.asked(state, &step, generation).evaluate(evaluator)?;
                    advance = self.advance(state, step, &fitness, generation);
                }
            }
        }
    }

    /// A whole generation with `evaluator`.
    #[cfg(test)]
    fn generation<E: Evaluator>(
        &self,
        evaluator: &E,
        state: &mut State,
        generation: usize,
    ) -> Result<GenerationRecord, RunError> {
        let step = self.begin(state, generation)?;
        self.finish(evaluator, state, Advance::Ask(step), generation)
    }

    /// The generation after its evaluation (see [`Esp::conclude_step`]),
    /// its lesion tests evaluated with `evaluator`.
    #[cfg(test)]
    fn conclude<E: Evaluator>(
        &self,
        evaluator: &E,
        state: &mut State,
        picks: &Picks,
        fitness: Vec<f64>,
        top: (Network, f64, u64),
        generation: usize,
    ) -> Result<GenerationRecord, RunError> {
        let advance = self.conclude_step(state, picks, &fitness, top, generation);
        self.finish(evaluator, state, advance, generation)
    }

    /// Stagnation with `evaluator` for its lesion tests; returns the lesion
    /// outcome applied, if any.
    #[cfg(test)]
    fn stagnate<E: Evaluator>(
        &self,
        evaluator: &E,
        state: &mut State,
        generation: usize,
    ) -> Result<Option<LesionOutcome>, RunError> {
        let stats = Stats {
            min: 0.0,
            mean: 0.0,
            max: 0.0,
        };
        let advance = self.stagnate_step(state, stats, generation);
        Ok(self.finish(evaluator, state, advance, generation)?.lesion)
    }

    /// A lesion test of the search's best network with `evaluator`.
    #[cfg(test)]
    fn lesion_test<E: Evaluator>(
        &self,
        evaluator: &E,
        state: &mut State,
        generation: usize,
    ) -> Result<LesionOutcome, RunError> {
        let variants = lesion_variants(state);
        let fitness = crate::evaluate_all(
            evaluator,
            &variants[..],
            self.seed,
            &[purpose::LESION, generation as u64],
        )?;
        Ok(self.judge_lesion(state, &variants, &fitness))
    }
}

/// The networks of a lesion test: the search's best network whole, then
/// with each hidden neuron lesioned in turn.
fn lesion_variants(state: &State) -> Vec<Network> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FnEvaluator;

    fn esp(settings: EspSettings) -> Esp {
        Esp::new(settings, 11).unwrap()
    }

    /// A state of `hidden` sub-populations of 2-input, 1-output neurons.
    fn state(e: &Esp, hidden: usize) -> State {
        let mut rng = stream(5, &[]);
        let subpops = (0..hidden)
            .map(|_| Subpop::random(&mut rng, e.settings.subpop_size, 3, 6.0))
            .collect();
        State::new(2, 1, subpops)
    }

    #[test]
    fn children_of_rank_j_overwrite_ranks_n_1_2j_and_n_2_2j() {
        let e = esp(EspSettings {
            subpop_size: 12,
            mutation_rate: 0.0,
            ..EspSettings::hoverstad()
        });
        // Neuron k's genes all equal k: a child's genes show its parents.
        let mut subpop = Subpop::from_neurons(5, (0..12).map(|k| [k as f64; 5]));
        e.recombine(&mut subpop, 1, 0);
        for (k, neuron) in subpop.neurons().enumerate().take(6) {
            assert_eq!(neuron, [k as f64; 5], "the top half survives unchanged");
        }
        for j in 0..3 {
            let (first, second) = (subpop.neuron(11 - 2 * j), subpop.neuron(10 - 2 * j));
            // One-point crossover: the first child starts with parent j's
            // genes up to the cut, the second with the mate's; the mate is
            // higher ranked (or, for the best, any of the top quarter).
            let mate = second[0];
            let cut = first.iter().take_while(|g| **g == j as f64).count();
            assert!(first[cut..].iter().all(|g| *g == mate), "{first:?}");
            assert!(second[..cut].iter().all(|g| *g == mate) && second[cut..].iter().all(|g| *g == j as f64));
            if j == 0 {
                assert!(mate < 3.0);
            } else {
                assert!(mate < j as f64 || cut == 0, "mate {mate} of rank {j}");
            }
        }
    }

    #[test]
    fn only_children_are_mutated_at_the_configured_rate() {
        let e = esp(EspSettings {
            subpop_size: 40,
            mutation_rate: 0.4,
            ..EspSettings::hoverstad()
        });
        let mut mutated = 0;
        for generation in 0..200 {
            // All neurons identical: crossover changes nothing, so any change is a mutation.
            let mut subpop = Subpop::from_neurons(11, vec![[1.0; 11]; 40]);
            e.recombine(&mut subpop, generation, 0);
            assert!(subpop.neurons().take(20).all(|n| n == [1.0; 11]));
            for child in subpop.neurons().skip(20) {
                let changed = child.iter().filter(|g| **g != 1.0).count();
                assert!(changed <= 1, "one gene at most");
                mutated += changed;
            }
        }
        // 200 x 20 children x 0.4 = 1600, sd about 31.
        assert!((1480..1720).contains(&mutated), "{mutated}");
    }

    #[test]
    fn systematic_sampling_evaluates_every_neuron_exactly_ten_times() {
        let e = esp(EspSettings {
            sampling: Sampling::Systematic,
            ..EspSettings::hoverstad()
        });
        let picks = e.sample(3, 5);
        assert_eq!(picks.count(), 400);
        for i in 0..5 {
            let mut counts = [0; 40];
            picks.networks().for_each(|p| counts[p[i]] += 1);
            assert!(counts.iter().all(|&c| c == 10), "sub-population {i}: {counts:?}");
        }
        // Random sampling: 400 picks per sub-population, unevenly spread.
        let random = esp(EspSettings::hoverstad()).sample(3, 5);
        let mut counts = [0; 40];
        random.networks().for_each(|p| counts[p[0]] += 1);
        assert_eq!(counts.iter().sum::<usize>(), 400);
        assert!(counts.iter().any(|&c| c != 10));
    }

    #[test]
    fn credit_is_the_mean_or_the_max_of_the_networks_a_neuron_joined() {
        for (credit, expected_best) in [(Credit::Mean, 2usize), (Credit::Max, 1usize)] {
            let e = esp(EspSettings {
                subpop_size: 4,
                credit,
                ..EspSettings::hoverstad()
            });
            let mut st = state(&e, 1);
            st.subpops[0] = Subpop::from_neurons(3, (0..4).map(|k| [k as f64; 3]));
            // Neuron 1: fitness 9 and 0 (mean 4.5, max 9); neuron 2: 5 and 5 (mean 5, max 5);
            // neuron 0: 1; neuron 3: in no network (0).
            let picks = Picks {
                subpops: 1,
                flat: vec![1, 1, 2, 2, 0],
            };
            e.assign_credit(&mut st, &picks, &[9.0, 0.0, 5.0, 5.0, 1.0]);
            let order: Vec<f64> = st.subpops[0].neurons().map(|n| n[0]).collect();
            assert_eq!(order[0], expected_best as f64, "{credit:?}: {order:?}");
            assert_eq!(order[3], 3.0, "{credit:?}: the unevaluated neuron ranks last");
        }
    }

    #[test]
    fn assembly_reads_the_picked_neurons_and_refuses_a_non_finite_weight() {
        let e = esp(EspSettings {
            subpop_size: 4,
            ..EspSettings::hoverstad()
        });
        let mut st = state(&e, 2);
        let picks = Picks {
            subpops: 2,
            flat: vec![3, 0, 1, 2],
        };
        let networks = st.networks(&picks).unwrap();
        assert_eq!(networks.len(), 2);
        for (j, pick) in picks.networks().enumerate() {
            let network = networks.network(j);
            for (k, &n) in pick.iter().enumerate() {
                assert_eq!(networks.neuron(j, k), st.subpops[k].neuron(n));
                assert_eq!(network.neuron(k), st.subpops[k].neuron(n));
                assert!(!networks.is_lesioned(j, k) && !network.is_lesioned(k));
            }
            assert_eq!((networks.shape(j), networks.hidden(j)), ((2, 1), 2));
        }
        // Any weight of any sub-population, picked or not, is checked.
        st.subpops[1].neuron_mut(3)[2] = f64::INFINITY;
        let err = st.networks(&picks).map(|_| ()).unwrap_err().to_string();
        assert!(
            err.starts_with("weight 2 of neuron 3 of sub-population 1 is not finite (inf)"),
            "{err}"
        );
    }

    /// Fitness 1 for a whole network, 0 with any neuron lesioned: never improves after the first generation.
    fn all_neurons_needed() -> impl Evaluator<Worker = ()> {
        FnEvaluator::new(2, 1, |n: &Network, _: &mut crate::rng::Stream| {
            Ok(if (0..n.hidden()).any(|k| n.is_lesioned(k)) {
                0.0
            } else {
                1.0
            })
        })
    }

    #[test]
    fn burst_mutation_rebuilds_every_subpop_around_the_best_network() {
        let e = esp(EspSettings {
            topology: TopologyMode::Off,
            ..EspSettings::hoverstad()
        });
        let mut st = state(&e, 3);
        let best =
            Network::from_neurons(2, 1, &[vec![1.0, 2.0, 3.0], vec![-1.0, 0.0, 1.0], vec![4.0, 4.0, 4.0]]).unwrap();
        st.best = Some((best.clone(), 1.0));
        e.stagnate(&all_neurons_needed(), &mut st, 1).unwrap();
        assert_eq!(st.subpops.len(), 3);
        assert_eq!(st.bursts, 1);
        for (k, subpop) in st.subpops.iter().enumerate() {
            let mut deltas: Vec<f64> = subpop
                .neurons()
                .flat_map(|n| n.iter().zip(best.neuron(k)).map(|(a, b)| (a - b).abs()))
                .collect();
            assert!(
                deltas.iter().all(|d| *d > 0.0 && *d <= 10.0),
                "every gene perturbed, clipped"
            );
            deltas.sort_by(f64::total_cmp);
            let median = deltas[deltas.len() / 2];
            assert!(
                (0.2..0.45).contains(&median),
                "Cauchy scale 0.3: median |noise| {median}"
            );
        }
    }

    fn redundancy_evaluator() -> impl Evaluator<Worker = ()> {
        // Fitness: the sum of gene 0 over the active hidden neurons.
        FnEvaluator::new(2, 1, |n: &Network, _: &mut crate::rng::Stream| {
            Ok((0..n.hidden())
                .filter(|&k| !n.is_lesioned(k))
                .map(|k| n.neuron(k)[0])
                .sum())
        })
    }

    #[test]
    fn lesion_test_removes_a_redundant_neuron_and_adds_otherwise() {
        let e = esp(EspSettings::hoverstad());
        let mut st = state(&e, 3);
        // Neuron 1 contributes 1 % of the fitness: redundant.
        let net =
            Network::from_neurons(2, 1, &[vec![5.0, 0.0, 0.0], vec![0.1, 0.0, 0.0], vec![4.9, 0.0, 0.0]]).unwrap();
        st.best = Some((net, 10.0));
        assert_eq!(
            e.lesion_test(&redundancy_evaluator(), &mut st, 1).unwrap(),
            LesionOutcome::Remove { neuron: 1 }
        );
        assert_eq!(st.evaluations, 4, "whole + 3 lesioned");
        // Every neuron carries a third: none is redundant.
        let net =
            Network::from_neurons(2, 1, &[vec![1.0, 0.0, 0.0], vec![1.0, 0.0, 0.0], vec![1.0, 0.0, 0.0]]).unwrap();
        st.best = Some((net, 3.0));
        assert_eq!(
            e.lesion_test(&redundancy_evaluator(), &mut st, 1).unwrap(),
            LesionOutcome::Add
        );
        // Never below one hidden neuron.
        let net = Network::from_neurons(2, 1, &[vec![0.0, 0.0, 0.0]]).unwrap();
        st.best = Some((net, 0.0));
        assert_eq!(
            e.lesion_test(&redundancy_evaluator(), &mut st, 1).unwrap(),
            LesionOutcome::Add
        );
    }

    fn run_states(settings: EspSettings, generations: usize) -> Vec<(usize, Option<usize>, Option<LesionOutcome>)> {
        let e = esp(EspSettings {
            subpop_size: 8,
            trials_per_neuron: 2,
            stagnation: 3,
            ..settings
        });
        let mut st = state(&e, 5);
        let eval = all_neurons_needed();
        (1..=generations)
            .map(|g| {
                let r = e.generation(&eval, &mut st, g).unwrap();
                (st.subpops.len(), st.best.as_ref().map(|(b, _)| b.hidden()), r.lesion)
            })
            .collect()
    }

    #[test]
    fn discard_all_keeps_the_subpop_count_within_best_plus_or_minus_one() {
        let states = run_states(EspSettings::hoverstad(), 120);
        assert!(
            states.iter().filter(|s| s.2.is_some()).count() >= 5,
            "lesion tests happened"
        );
        for (subpops, best, _) in &states {
            let best = best.unwrap();
            assert!(
                subpops.abs_diff(best) <= 1,
                "{subpops} sub-populations, best has {best}"
            );
        }
        assert!(states.iter().any(|s| s.0 == 6), "a sub-population was added");
        // Gomez's form: failed lesion tests keep adding sub-populations.
        let gomez = run_states(
            EspSettings {
                burst: BurstMode::Gomez,
                ..EspSettings::hoverstad()
            },
            120,
        );
        let last = gomez.last().unwrap();
        assert!(last.0 >= last.1.unwrap() + 3, "{last:?}");
    }

    #[test]
    fn erase_best_forgets_the_best_on_a_topology_change_but_keeps_the_champion() {
        let e = esp(EspSettings {
            subpop_size: 8,
            trials_per_neuron: 2,
            stagnation: 3,
            erase_best: true,
            ..EspSettings::hoverstad()
        });
        let mut st = state(&e, 5);
        let eval = all_neurons_needed();
        let mut saw_erase = false;
        for g in 1..=60 {
            let r = e.generation(&eval, &mut st, g).unwrap();
            if r.lesion.is_some() {
                assert!(st.best.is_none(), "forgotten at the change");
                assert_eq!(r.best, None);
                saw_erase = true;
                let champion = st.champion.as_ref().unwrap();
                assert_eq!((champion.generation, champion.fitness), (1, 1.0), "the champion stays");
            }
            if let Some((b, _)) = &st.best {
                assert_eq!(b.hidden(), st.subpops.len(), "the best always has the current size");
            }
        }
        assert!(saw_erase);
    }

    #[test]
    fn a_run_stops_where_the_goal_the_budget_or_the_callback_says_and_returns_its_result() {
        let settings = EspSettings {
            subpop_size: 8,
            trials_per_neuron: 2,
            generations: 40,
            ..EspSettings::hoverstad()
        };
        let eval = redundancy_evaluator();
        let run = |stop: StopAt, stop_after: usize| {
            Esp::new(settings.clone(), 3)
                .unwrap()
                .stop_at(stop)
                .run(&eval, |r| {
                    if r.generation == stop_after {
                        Control::Stop
                    } else {
                        Control::Continue
                    }
                })
                .unwrap()
        };
        let whole = run(StopAt::NEVER, 0);
        assert_eq!((whole.ending, whole.records.len()), (Ending::Completed, 40));
        let prefix = |result: &RunResult| {
            assert_eq!(
                result.records[..],
                whole.records[..result.records.len()],
                "the same run, cut short"
            );
        };
        let goal = whole.records[9].champion;
        let reached = run(
            StopAt {
                goal: Some(goal),
                ..StopAt::NEVER
            },
            0,
        );
        prefix(&reached);
        assert_eq!(reached.ending, Ending::Goal);
        assert_eq!(reached.records.last().unwrap().champion, goal);
        assert!(reached.records.len() <= 10);
        // The champion's evaluation number: 16 networks a generation, plus lesion tests.
        let champion = &reached.champion;
        let before = match champion.generation {
            1 => 0,
            g => reached.records[g - 2].evaluations,
        };
        assert!(champion.evaluation > before && champion.evaluation <= before + 16);
        let budget = run(
            StopAt {
                evaluations: Some(100),
                ..StopAt::NEVER
            },
            0,
        );
        prefix(&budget);
        assert_eq!(budget.ending, Ending::Budget);
        let spent = budget.evaluations();
        assert!(
            spent >= 100 && budget.records[budget.records.len() - 2].evaluations < 100,
            "{spent}"
        );
        let told = run(StopAt::NEVER, 7);
        prefix(&told);
        assert_eq!((told.ending, told.records.len()), (Ending::Stopped, 7));
    }

    #[test]
    fn gomez_and_hoverstad_differ_in_burst_mode_lesion_timing_and_threshold_only() {
        let (g, h) = (EspSettings::gomez(), EspSettings::hoverstad());
        assert_eq!(EspSettings::default(), g);
        assert_eq!(
            (g.burst, g.bursts_before_lesion, g.lesion_threshold),
            (BurstMode::Gomez, 1, 0.8)
        );
        assert_eq!(
            (h.burst, h.bursts_before_lesion, h.lesion_threshold),
            (BurstMode::DiscardAll, 2, 0.9)
        );
        assert_eq!(
            EspSettings {
                burst: h.burst,
                bursts_before_lesion: h.bursts_before_lesion,
                lesion_threshold: h.lesion_threshold,
                ..g
            },
            h
        );
        let err = Esp::new(
            EspSettings {
                mutation_rate: 1.5,
                ..g
            },
            1,
        )
        .unwrap_err();
        assert_eq!(
            err,
            SettingsError::NotAProbability {
                name: "esp.mutation_rate",
                value: 1.5
            }
        );
        assert_eq!(
            err.to_string(),
            "esp.mutation_rate must be a probability in [0, 1], got 1.5"
        );
    }

    /// Feeds `tops` to `conclude` as the generations' best fitnesses (no
    /// lesion tests) and returns the generations that burst.
    fn bursts_for(rule: StagnationRule, tops: &[f64]) -> Vec<usize> {
        let e = esp(EspSettings {
            subpop_size: 8,
            trials_per_neuron: 2,
            stagnation: 3,
            stagnation_rule: rule,
            topology: TopologyMode::Off,
            ..EspSettings::default()
        });
        let mut st = state(&e, 2);
        let eval = all_neurons_needed();
        let mut bursts = Vec::new();
        for (g, &top) in tops.iter().enumerate() {
            let generation = g + 1;
            let picks = e.sample(generation, st.subpops.len());
            let network = st.networks(&picks).unwrap().network(0).into_owned();
            let fitness = vec![top; picks.count()];
            let record = e
                .conclude(&eval, &mut st, &picks, fitness, (network, top, 1), generation)
                .unwrap();
            if record.burst {
                bursts.push(generation);
            }
        }
        bursts
    }

    #[test]
    fn stagnation_follows_the_phase_best_or_the_all_time_best() {
        // The best of generation 1 stands; the burst at 4 sets the
        // population back, which climbs again during 5-7 without reaching 5.
        let tops = [5.0, 5.0, 5.0, 5.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0];
        // Phase best: each rise postpones the burst; stagnation is 3
        // generations after the phase best last rose.
        assert_eq!(bursts_for(StagnationRule::PhaseBest, &tops), [4, 10]);
        // All-time best: a fruitless burst is followed by the next exactly 3 later.
        assert_eq!(bursts_for(StagnationRule::AllTimeBest, &tops), [4, 7, 10, 13]);
        // A new all-time best restarts both counts.
        let rising = [1.0, 2.0, 3.0, 3.0, 3.0, 3.0, 4.0, 4.0, 4.0, 4.0];
        assert_eq!(bursts_for(StagnationRule::PhaseBest, &rising), [6, 10]);
        assert_eq!(bursts_for(StagnationRule::AllTimeBest, &rising), [6, 10]);
    }
}
