//! Ask/tell: driving a run by hand, or many together, is the same run as
//! `run`, bit for bit; and mistakes in driving it are typed errors.

use esp_neuroevolution::network::{Network, NetworkSet};
use esp_neuroevolution::rng::Stream;
use esp_neuroevolution::together::{evaluate_jobs, run_together, Job};
use esp_neuroevolution::{
    evaluate_all, evaluate_each_part, AskPurpose, AskTell, Control, Ending, Esp, EspSettings, Evaluator, FnEvaluator,
    GenerationRecord, HillClimb, HillClimbSettings, Part, RunError, RunResult, StopAt, TopologyMode,
};

mod common;

use common::{bits, problem, small};
use esp_neuroevolution::rand::RngExt;

/// Drives `run` by hand: each asked network evaluated one by one with its
/// stream, on this thread; returns the result and the purposes asked.
fn by_hand<R: AskTell, E: Evaluator>(
    run: &mut R,
    evaluator: &E,
    mut stop_after: impl FnMut(&GenerationRecord) -> bool,
) -> (RunResult, Vec<AskPurpose>) {
    let mut worker = evaluator.worker().unwrap();
    let mut purposes = Vec::new();
    while let Some(asked) = run.ask().unwrap() {
        purposes.push(asked.purpose());
        let (ticket, streams) = (asked.ticket(), asked.streams());
        let fitness: Vec<f64> = (0..asked.len())
            .map(|j| {
                evaluator
                    .evaluate(&mut worker, &asked.network(j), &mut streams.stream(j))
                    .unwrap()
            })
            .collect();
        if let Some(record) = run.tell(ticket, &fitness).unwrap() {
            if stop_after(record) {
                run.stop();
            }
        }
    }
    (run.result().unwrap(), purposes)
}

#[test]
fn esp_driven_by_hand_is_run_bit_for_bit_with_bursts_and_lesion_tests() {
    let evaluator = problem();
    for settings in [EspSettings::gomez(), EspSettings::hoverstad()] {
        let esp = Esp::new(small(settings.clone()), 17).unwrap();
        let expected = esp.run(&evaluator, |_| {}).unwrap();
        let mut run = esp.start(2, 1).unwrap();
        let (got, purposes) = by_hand(&mut run, &evaluator, |_| false);
        assert_eq!(bits(&got), bits(&expected), "{:?}", settings.burst);
        assert_eq!(got.ending, Ending::Completed);
        let lesion_tests = purposes
            .iter()
            .filter(|p| matches!(p, AskPurpose::LesionTest(_)))
            .count();
        let generations = purposes
            .iter()
            .filter(|p| matches!(p, AskPurpose::Generation(_)))
            .count();
        assert_eq!(generations, 80);
        assert!(
            lesion_tests >= 3,
            "{:?}: {lesion_tests} lesion tests, {} bursts",
            settings.burst,
            got.records.last().unwrap().bursts
        );
        assert_eq!(
            lesion_tests,
            got.records.iter().filter(|r| r.lesion.is_some()).count(),
            "one lesion test per topology change"
        );
        assert!(run.ask().unwrap().is_none(), "an ended run asks for nothing");
    }
}

#[test]
fn the_hill_climber_driven_by_hand_is_run_bit_for_bit() {
    let evaluator = problem();
    for elitist in [false, true] {
        let settings = HillClimbSettings {
            hidden: 2,
            candidates: 12,
            cycles: 30,
            elitist,
            ..HillClimbSettings::default()
        };
        let hill_climb = HillClimb::new(settings, 5).unwrap();
        let expected = hill_climb.run(&evaluator, |_| {}).unwrap();
        let (got, purposes) = by_hand(&mut hill_climb.start(2, 1).unwrap(), &evaluator, |_| false);
        assert_eq!(bits(&got), bits(&expected), "elitist {elitist}");
        assert_eq!(purposes[0] == AskPurpose::Base, elitist);
        assert_eq!(purposes.len(), 30 + usize::from(elitist));
    }
}

