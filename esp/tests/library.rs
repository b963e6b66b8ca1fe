//! The library as a user meets it: runs saved and restored at any point,
//! fitness of any sign, careless inputs answered by typed errors, and the
//! stagnation rule's minimum improvement.

mod common;

use common::{bits, problem, small};
use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::Stream;
use esp_neuroevolution::{
    AnyRun, AskTell, Esp, EspSettings, Evaluator, FnEvaluator, HillClimb, HillClimbSettings, RunError, RunResult,
    Sampling, SettingsError, StopAt, TopologyMode,
};

/// XOR's squared error over its four patterns (inputs x1, x2 and a bias).
fn xor_error(net: &Network) -> anyhow::Result<f64> {
    let mut out = [0.0];
    let mut error = 0.0;
    for (a, b) in [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)] {
        net.try_activate(&[a, b, 1.0], &mut out)?;
        let target = if a != b { 1.0 } else { 0.0 };
        error += (out[0] - target).powi(2);
    }
    Ok(error)
}

/// XOR scored as `offset - squared error`, the error rounded to 1/64 so
/// that any offset that is a small integer shifts every fitness exactly.
fn xor(offset: f64) -> impl Evaluator<Worker = ()> {
    FnEvaluator::new(3, 1, move |net: &Network, _: &mut Stream| {
        Ok(offset - (xor_error(net)? * 64.0).round() / 64.0)
    })
}

/// Drives `run` to its end; after every `every`-th tell (counting from
/// `offset`) it is saved to JSON, dropped and restored. Returns the result
/// and the number of restores.
fn drive_with_restores<R, E>(mut run: R, evaluator: &E, every: usize, offset: usize) -> (RunResult, usize)
where
    R: AskTell + serde::Serialize + serde::de::DeserializeOwned,
    E: Evaluator,
{
    let (mut tells, mut restores) = (0, 0);
    while let Some(asked) = run.ask().unwrap() {
        let (ticket, fitness) = (asked.ticket(), asked.evaluate(evaluator).unwrap());
        run.tell(ticket, &fitness).unwrap();
        tells += 1;
        if tells % every == offset % every {
            let saved = serde_json::to_string(&run).unwrap();
            run = serde_json::from_str(&saved).unwrap();
            restores += 1;
        }
    }
    (run.result().unwrap(), restores)
}

#[test]
fn an_esp_run_saved_and_restored_anywhere_ends_as_one_never_stopped() {
    let evaluator = problem();
    for settings in [EspSettings::gomez(), EspSettings::hoverstad()] {
        let esp = Esp::new(small(settings), 4).unwrap();
        let whole = esp.run(&evaluator, |_| {}).unwrap();
        assert!(
            whole.records.iter().any(|r| r.lesion.is_some()),
            "lesion tests happened"
        );
        // Saved after every tell (between a generation's evaluation and its
        // lesion test too), and after every third.
        for (every, offset) in [(1, 0), (3, 1)] {
            let (resumed, restores) = drive_with_restores(esp.start(2, 1).unwrap(), &evaluator, every, offset);
            assert!(restores >= 20);
            assert_eq!(bits(&resumed), bits(&whole));
        }
    }
}

