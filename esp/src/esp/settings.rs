//! ESP's settings: every switch and number of a run, their defaults
//! (Gomez's ESP), Høverstad's values, and their bounds.

use serde::{Deserialize, Serialize};

use crate::limits::{
    check_cauchy_limit, check_count, check_non_negative, check_positive, check_probability, MAX_GENERATIONS,
    MAX_HIDDEN, MAX_NETWORKS_PER_GENERATION, MAX_SUBPOP_SIZE, MAX_TRIALS_PER_NEURON, MIN_SUBPOP_SIZE,
};
use crate::SettingsError;

/// How networks are formed from the sub-populations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// Each network takes a uniformly random neuron from every
    /// sub-population (Gomez's ESP and Høverstad's paper). A neuron may
    /// then join no network in a generation: it ranks below every neuron
    /// that joined one.
    Random,
    /// Høverstad's alternative (his Table 4): per round, shuffle every
    /// sub-population and build network k from the k-th neurons; every
    /// neuron is evaluated exactly `trials_per_neuron` times.
    Systematic,
}

/// How a neuron's fitness is derived from its networks'.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Credit {
    /// The mean fitness of the networks it took part in (Gomez's ESP and
    /// Høverstad's paper).
    Mean,
    /// The highest (Høverstad's Table 5).
    Max,
}

/// What burst mutation does with the sub-populations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BurstMode {
    /// Høverstad's: discard all sub-populations, rebuild one per neuron of
    /// the best network, then apply a pending topology change again (lesion
    /// test, add or remove).
    DiscardAll,
    /// Gomez's original: rebuild the sub-populations of the best network's
    /// neurons; sub-populations added since it was found persist untouched.
    Gomez,
}

/// When the search has stagnated (Høverstad's §3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StagnationRule {
    /// The paper's and Gomez's code's reading: the best network fitness of
    /// each generation is logged since the last burst mutation (the phase
    /// best, reset at every burst and topology change); stagnation is
    /// declared when it has not risen (by more than
    /// [`EspSettings::stagnation_min_improvement`]) for `stagnation`
    /// generations. After a burst the population climbs back, and each
    /// rise postpones the next burst.
    PhaseBest,
    /// Generations since the search's best network (all-time) last
    /// improved (by more than the minimum improvement): after a fruitless
    /// burst the next one follows exactly `stagnation` generations later.
    AllTimeBest,
}

/// Whether lesion tests change the topology.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TopologyMode {
    /// Lesion tests add or remove sub-populations (Gomez's ESP and
    /// Høverstad's paper).
    Lesion,
    /// No lesion tests, no topology change (Høverstad's Table 6).
    Off,
}

/// When [`EspSettings::erase_best`] forgets the search's best network
/// (Høverstad's Table 6, "Erase").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EraseAt {
    /// At every burst mutation, once the sub-populations are rebuilt
    /// around it: Table 6's caption ("best network erased at each burst
    /// mutation") and §5.3, which describe the experiment that made the
    /// table.
    Burst,
    /// Whenever a sub-population is added or removed: §3.2's wording of
    /// the option ("discard the best network whenever a sub-population is
    /// added or removed").
    TopologyChange,
}

/// When discard-all burst mutation ([`BurstMode::DiscardAll`]) asks for a
/// new lesion test of the best network after rebuilding the
/// sub-populations around it, outside the lesion test that
/// [`EspSettings::bursts_before_lesion`] triggers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Relesion {
    /// While a topology change is pending: the last lesion test's change
    /// has not yet brought a better network (§3.2's example: "erasing all
    /// 6 sub-populations after stagnation, after which a new lesion test is
    /// performed on the 5-neuron solution, a 6th sub-population is once
    /// again added").
    Pending,
    /// At every discard-all burst mutation: §3.2's "discard all
    /// sub-populations at each round of burst mutation", each followed by
    /// "a new lesion test ... on the" best network, whether or not a
    /// change is pending.
    EveryBurst,
}