#[test]
fn stop_ends_the_run_where_the_callback_would() {
    let evaluator = problem();
    let esp = Esp::new(small(EspSettings::hoverstad()), 3).unwrap();
    // The last generation too: a stop there ends it as Stopped, not Completed.
    for stop_at in [1, 25, 80] {
        let expected = esp
            .run(&evaluator, |r| {
                if r.generation == stop_at {
                    Control::Stop
                } else {
                    Control::Continue
                }
            })
            .unwrap();
        let (got, _) = by_hand(&mut esp.start(2, 1).unwrap(), &evaluator, |r| r.generation == stop_at);
        assert_eq!(bits(&got), bits(&expected));
        assert_eq!((got.ending, got.records.len()), (Ending::Stopped, stop_at));
    }
    // The goal and the budget end it by themselves, and before a stop.
    let whole = esp.run(&evaluator, |_| {}).unwrap();
    let goal = whole.records[30].champion;
    let stop = StopAt {
        goal: Some(goal),
        evaluations: None,
    };
    let esp_goal = esp.clone().stop_at(stop);
    let expected = esp_goal.run(&evaluator, |_| Control::Stop).unwrap();
    let (got, _) = by_hand(&mut esp_goal.start(2, 1).unwrap(), &evaluator, |_| true);
    assert_eq!(bits(&got), bits(&expected));
    let (unstopped, _) = by_hand(&mut esp_goal.start(2, 1).unwrap(), &evaluator, |_| false);
    assert_eq!(unstopped.ending, Ending::Goal);
    let budget = esp.clone().stop_at(StopAt {
        goal: None,
        evaluations: Some(500),
    });
    let (got, _) = by_hand(&mut budget.start(2, 1).unwrap(), &evaluator, |_| false);
    assert_eq!(bits(&got), bits(&budget.run(&evaluator, |_| {}).unwrap()));
    assert_eq!(got.ending, Ending::Budget);
}

#[test]
fn a_wrong_tell_is_a_typed_error_that_leaves_the_run_as_it_was() {
    let evaluator = problem();
    let esp = Esp::new(small(EspSettings::hoverstad()), 9).unwrap();
    let expected = esp.run(&evaluator, |_| {}).unwrap();
    let mut run = esp.start(2, 1).unwrap();
    assert!(matches!(run.result(), Err(RunError::NotEnded)));
    let asked = run.ask().unwrap().expect("a new run asks");
    assert_eq!((asked.purpose(), asked.len()), (AskPurpose::Generation(1), 16));
    let (ticket, fitness) = (asked.ticket(), asked.evaluate(&evaluator).unwrap());
    let error = run.tell(ticket, &fitness[1..]).unwrap_err();
    assert!(
        matches!(error, RunError::FitnessCount { expected: 16, got: 15 }),
        "{error:?}"
    );
    assert_eq!(error.to_string(), "told 15 fitnesses for the 16 networks asked");
    let mut with_nan = fitness.clone();
    with_nan[4] = f64::NAN;
    assert!(matches!(
        run.tell(ticket, &with_nan).unwrap_err(),
        RunError::NanFitness { network: 4 }
    ));
    let mut with_infinity = fitness.clone();
    with_infinity[7] = f64::INFINITY;
    assert!(matches!(
        run.tell(ticket, &with_infinity).unwrap_err(),
        RunError::InfiniteFitness { network: 7, .. }
    ));
    // Another run's ticket, even of the same settings and ask, is refused.
    let mut twin = esp.start(2, 1).unwrap();
    let twin_ticket = twin.ask().unwrap().unwrap().ticket();
    assert!(matches!(
        run.tell(twin_ticket, &fitness).unwrap_err(),
        RunError::ForeignTicket
    ));
    // Asking again asks for the same networks, under the same ticket; the run goes on unharmed.
    let again = run.ask().unwrap().unwrap();
    assert_eq!(again.ticket(), ticket);
    assert_eq!(again.evaluate(&evaluator).unwrap(), fitness);
    assert_eq!(run.tell(ticket, &fitness).unwrap().unwrap().generation, 1);
    // The same ticket twice (or a tell with no ask since the last) is refused.
    let error = run.tell(ticket, &fitness).unwrap_err();
    assert!(
        matches!(error, RunError::TicketTold { ticket: 0, told: 1 }),
        "{error:?}"
    );
    let (got, _) = by_hand(&mut run, &evaluator, |_| false);
    assert_eq!(bits(&got), bits(&expected));
    assert!(matches!(run.tell(ticket, &fitness).unwrap_err(), RunError::Ended));
    assert_eq!(bits(&run.into_result().unwrap()), bits(&expected));
    // A run on networks without inputs cannot start.
    assert!(matches!(esp.start(0, 1), Err(RunError::Network(_))));
    let hill_climb = HillClimb::new(HillClimbSettings::default(), 1).unwrap();
    assert!(matches!(hill_climb.start(2, 0), Err(RunError::Network(_))));
}

