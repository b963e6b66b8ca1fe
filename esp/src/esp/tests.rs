//! ESP's unit tests: each step of a generation against its definition.

use super::generation::{Stats, Step};
use super::population::State;
use super::stagnation::lesion_variants;
use super::*;
use crate::network::{Network, NetworkSet};
use crate::rng::stream;
use crate::run::{Advance, Search};
use crate::subpop::{Picks, Subpop};
use crate::{
    purpose, Control, Ending, Evaluator, FnEvaluator, GenerationRecord, LesionOutcome, RunError, RunResult,
    SettingsError, StopAt,
};

/// Test steps: a generation, or part of one, evaluated on the spot.
impl Esp {
    /// Steps generation `generation` on from `advance` with `evaluator`
    /// until its record.
    fn finish<E: Evaluator>(
        &self,
        evaluator: &E,
        state: &mut State,
        mut advance: Advance<Step>,
        generation: usize,
    ) -> Result<GenerationRecord, RunError> {
        loop {
            match advance {
                Advance::Record(record) => return Ok(record),
                Advance::Begin => advance = Advance::Ask(self.begin(state, generation)?),
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
fn random_sampling_picks_each_network_s_neurons_uniformly_and_independently() {
    let e = esp(EspSettings::hoverstad());
    let mut counts = vec![[0usize; 40]; 5];
    for generation in 1..=25 {
        let picks = e.sample(generation, 5);
        assert_eq!(picks.count(), 400);
        for network in picks.networks() {
            for (subpop, &neuron) in network.iter().enumerate() {
                counts[subpop][neuron] += 1;
            }
        }
    }
    // 25 generations x 400 networks: each neuron expected 250 times.
    for subpop in &counts {
        let chi2: f64 = subpop.iter().map(|&c| (c as f64 - 250.0).powi(2) / 250.0).sum();
        // 39 degrees of freedom: the 99.9th percentile is 72.1.
        assert!(chi2 < 72.1, "chi-square {chi2}");
        // Not systematic: some neuron is picked other than 10 times a generation.
        assert!(subpop.iter().any(|&c| c != 250));
    }
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
    let best = Network::from_neurons(2, 1, &[vec![1.0, 2.0, 3.0], vec![-1.0, 0.0, 1.0], vec![4.0, 4.0, 4.0]]).unwrap();
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
    let net = Network::from_neurons(2, 1, &[vec![5.0, 0.0, 0.0], vec![0.1, 0.0, 0.0], vec![4.9, 0.0, 0.0]]).unwrap();
    st.best = Some((net, 10.0));
    assert_eq!(
        e.lesion_test(&redundancy_evaluator(), &mut st, 1).unwrap(),
        LesionOutcome::Remove { neuron: 1 }
    );
    assert_eq!(st.evaluations, 4, "whole + 3 lesioned");
    // Every neuron carries a third: none is redundant.
    let net = Network::from_neurons(2, 1, &[vec![1.0, 0.0, 0.0], vec![1.0, 0.0, 0.0], vec![1.0, 0.0, 0.0]]).unwrap();
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

/// What `read` takes from each of `generations` generations of `settings`
/// (small populations, b = 3) on a problem that never improves after its
/// first generation.
fn small_run<T>(
    settings: EspSettings,
    generations: usize,
    mut read: impl FnMut(GenerationRecord, &State) -> T,
) -> Vec<T> {
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
            let record = e.generation(&eval, &mut st, g).unwrap();
            read(record, &st)
        })
        .collect()
}

fn run_states(settings: EspSettings, generations: usize) -> Vec<(usize, Option<usize>, Option<LesionOutcome>)> {
    small_run(settings, generations, |r, st| {
        (st.subpops.len(), st.best.as_ref().map(|(b, _)| b.hidden()), r.lesion)
    })
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
        erase_at: EraseAt::TopologyChange,
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

/// Records of [`small_run`], with the erased bar after each generation.
fn records_of(settings: EspSettings, generations: usize) -> Vec<(GenerationRecord, Option<f64>)> {
    small_run(settings, generations, |record, st| (record, st.erased))
}

/// The records of [`records_of`] as text, to compare two runs whole.
fn debug_records(records: Vec<(GenerationRecord, Option<f64>)>) -> Vec<String> {
    records.iter().map(|(r, _)| format!("{r:?}")).collect()
}

#[test]
fn erase_at_burst_forgets_the_best_at_every_burst_and_lesion_tests_still_follow() {
    let erase = |at| EspSettings {
        erase_best: true,
        erase_at: at,
        ..EspSettings::hoverstad()
    };
    let at_burst = records_of(erase(EraseAt::Burst), 60);
    let bursts: Vec<&GenerationRecord> = at_burst.iter().map(|(r, _)| r).filter(|r| r.burst).collect();
    assert!(bursts.len() >= 10, "{} bursts", bursts.len());
    // Table 6's caption: the best network is erased at each burst mutation.
    assert!(bursts.iter().all(|r| r.best.is_none()), "forgotten at every burst");
    assert!(at_burst.iter().filter(|(r, _)| !r.burst).all(|(r, _)| r.best.is_some()));
    // The forgotten fitness is the bar: no network beats 1, so the
    // fruitless bursts still bring lesion tests (every second burst).
    assert!(at_burst.iter().skip(4).all(|(_, erased)| *erased == Some(1.0)));
    let lesions = bursts.iter().filter(|r| r.lesion.is_some()).count();
    assert!(
        lesions * 2 >= bursts.len() - 1,
        "{lesions} lesion tests in {} bursts",
        bursts.len()
    );
    assert!(at_burst.iter().all(|(r, _)| r.champion == 1.0), "the champion stays");
    // On a topology change only: a burst without a lesion test keeps the best.
    let on_change = records_of(erase(EraseAt::TopologyChange), 60);
    assert!(on_change
        .iter()
        .any(|(r, _)| r.burst && r.lesion.is_none() && r.best.is_some()));
    assert!(on_change.iter().all(|(r, _)| r.lesion.is_none() || r.best.is_none()));
    assert!(on_change.iter().all(|(_, erased)| erased.is_none()));
    // erase_at alone changes nothing while erase_best is off.
    let off = |at| EspSettings {
        erase_at: at,
        ..EspSettings::hoverstad()
    };
    assert_eq!(
        debug_records(records_of(off(EraseAt::Burst), 40)),
        debug_records(records_of(off(EraseAt::TopologyChange), 40))
    );
}

#[test]
fn the_lesion_trigger_counts_fruitless_bursts_and_the_threshold_is_the_share_kept() {
    // The trigger: the first lesion test comes at the n-th fruitless burst.
    for trigger in [1, 2, 3] {
        let records = records_of(
            EspSettings {
                bursts_before_lesion: trigger,
                burst: BurstMode::Gomez,
                ..EspSettings::hoverstad()
            },
            80,
        );
        let bursts: Vec<&GenerationRecord> = records.iter().map(|(r, _)| r).filter(|r| r.burst).collect();
        let first = bursts.iter().position(|r| r.lesion.is_some()).unwrap();
        assert_eq!(
            first, trigger,
            "trigger {trigger}: a lesion test at the burst after {trigger} fruitless ones"
        );
    }
    // The threshold: a neuron whose loss keeps exactly 85 % is redundant
    // at 0.8, not at 0.9.
    let net = Network::from_neurons(2, 1, &[vec![8.5, 0.0, 0.0], vec![1.5, 0.0, 0.0]]).unwrap();
    for (threshold, outcome) in [(0.8, LesionOutcome::Remove { neuron: 1 }), (0.9, LesionOutcome::Add)] {
        let e = esp(EspSettings {
            lesion_threshold: threshold,
            ..EspSettings::hoverstad()
        });
        let mut st = state(&e, 2);
        st.best = Some((net.clone(), 10.0));
        assert_eq!(e.lesion_test(&redundancy_evaluator(), &mut st, 1).unwrap(), outcome);
    }
}

#[test]
fn the_burst_scale_is_the_cauchy_scale_of_the_burst_noise() {
    for scale in [0.1, 1.0] {
        let e = esp(EspSettings {
            topology: TopologyMode::Off,
            burst_scale: scale,
            ..EspSettings::hoverstad()
        });
        let mut st = state(&e, 2);
        let best = Network::from_neurons(2, 1, &[vec![1.0, 2.0, 3.0], vec![-1.0, 0.0, 1.0]]).unwrap();
        st.best = Some((best.clone(), 1.0));
        e.stagnate(&all_neurons_needed(), &mut st, 1).unwrap();
        let mut deltas: Vec<f64> = (0..2)
            .flat_map(|k| {
                let reference = best.neuron(k).to_vec();
                st.subpops[k]
                    .neurons()
                    .flat_map(move |n| {
                        n.iter()
                            .zip(reference.clone())
                            .map(|(a, b)| (a - b).abs())
                            .collect::<Vec<_>>()
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        deltas.sort_by(f64::total_cmp);
        // The median of |Cauchy(scale)| is the scale itself.
        let median = deltas[deltas.len() / 2];
        assert!(
            (0.7 * scale..1.4 * scale).contains(&median),
            "scale {scale}: median {median}"
        );
    }
}

#[test]
fn relesion_every_burst_tests_the_best_at_each_discard_all_burst() {
    let relesion = |r| EspSettings {
        relesion: r,
        ..EspSettings::hoverstad()
    };
    // Pending: the first bursts (no change yet pending, fewer than two
    // fruitless bursts) rebuild the sub-populations without a lesion test.
    let pending = records_of(relesion(Relesion::Pending), 60);
    let first_burst = pending.iter().map(|(r, _)| r).find(|r| r.burst).unwrap();
    assert_eq!(first_burst.lesion, None);
    // Every burst: each discard-all burst is followed by a lesion test,
    // whose change is applied.
    let every = records_of(relesion(Relesion::EveryBurst), 60);
    let bursts: Vec<&GenerationRecord> = every.iter().map(|(r, _)| r).filter(|r| r.burst).collect();
    assert!(bursts.len() >= 10);
    assert!(bursts.iter().all(|r| r.lesion.is_some()), "{bursts:?}");
    assert_eq!(bursts[0].lesion, Some(LesionOutcome::Add));
    assert_eq!(bursts[0].subpops, 6, "the first burst's test adds a sub-population");
    // Gomez's burst keeps its own timing: the setting is discard-all's.
    let gomez = |r| EspSettings {
        burst: BurstMode::Gomez,
        relesion: r,
        ..EspSettings::hoverstad()
    };
    assert_eq!(
        debug_records(records_of(gomez(Relesion::EveryBurst), 40)),
        debug_records(records_of(gomez(Relesion::Pending), 40))
    );
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
fn gomez_and_hoverstad_differ_in_burst_mode_lesion_timing_threshold_and_erasing_only() {
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
    assert_eq!((g.erase_at, h.erase_at), (EraseAt::TopologyChange, EraseAt::Burst));
    assert_eq!((g.relesion, h.relesion), (Relesion::Pending, Relesion::Pending));
    assert_eq!(
        EspSettings {
            burst: h.burst,
            bursts_before_lesion: h.bursts_before_lesion,
            lesion_threshold: h.lesion_threshold,
            erase_at: h.erase_at,
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

#[test]
fn an_ask_gives_each_network_s_picks_and_credit_follows_them() {
    use crate::AskTell as _;
    let e = esp(EspSettings {
        subpop_size: 4,
        ..EspSettings::hoverstad()
    });
    let credit = Credit::Mean.neuron_credits(
        1,
        4,
        [&[1usize][..], &[1], &[2], &[2], &[0]],
        &[9.0, 0.0, 5.0, 5.0, 1.0],
    );
    assert_eq!(credit, [Some(1.0), Some(4.5), Some(5.0), None]);
    let credit = Credit::Max.neuron_credits(
        1,
        4,
        [&[1usize][..], &[1], &[2], &[2], &[0]],
        &[9.0, 0.0, 5.0, 5.0, 1.0],
    );
    assert_eq!(credit, [Some(1.0), Some(9.0), Some(5.0), None]);

    // A generation's picks name the neurons its networks are made of.
    let mut run = e.start(2, 1).unwrap();
    let asked = run.ask().unwrap().unwrap();
    assert!(matches!(asked.purpose(), crate::AskPurpose::Generation(1)));
    let picks = e.sample(1, e.settings.initial_hidden);
    for (j, expected) in picks.networks().enumerate() {
        assert_eq!(asked.picks(j), Some(expected));
    }
    assert_eq!(asked.picks(picks.count()), None);
}