#[test]
fn a_hill_climbing_run_saved_and_restored_anywhere_ends_as_one_never_stopped() {
    let evaluator = problem();
    for elitist in [false, true] {
        let hill_climb = HillClimb::new(
            HillClimbSettings {
                hidden: 2,
                candidates: 6,
                cycles: 40,
                elitist,
                ..HillClimbSettings::default()
            },
            8,
        )
        .unwrap();
        let whole = hill_climb.run(&evaluator, |_| {}).unwrap();
        let (resumed, restores) = drive_with_restores(hill_climb.start(2, 1).unwrap(), &evaluator, 1, 0);
        assert_eq!(restores, 40 + usize::from(elitist), "the elitist base's tell too");
        assert_eq!(bits(&resumed), bits(&whole));
        // Either kind behind AnyRun, tagged with its kind.
        let any = AnyRun::from(hill_climb.start(2, 1).unwrap());
        assert!(serde_json::to_string(&any).unwrap().starts_with(r#"{"hill_climb":"#));
        assert_eq!(bits(&drive_with_restores(any, &evaluator, 2, 0).0), bits(&whole));
    }
}

#[test]
fn a_saved_run_that_does_not_fit_its_settings_is_refused_and_old_tickets_are_foreign() {
    let evaluator = problem();
    let esp = Esp::new(small(EspSettings::gomez()), 2).unwrap();
    let mut run = esp.start(2, 1).unwrap();
    let ticket = run.ask().unwrap().unwrap().ticket();
    let saved = serde_json::to_value(&run).unwrap();
    // The restored run issues tickets of its own.
    let mut restored: esp_neuroevolution::EspRun = serde_json::from_value(saved.clone()).unwrap();
    let fitness = restored.ask().unwrap().unwrap().evaluate(&evaluator).unwrap();
    assert!(matches!(restored.tell(ticket, &fitness), Err(RunError::ForeignTicket)));
    // Sub-populations of another size than the settings', or a weight that is not a number.
    let mut smaller = saved.clone();
    smaller["search"]["settings"]["subpop_size"] = 9.into();
    let error = serde_json::from_value::<esp_neuroevolution::EspRun>(smaller).unwrap_err();
    assert!(error.to_string().contains("cannot restore the run"), "{error}");
    let mut invalid = saved;
    invalid["search"]["settings"]["mutation_rate"] = 2.0.into();
    let error = serde_json::from_value::<esp_neuroevolution::EspRun>(invalid).unwrap_err();
    assert!(
        error.to_string().contains("esp.mutation_rate must be a probability"),
        "{error}"
    );
    // A network checks its weights and shape as it is read.
    let network = Network::from_genes(2, 1, vec![0.5, -1.0, 2.0]).unwrap();
    let json = serde_json::to_string(&network).unwrap();
    assert_eq!(serde_json::from_str::<Network>(&json).unwrap(), network);
    let error = serde_json::from_str::<Network>(&json.replace("[0.5,-1.0,2.0]", "[0.5,-1.0]")).unwrap_err();
    assert!(error.to_string().contains("whole hidden neurons"), "{error}");
}

#[test]
fn adding_a_constant_to_the_fitness_changes_no_run_whatever_its_sign() {
    for sampling in [Sampling::Random, Sampling::Systematic] {
        // One network a neuron: with random sampling many neurons join no
        // network, and must rank below every one that did, at any sign.
        let settings = EspSettings {
            subpop_size: 10,
            trials_per_neuron: 1,
            initial_hidden: 2,
            generations: 80,
            stagnation: 5,
            sampling,
            topology: TopologyMode::Off,
            ..EspSettings::default()
        };
        let esp = Esp::new(settings, 3).unwrap();
        let positive = esp.run(&xor(4.0), |_| {}).unwrap();
        for offset in [0.0, -16.0, 1024.0] {
            let shifted = esp.run(&xor(offset), |_| {}).unwrap();
            assert_eq!(
                shifted.champion.network, positive.champion.network,
                "{sampling:?} {offset}"
            );
            assert_eq!(shifted.champion.evaluation, positive.champion.evaluation);
            for (a, b) in shifted.records.iter().zip(&positive.records) {
                assert_eq!(
                    (a.max - offset, a.bursts),
                    (b.max - 4.0, b.bursts),
                    "{sampling:?} {offset}"
                );
            }
        }
    }
}

#[test]
fn careless_inputs_are_typed_errors() {
    let evaluator = xor(4.0);
    let esp = Esp::new(small(EspSettings::gomez()), 1).unwrap();
    for goal in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let stop = StopAt {
            goal: Some(goal),
            evaluations: None,
        };
        let error = esp.clone().stop_at(stop).run(&evaluator, |_| {}).unwrap_err();
        assert!(
            matches!(
                error,
                RunError::Settings(SettingsError::NotFinite { name: "stop.goal", .. })
            ),
            "{error:?}"
        );
        let hill_climb = HillClimb::new(HillClimbSettings::default(), 1).unwrap().stop_at(stop);
        assert!(matches!(hill_climb.start(3, 1), Err(RunError::Settings(_))));
    }
    // Cycle 0 has no rates.
    let hill_climb = HillClimb::new(HillClimbSettings::default(), 1).unwrap();
    assert_eq!(
        hill_climb.rates(0),
        Err(SettingsError::TooFew {
            name: "cycle",
            value: 0,
            min: 1
        })
    );
    // An evaluator that feeds the network the wrong number of inputs: an
    // error naming the lengths, not a panic.
    let three_inputs = FnEvaluator::new(2, 1, |net: &Network, _: &mut Stream| {
        let mut out = [0.0];
        net.try_activate(&[0.0, 1.0, 1.0], &mut out)?;
        Ok(out[0])
    });
    let error = esp.run(&three_inputs, |_| {}).unwrap_err();
    assert_eq!(error.to_string(), "the network has 2 inputs, got 3");
    // An infinite fitness would break the ranking.
    let infinite = FnEvaluator::new(2, 1, |_: &Network, _: &mut Stream| Ok(f64::INFINITY));
    let error = esp.run(&infinite, |_| {}).unwrap_err();
    assert!(matches!(error, RunError::InfiniteFitness { network: 0, value } if value == f64::INFINITY));
    // A negative minimum improvement.
    let error = Esp::new(
        EspSettings {
            stagnation_min_improvement: -1.0,
            ..EspSettings::default()
        },
        1,
    )
    .unwrap_err();
    assert_eq!(
        error.to_string(),
        "esp.stagnation_min_improvement must be finite and >= 0, got -1"
    );
}

#[test]
fn a_minimum_improvement_lets_a_creeping_run_burst() {
    // XOR, 2 hidden units of 20 neurons, stagnation after 20 generations:
    // each generation's best creeps up by hairs, so under the phase-best
    // rule the run never stagnates and never bursts.
    let settings = EspSettings {
        subpop_size: 20,
        initial_hidden: 2,
        generations: 500,
        ..EspSettings::default()
    };
    let xor = FnEvaluator::new(3, 1, |net: &Network, _: &mut Stream| Ok(4.0 - xor_error(net)?));
    let creeping = Esp::new(settings.clone(), 2).unwrap().run(&xor, |_| {}).unwrap();
    let last = creeping.records.last().unwrap();
    assert_eq!(last.bursts, 0);
    assert!((3.4..3.6).contains(&last.champion), "{}", last.champion);
    let with_minimum = EspSettings {
        stagnation_min_improvement: 0.01,
        ..settings
    };
    let bursting = Esp::new(with_minimum, 2).unwrap().run(&xor, |_| {}).unwrap();
    assert!(bursting.records.last().unwrap().bursts >= 10);
}

#[test]
fn runs_together_saved_after_a_round_resume_to_their_own_runs() {
    use esp_neuroevolution::together::run_together_with;
    use esp_neuroevolution::Control;
    let evaluator = problem();
    let esp = Esp::new(small(EspSettings::hoverstad()), 5).unwrap();
    let hill_climb = HillClimb::new(
        HillClimbSettings {
            hidden: 2,
            candidates: 6,
            cycles: 30,
            elitist: true,
            ..HillClimbSettings::default()
        },
        6,
    )
    .unwrap();
    let alone = [
        esp.run(&evaluator, |_| {}).unwrap(),
        hill_climb.run(&evaluator, |_| {}).unwrap(),
    ];
    let start = || -> Vec<AnyRun> { vec![esp.start(2, 1).unwrap().into(), hill_climb.start(2, 1).unwrap().into()] };
    let evaluators = [&evaluator, &evaluator];
    // Saved after round 7, as a killed process would have left them.
    let mut saved = String::new();
    let mut runs = start();
    let errors = run_together_with(
        &mut runs,
        &evaluators,
        |_, _| Control::Continue,
        |round, runs| {
            if round == 7 {
                saved = serde_json::to_string(runs).unwrap();
            }
        },
    );
    assert!(errors.iter().all(Option::is_none));
    let mut restored: Vec<AnyRun> = serde_json::from_str(&saved).unwrap();
    assert!(restored.iter().zip(start()).all(|(a, b)| a.same_search(&b)));
    assert!(restored
        .iter()
        .all(|run| !run.records().is_empty() && run.ending().is_none()));
    let errors = run_together_with(&mut restored, &evaluators, |_, _| Control::Continue, |_, _| {});
    assert!(errors.iter().all(Option::is_none));
    for ((resumed, uninterrupted), alone) in restored.into_iter().zip(runs).zip(&alone) {
        assert_eq!(bits(&resumed.into_result().unwrap()), bits(alone));
        assert_eq!(bits(&uninterrupted.into_result().unwrap()), bits(alone));
    }
}