#[test]
fn runs_run_together_are_each_their_own_run_bit_for_bit() {
    let (a, b) = (problem(), problem());
    let settings = HillClimbSettings {
        hidden: 2,
        candidates: 10,
        cycles: 50,
        elitist: true,
        ..HillClimbSettings::default()
    };
    // ESP of both forms, a hill-climber, a run stopped at a goal and one at a
    // callback, over two evaluators.
    let esps: Vec<Esp> = (0..4)
        .map(|seed| {
            let form = if seed % 2 == 0 {
                EspSettings::gomez()
            } else {
                EspSettings {
                    topology: TopologyMode::Lesion,
                    ..EspSettings::hoverstad()
                }
            };
            Esp::new(small(form), seed).unwrap()
        })
        .collect();
    let goal = esps[2].run(&a, |_| {}).unwrap().records[20].champion;
    let goal_esp = esps[2].clone().stop_at(StopAt {
        goal: Some(goal),
        evaluations: None,
    });
    let hill_climb = HillClimb::new(settings, 4).unwrap();
    let stop_at_12 = |r: &GenerationRecord| {
        if r.generation == 12 {
            Control::Stop
        } else {
            Control::Continue
        }
    };
    let expected = [
        esps[0].run(&a, |_| {}).unwrap(),
        esps[1].run(&b, |_| {}).unwrap(),
        goal_esp.run(&a, |_| {}).unwrap(),
        esps[3].run(&b, stop_at_12).unwrap(),
        hill_climb.run(&a, |_| {}).unwrap(),
    ];
    let mut runs: Vec<Box<dyn AskTell + Send>> = vec![
        Box::new(esps[0].start(2, 1).unwrap()),
        Box::new(esps[1].start(2, 1).unwrap()),
        Box::new(goal_esp.start(2, 1).unwrap()),
        Box::new(esps[3].start(2, 1).unwrap()),
        Box::new(hill_climb.start(2, 1).unwrap()),
    ];
    let evaluators = [&a, &b, &a, &b, &a];
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut fresh: Vec<Box<dyn AskTell + Send>> = Vec::new();
        std::mem::swap(&mut fresh, &mut runs);
        let errors = pool.install(|| {
            run_together(&mut fresh, &evaluators, |i, r| {
                if i == 3 {
                    stop_at_12(r)
                } else {
                    Control::Continue
                }
            })
        });
        assert!(errors.iter().all(Option::is_none), "{errors:?}");
        for (run, expected) in fresh.iter().zip(&expected) {
            assert_eq!(bits(&run.result().unwrap()), bits(expected), "{threads} threads");
        }
        runs = vec![
            Box::new(esps[0].start(2, 1).unwrap()),
            Box::new(esps[1].start(2, 1).unwrap()),
            Box::new(goal_esp.start(2, 1).unwrap()),
            Box::new(esps[3].start(2, 1).unwrap()),
            Box::new(hill_climb.start(2, 1).unwrap()),
        ];
    }
    assert_eq!(expected[2].ending, Ending::Goal);
    assert_eq!(expected[3].ending, Ending::Stopped);
}

#[test]
fn a_failing_run_among_runs_together_fails_alone() {
    // Network evaluations fail once the weights grow past 30; the
    // hill-climber with large noise gets there, ESP's runs never do.
    let evaluator = FnEvaluator::new(2, 1, |net: &Network, rng: &mut Stream| {
        let largest = net.genes().iter().fold(0.0f64, |m, g| m.max(g.abs()));
        if largest > 30.0 {
            anyhow::bail!("weight {largest} too large");
        }
        Ok(-largest + rng.random::<f64>())
    });
    let settings = HillClimbSettings {
        hidden: 2,
        candidates: 4,
        cycles: 400,
        alpha: 5.0,
        anneal_alpha: 1.0,
        cauchy_limit: 100.0,
        ..HillClimbSettings::default()
    };
    let wild = HillClimb::new(settings, 1).unwrap();
    let calm = Esp::new(
        EspSettings {
            init_range: 1.0,
            generations: 30,
            ..small(EspSettings::gomez())
        },
        2,
    )
    .unwrap();
    let alone = calm.run(&evaluator, |_| {}).unwrap();
    let mut runs: Vec<Box<dyn AskTell + Send>> =
        vec![Box::new(wild.start(2, 1).unwrap()), Box::new(calm.start(2, 1).unwrap())];
    let errors = run_together(&mut runs, &[&evaluator, &evaluator], |_, _| Control::Continue);
    let message = format!("{:#}", errors[0].as_ref().expect("the wild run fails"));
    assert!(message.contains("too large"), "{message}");
    assert!(errors[1].is_none());
    assert_eq!(bits(&runs[1].result().unwrap()), bits(&alone));
}