/// Every setting of ESP, named in configuration files as `esp.<field>`.
///
/// The default is Gomez's ESP ([`EspSettings::gomez`]); Høverstad's
/// modified ESP ([`EspSettings::hoverstad`]) differs in three fields
/// (`burst`, `bursts_before_lesion`, `lesion_threshold`). Each field's doc
/// gives its default, Gomez's and Høverstad's values, and its bounds, which
/// [`EspSettings::validate`] checks ([`crate::limits`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EspSettings {
    /// Neurons per sub-population. Default 40 (Gomez's and Høverstad's).
    /// Bounds: 4 ([`MIN_SUBPOP_SIZE`]) to 10,000.
    pub subpop_size: usize,
    /// Networks per generation = this x `subpop_size`. Default 10 (Gomez's
    /// and Høverstad's). Bounds: 1 to 1,000, and at most 100,000 networks
    /// per generation.
    pub trials_per_neuron: usize,
    /// Sub-populations (hidden neurons) at the start. Default 5 (Gomez's
    /// and Høverstad's). Bounds: 1 to 100.
    pub initial_hidden: usize,
    /// Generations. Default 2000 (Høverstad's; Gomez's ESP runs until
    /// solved). Bounds: 1 to 1,000,000.
    pub generations: usize,
    /// Initial weights are uniform in (-range, range). Default 6 (Gomez's
    /// and Høverstad's). Bounds: (0, 1e6].
    pub init_range: f64,
    /// Network formation. Default random (Gomez's and Høverstad's).
    pub sampling: Sampling,
    /// Neuron credit. Default mean (Gomez's and Høverstad's).
    pub credit: Credit,
    /// Probability that a child gets Cauchy noise on one gene. Default 0.4
    /// (Gomez's and Høverstad's). Bounds: [0, 1].
    pub mutation_rate: f64,
    /// Scale of that Cauchy noise. Default 0.3 (Gomez's and Høverstad's).
    /// Bounds: (0, 1e6].
    pub mutation_scale: f64,
    /// Cauchy draws larger than this in magnitude are drawn again. Default
    /// 10 (Gomez's and Høverstad's). Bounds: (0, 1e6] and at least 0.1 x
    /// the larger of `mutation_scale` and `burst_scale`.
    pub cauchy_limit: f64,
    /// Generations without improvement before a burst mutation (b).
    /// Default 20 (Gomez's code); Høverstad gives no number (the PSA's
    /// chosen value is 50: psa-esp's docs/model.md). Bounds: at least 1.
    pub stagnation: usize,
    /// What "without improvement" means. Default phase_best (Gomez's code
    /// and Høverstad's §3.2).
    pub stagnation_rule: StagnationRule,
    /// The least rise of the best fitness (the phase best or the all-time
    /// best, as `stagnation_rule` says) that counts as an improvement for
    /// the stagnation count: a generation whose best exceeds it by this
    /// much or less counts as stagnant. Default 0 (Gomez's and Høverstad's:
    /// any rise counts). Bounds: finite and >= 0.
    ///
    /// Where fitness creeps up by tiny amounts a run under the phase best
    /// rule may never burst: XOR scored `4 - squared error` with 2 hidden
    /// units of 20 neurons (seed 2) stays near 3.5 for 500 generations
    /// with no burst mutation, as each generation's best rises by a hair;
    /// with a minimum improvement of 0.01 it bursts 23 times (a test in
    /// `tests/library.rs`).
    #[serde(skip_serializing_if = "is_zero")]
    pub stagnation_min_improvement: f64,
    /// Scale of the Cauchy noise of burst mutation, on every gene. Default
    /// 0.3 (Gomez's and Høverstad's). Bounds: (0, 1e6].
    pub burst_scale: f64,
    /// Burst mutation's form. Default gomez (Gomez's); Høverstad's:
    /// discard_all.
    pub burst: BurstMode,
    /// Lesion tests after `bursts_before_lesion` fruitless burst mutations.
    /// Default lesion (Gomez's and Høverstad's).
    pub topology: TopologyMode,
    /// Burst mutations without improvement that trigger a lesion test.
    /// Default 1 (Gomez's code); Høverstad's: 2. Bounds: at least 1.
    pub bursts_before_lesion: usize,
    /// A neuron is redundant when the network without it keeps this share
    /// of the fitness. Default 0.8 (Gomez's code); Høverstad's preset: 0.9
    /// (chosen here). Bounds: [0, 1]. The one setting that reads fitness
    /// as a ratio: the lesion test is the only step of ESP that adding a
    /// constant to every fitness can change.
    pub lesion_threshold: f64,
    /// Forget the search's best network, at the moments `erase_at` says
    /// (Høverstad's Table 6). Default false (Gomez's and Høverstad's).
    pub erase_best: bool,
    /// When `erase_best` forgets the best network. Default
    /// topology_change (the reading of files written before the setting
    /// existed); Høverstad's preset: burst (Table 6's caption).
    pub erase_at: EraseAt,
    /// When discard-all burst mutation tests the best network again.
    /// Default pending (the reading of files written before the setting
    /// existed, and Høverstad's preset).
    pub relesion: Relesion,
}

/// Whether a minimum improvement is the default 0 (left out of a written
/// configuration, which then reads as before the setting existed).
fn is_zero(value: &f64) -> bool {
    *value == 0.0
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
            stagnation_min_improvement: 0.0,
            burst_scale: 0.3,
            burst: BurstMode::Gomez,
            topology: TopologyMode::Lesion,
            bursts_before_lesion: 1,
            lesion_threshold: 0.8,
            erase_best: false,
            erase_at: EraseAt::TopologyChange,
            relesion: Relesion::Pending,
        }
    }

    /// Høverstad's modified ESP (his Table 1): burst mutation discards all
    /// sub-populations ([`BurstMode::DiscardAll`]), two fruitless burst
    /// mutations bring a lesion test, the lesion threshold is 0.9, and
    /// erasing the best network (when switched on) happens at every burst
    /// mutation ([`EraseAt::Burst`], his Table 6's caption).
    pub fn hoverstad() -> EspSettings {
        EspSettings {
            burst: BurstMode::DiscardAll,
            bursts_before_lesion: 2,
            lesion_threshold: 0.9,
            erase_at: EraseAt::Burst,
            ..EspSettings::gomez()
        }
    }

    /// Rejects out-of-range values, naming the setting.
    pub fn validate(&self) -> Result<(), SettingsError> {
        check_count("esp.subpop_size", self.subpop_size, MIN_SUBPOP_SIZE, MAX_SUBPOP_SIZE)?;
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
        check_non_negative("esp.stagnation_min_improvement", self.stagnation_min_improvement)?;
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