#[test]
fn jobs_evaluated_together_get_what_each_gets_alone() {
    let evaluator = problem();
    let networks: Vec<Network> = (0..23)
        .map(|j| Network::from_genes(2, 1, vec![j as f64 / 10.0, 0.5, -0.25]).unwrap())
        .collect();
    let families = [(1, vec![3, 4]), (2, vec![]), (1, vec![3, 5])];
    let jobs: Vec<Job<'_, _, [Network]>> = families
        .iter()
        .enumerate()
        .map(|(i, (seed, key))| Job {
            evaluator: &evaluator,
            networks: &networks[i..],
            streams: esp_neuroevolution::rng::StreamFamily::new(*seed, key),
        })
        .collect();
    let together = evaluate_jobs(&jobs);
    for (i, (seed, key)) in families.iter().enumerate() {
        let alone = evaluate_all(&evaluator, &networks[i..], *seed, key).unwrap();
        assert_eq!(together[i].as_ref().unwrap(), &alone);
    }
}

/// `inner` as an evaluator that takes a round's parts together (as a GPU
/// does), noting how many parts each call gets.
struct Together<E> {
    inner: E,
    calls: std::sync::Mutex<Vec<usize>>,
}

impl<E: Evaluator> Evaluator for Together<E> {
    type Worker = E::Worker;
    fn inputs(&self) -> usize {
        self.inner.inputs()
    }
    fn outputs(&self) -> usize {
        self.inner.outputs()
    }
    fn worker(&self) -> anyhow::Result<E::Worker> {
        self.inner.worker()
    }
    fn evaluate(&self, worker: &mut E::Worker, network: &Network, rng: &mut Stream) -> anyhow::Result<f64> {
        self.inner.evaluate(worker, network, rng)
    }
    fn takes_parts_together(&self) -> bool {
        true
    }
    fn evaluate_parts<S: NetworkSet + ?Sized>(
        &self,
        worker: &mut E::Worker,
        parts: &[Part<'_, S>],
    ) -> Vec<anyhow::Result<Vec<f64>>> {
        self.calls.lock().unwrap().push(parts.len());
        evaluate_each_part(&self.inner, worker, parts)
    }
}

#[test]
fn an_evaluator_that_takes_parts_together_gets_every_run_of_a_round_in_one_call() {
    let together = Together {
        inner: problem(),
        calls: std::sync::Mutex::new(Vec::new()),
    };
    let esps: Vec<Esp> = (0..4)
        .map(|seed| Esp::new(small(EspSettings::hoverstad()), seed).unwrap())
        .collect();
    let expected: Vec<RunResult> = esps.iter().map(|e| e.run(&problem(), |_| {}).unwrap()).collect();
    let mut runs: Vec<Box<dyn AskTell + Send>> = esps
        .iter()
        .map(|e| Box::new(e.start(2, 1).unwrap()) as Box<dyn AskTell + Send>)
        .collect();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let errors = pool.install(|| run_together(&mut runs, &[&together; 4], |_, _| Control::Continue));
    assert!(errors.iter().all(Option::is_none), "{errors:?}");
    for (run, expected) in runs.iter().zip(&expected) {
        assert_eq!(bits(&run.result().unwrap()), bits(expected));
    }
    let calls = together.calls.into_inner().unwrap();
    // A call a round, each with every run still going: all 4 at first.
    assert_eq!(calls[0], 4, "{calls:?}");
    assert!(calls.iter().all(|&parts| (1..=4).contains(&parts)), "{calls:?}");
    let rounds = expected.iter().map(|r| r.records.len()).max().unwrap();
    assert!(
        calls.len() >= rounds && calls.len() < calls.iter().sum::<usize>(),
        "{calls:?}"
    );
}
