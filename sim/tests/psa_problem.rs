//! The PSA control problem: fitness, tasks, sensors and noise, trials.

use std::f64::consts::{FRAC_PI_2, PI};
use strum::VariantArray;

use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::stream;
use psa_sim::numeric::NoiseSource;
use psa_sim::physics::{BackendKind, BodyState};
use psa_sim::psa::fitness::StepError;
use psa_sim::psa::{
    FitnessKind, FitnessSettings, NoiseSettings, PsaSettings, SensorSettings, Target, Task, TaskSettings, TrialRecord,
    TrialRunner,
};
use rand::RngExt;

/// A 7-1-4 network whose every output is exactly `u` (0 or 1): the hidden
/// unit sits near 1 and the output weights saturate the sigmoid.
fn constant_network(u: f64) -> Network {
    let w_out = if u > 0.5 { 1000.0 } else { -1000.0 };
    let mut genes = vec![0.0; 6];
    genes.push(6.0); // bias weight
    genes.extend([w_out; 4]);
    Network::from_genes(7, 4, genes).unwrap()
}

fn random_network(seed: u64, hidden: usize) -> Network {
    let mut rng = stream(seed, &[]);
    Network::from_genes(7, 4, (0..hidden * 11).map(|_| rng.random_range(-6.0..6.0)).collect()).unwrap()
}

fn fitness(settings: &PsaSettings, task: Task, network: &Network, seed: u64) -> f64 {
    TrialRunner::new(settings, task)
        .unwrap()
        .evaluate(network, &mut stream(seed, &[]))
        .unwrap()
}

fn step(x: f64, y: f64, heading: f64, omega: f64, previous_omega: f64) -> StepError {
    StepError {
        x,
        y,
        heading,
        omega,
        previous_omega,
    }
}

#[test]
fn incremental_fitness_scores_box_spin_and_heading_as_specified() {
    let f = FitnessSettings::default();
    assert_eq!(f.kind, FitnessKind::Incremental);
    // In the box, still, on heading: 1 + 3.
    assert_eq!(f.points(&step(0.0, 0.0, 0.0, 0.0, 0.0)), 4.0);
    // The box is open: |x| < 0.2 and |y| < 0.2, strictly.
    assert_eq!(f.points(&step(0.1999, -0.1999, 0.0, 0.0, 0.0)), 4.0);
    assert_eq!(f.points(&step(0.2, 0.0, 0.0, 0.0, 0.0)), 0.0);
    assert_eq!(f.points(&step(0.0, -0.2001, 0.0, 0.0, 0.0)), 0.0);
    // Off heading: the +3 is lost, the 1 stays.
    assert_eq!(f.points(&step(0.0, 0.0, 0.05, 0.0, 0.0)), 1.0);
    assert_eq!(f.points(&step(0.0, 0.0, -0.0499, 0.0, 0.0)), 4.0);
    // Spinning fast and not slowing: nothing, even on heading.
    assert_eq!(f.points(&step(0.0, 0.0, 0.0, 0.5, 0.5)), 0.0);
    assert_eq!(f.points(&step(0.0, 0.0, 0.0, -0.5, 0.4)), 0.0);
    // Spinning fast but slowing down (in magnitude, either sign): scores.
    assert_eq!(f.points(&step(0.0, 0.0, 0.0, 0.5, 0.6)), 4.0);
    assert_eq!(f.points(&step(0.0, 0.0, 1.0, -0.5, 0.6)), 1.0);
    // Under the spin window: scores whatever the trend.
    assert_eq!(f.points(&step(0.0, 0.0, 0.0, 0.049, 0.0)), 4.0);
    // The +3 needs the 1: on heading out of the box scores nothing.
    assert_eq!(f.points(&step(0.5, 0.0, 0.0, 0.0, 0.0)), 0.0);
    assert_eq!(f.maximum(500), 2000.0);
}

#[test]
fn original_fitness_needs_box_and_heading_only() {
    let f = FitnessSettings {
        kind: FitnessKind::Original,
        ..FitnessSettings::default()
    };
    assert_eq!(f.points(&step(0.1, 0.1, 0.01, 0.0, 0.0)), 1.0);
    assert_eq!(f.points(&step(0.1, 0.1, 0.01, 3.0, 1.0)), 1.0, "spin does not matter");
    assert_eq!(f.points(&step(0.1, 0.1, 0.06, 0.0, 0.0)), 0.0);
    assert_eq!(f.points(&step(0.3, 0.1, 0.0, 0.0, 0.0)), 0.0);
    assert_eq!(f.maximum(500), 500.0);
}

#[test]
fn a_hand_built_trajectory_scores_step_by_step() {
    // Through a trial: record the points and re-score them by hand.
    let settings = PsaSettings {
        backend: BackendKind::Native,
        ..PsaSettings::default()
    };
    let mut runner = TrialRunner::new(&settings, Task::StopAtPosition).unwrap();
    let mut record = TrialRecord::default();
    let total = runner
        .run_trial(&constant_network(0.0), &mut stream(1, &[]), Some(&mut record))
        .unwrap();
    assert_eq!(record.states.len(), 501);
    // Coasting at 0.4 m/s along +y on the target heading: in the box
    // (|y - 0.4| < 0.2) for steps 11..=29 in exact arithmetic (steps 10 and
    // 30 sit on its edges, y = 0.2 and 0.6, and rounding decides them), 4
    // points each.
    for (n, p) in record.points.iter().enumerate() {
        let y = record.states[n + 1].y;
        let expected = if (y - 0.4).abs() < 0.2 { 4.0 } else { 0.0 };
        assert_eq!(*p, expected, "step {}", n + 1);
    }
    assert_eq!(total, record.points.iter().sum::<f64>());
    assert!([76.0, 80.0, 84.0].contains(&total), "{total}");
}

#[test]
fn doing_nothing_scores_0_0_and_the_coasting_points_of_task_3() {
    for backend in [BackendKind::Ode, BackendKind::Native] {
        let settings = PsaSettings {
            backend,
            ..PsaSettings::default()
        };
        let idle = constant_network(0.0);
        assert_eq!(
            fitness(&settings, Task::StopRotation, &idle, 1),
            0.0,
            "{backend}: it spins forever"
        );
        assert_eq!(
            fitness(&settings, Task::Turn, &idle, 1),
            0.0,
            "{backend}: it spins past the target heading forever"
        );
        // Coasting at 0.4 m/s on heading 0 through the box (0.2 m to 0.6 m):
        // 4 points for each of the 19 to 21 steps inside it, of 2000.
        let t3 = fitness(&settings, Task::StopAtPosition, &idle, 1);
        assert!((3.8..=4.2).contains(&t3), "{backend}: coasting through the box: {t3}");
    }
}

#[test]
fn firing_every_thruster_fully_scores_under_2_percent() {
    let full = constant_network(1.0);
    for &task in Task::VARIANTS {
        // Task 3: it shoots through the box on the target heading (4 points a step).
        let f = fitness(&PsaSettings::default(), task, &full, 1);
        assert!(f < 2.0, "task {task}: {f}");
    }
}

#[test]
fn ode_and_native_give_the_same_fitness_with_and_without_noise() {
    let noisy = NoiseSettings {
        input_sd: 0.05,
        output_sd: 0.05,
        ..NoiseSettings::default()
    };
    for noise in [NoiseSettings::default(), noisy] {
        for &task in Task::VARIANTS {
            for k in 0..8 {
                let net = random_network(100 + k, 5);
                let mut s = PsaSettings {
                    noise,
                    trials: 2,
                    ..PsaSettings::default()
                };
                s.random_init = task.has_random_init() && noise.input_sd > 0.0;
                let ode = fitness(&s, task, &net, k);
                let native = fitness(
                    &PsaSettings {
                        backend: BackendKind::Native,
                        ..s.clone()
                    },
                    task,
                    &net,
                    k,
                );
                assert_eq!(ode, native, "task {task}, network {k}, noise {noise:?}");
                // The same inputs give the same fitness.
                assert_eq!(ode, fitness(&s, task, &net, k));
            }
        }
    }
}

#[test]
fn random_networks_earn_varied_fitness() {
    // The problem discriminates: not every network scores the same.
    let scores: Vec<f64> = (0..20)
        .map(|k| fitness(&PsaSettings::default(), Task::Turn, &random_network(k, 5), 0))
        .collect();
    let distinct = scores
        .iter()
        .map(|s| s.to_bits())
        .collect::<std::collections::HashSet<_>>()
        .len();
    assert!(distinct >= 5, "{scores:?}");
}

#[test]
fn injected_noise_has_the_configured_mean_and_sd() {
    let noise = NoiseSettings {
        input_sd: 0.05,
        output_sd: 0.2,
        ..NoiseSettings::default()
    };
    let mut source = NoiseSource::new(9);
    let n = 40_000;
    let mut samples = Vec::with_capacity(n * 7);
    for _ in 0..n {
        let mut inputs = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        noise.perturb_inputs(&mut inputs, &mut source);
        // The bias (1) gets its noise too: on "each input neuron".
        assert_ne!(inputs[6], 1.0, "the bias gets noise by default");
        samples.extend_from_slice(&inputs[..6]);
        samples.push(inputs[6] - 1.0);
    }
    let mean = samples.iter().sum::<f64>() / samples.len() as f64;
    let sd = (samples.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (samples.len() - 1) as f64).sqrt();
    // Standard errors: mean 0.05 / sqrt(280000) = 1e-4; sd about 7e-5.
    assert!(mean.abs() < 5e-4, "mean {mean}");
    assert!((sd - 0.05).abs() < 5e-4, "sd {sd}");
    // Outputs: noise only (the trial clamps afterwards), half of it below 0 at 0.
    let mut outs = Vec::with_capacity(n);
    let mut below_zero = 0;
    for _ in 0..n {
        let mut u = [0.5, 0.0, 1.0, 0.5];
        noise.perturb_outputs(&mut u, &mut source);
        below_zero += usize::from(u[1] < 0.0);
        outs.push(u[0]);
    }
    let mean = outs.iter().sum::<f64>() / n as f64;
    let sd = (outs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    assert!((mean - 0.5).abs() < 5e-3, "output mean {mean}");
    assert!((sd - 0.2).abs() < 5e-3, "output sd {sd}");
    assert!(
        (below_zero as f64 / n as f64 - 0.5).abs() < 0.02,
        "{below_zero} below 0"
    );
    // No noise configured: no change, and no seed drawn from the stream.
    let mut u = [0.3; 4];
    NoiseSettings::default().perturb_outputs(&mut u, &mut source);
    assert_eq!(u, [0.3; 4]);
    let (mut drawn, mut untouched) = (stream(9, &[]), stream(9, &[]));
    assert_eq!(NoiseSettings::default().draw_seed(&mut drawn), 0);
    assert_eq!(drawn.random::<u64>(), untouched.random::<u64>());
    assert_eq!(
        noise.draw_seed(&mut drawn),
        untouched.random::<u64>(),
        "one word when noisy"
    );
}

#[test]
fn thrust_under_output_noise_is_clamped_to_the_unit_interval() {
    // A network at full thrust, noise of sd 0.5: about half the commands
    // would exceed 1 and some fall below 0; the trial clamps them all.
    let settings = PsaSettings {
        backend: BackendKind::Native,
        noise: NoiseSettings {
            input_sd: 0.0,
            output_sd: 0.5,
            ..NoiseSettings::default()
        },
        ..PsaSettings::default()
    };
    let mut runner = TrialRunner::new(&settings, Task::StopAtPosition).unwrap();
    let mut record = TrialRecord::default();
    runner
        .run_trial(&constant_network(1.0), &mut stream(4, &[]), Some(&mut record))
        .unwrap();
    let commands: Vec<f64> = record.outputs.iter().flatten().copied().collect();
    assert!(commands.iter().all(|u| (0.0..=1.0).contains(u)));
    let at_one = commands.iter().filter(|&&u| u == 1.0).count();
    assert!(
        at_one > commands.len() / 3,
        "{at_one} of {} clamped to 1",
        commands.len()
    );
    assert!(commands.iter().any(|&u| u > 0.0 && u < 1.0));
}

#[test]
fn start_states_and_targets_are_as_specified() {
    let t = TaskSettings::default();
    let mut rng = stream(3, &[]);
    let (s1, g1) = t.start_and_target(Task::StopRotation, false, &mut rng);
    assert_eq!(
        (s1, g1),
        (
            BodyState {
                omega: 1.0,
                ..BodyState::default()
            },
            Target::default()
        )
    );
    let (s2, g2) = t.start_and_target(Task::Turn, false, &mut rng);
    assert_eq!(
        (s2, g2),
        (
            BodyState {
                // Clockwise, away from the target heading.
                omega: -0.75,
                ..BodyState::default()
            },
            Target {
                heading: FRAC_PI_2,
                ..Target::default()
            }
        )
    );
    let (s3, g3) = t.start_and_target(Task::StopAtPosition, false, &mut rng);
    assert_eq!(
        s3,
        BodyState {
            vy: 0.4,
            ..BodyState::default()
        }
    );
    assert_eq!(
        g3,
        Target {
            x: 0.0,
            y: 0.40,
            heading: 0.0
        }
    );
    // Random initialisation: task 1 heading uniform in (-pi, pi], task 3 distance uniform in [0.25, 0.55].
    let headings: Vec<f64> = (0..20_000)
        .map(|_| t.start_and_target(Task::StopRotation, true, &mut rng).0.heading)
        .collect();
    assert!(headings.iter().all(|h| *h > -PI && *h <= PI));
    let mean = headings.iter().sum::<f64>() / headings.len() as f64;
    assert!(mean.abs() < 0.05, "mean {mean}");
    assert!(headings.iter().any(|h| *h < -3.0) && headings.iter().any(|h| *h > 3.0));
    let distances: Vec<f64> = (0..20_000)
        .map(|_| t.start_and_target(Task::StopAtPosition, true, &mut rng).1.y)
        .collect();
    assert!(distances.iter().all(|d| (0.25..=0.55).contains(d)));
    let mean = distances.iter().sum::<f64>() / distances.len() as f64;
    assert!((mean - 0.40).abs() < 0.005, "mean {mean}");
    assert!(distances.iter().any(|d| *d < 0.26) && distances.iter().any(|d| *d > 0.54));
}

#[test]
fn random_init_is_refused_for_task_2_and_bad_settings_name_themselves() {
    let s = PsaSettings {
        random_init: true,
        ..PsaSettings::default()
    };
    let err = TrialRunner::new(&s, Task::Turn).err().unwrap().to_string();
    assert!(err.contains("task 2"), "{err}");
    let s = PsaSettings {
        noise: NoiseSettings {
            input_sd: -0.1,
            output_sd: 0.0,
            ..NoiseSettings::default()
        },
        ..PsaSettings::default()
    };
    let err = TrialRunner::new(&s, Task::Turn).err().unwrap().to_string();
    assert!(err.contains("noise.input_sd") && err.contains("-0.1"), "{err}");
    let s = PsaSettings {
        sensors: SensorSettings {
            bias: f64::NAN,
            ..SensorSettings::default()
        },
        ..PsaSettings::default()
    };
    assert!(TrialRunner::new(&s, Task::Turn)
        .err()
        .unwrap()
        .to_string()
        .contains("sensors.bias"));
    let wrong = Network::from_genes(3, 4, vec![0.0; 7]).unwrap();
    let mut runner = TrialRunner::new(&PsaSettings::default(), Task::Turn).unwrap();
    let err = runner.evaluate(&wrong, &mut stream(0, &[])).unwrap_err().to_string();
    assert!(err.contains("3 inputs"), "{err}");
}

#[test]
fn inputs_are_relative_to_the_target_scaled_and_wrapped() {
    let mut s = SensorSettings::default();
    let state = BodyState {
        x: 0.1,
        y: 0.5,
        heading: -3.0,
        vx: -0.2,
        vy: 0.05,
        omega: 0.7,
    };
    let target = Target {
        x: 0.0,
        y: 0.4,
        heading: PI,
    };
    let i = s.inputs(&state, &target);
    // The defaults: 10 per m, 10 per m/s, 1 per rad and per rad/s.
    assert!((i[0] - 1.0).abs() < 1e-12 && (i[1] - 1.0).abs() < 1e-12);
    assert!((i[2] + 2.0).abs() < 1e-12 && (i[3] - 0.5).abs() < 1e-12);
    // The heading itself: -3 lies in (-pi, pi].
    assert_eq!(i[4], -3.0);
    assert_eq!((i[5], i[6]), (0.7, 1.0));
    // The heading error: -3 - pi wraps to 2 pi - 3 - pi = pi - 3.
    s.heading_input = psa_sim::psa::HeadingInput::Error;
    let i = s.inputs(&state, &target);
    assert!((i[4] - (PI - 3.0)).abs() < 1e-12, "{}", i[4]);
}

mod per_task {
    use psa_sim::psa::{FitnessKind, Scoring, Task, TaskOverrides, TrialRunner};

    #[test]
    fn a_task_flies_its_own_steps_and_fitness_and_is_scored_with_its_scoring() {
        let mut s = psa_sim::psa::PsaSettings {
            task3: TaskOverrides {
                steps: Some(2000),
                fitness: Some(FitnessKind::Original),
                scoring: None,
            },
            ..psa_sim::psa::PsaSettings::default()
        };
        s.fitness.scoring = Scoring::Original;
        let task3 = s.for_task(Task::StopAtPosition).unwrap();
        assert_eq!((task3.steps, task3.fitness.kind), (2000, FitnessKind::Original));
        assert!(task3.task3.is_empty());
        assert_eq!(
            TrialRunner::new(&s, Task::StopAtPosition).unwrap().maximum_points(),
            2000.0
        );
        assert_eq!(TrialRunner::new(&s, Task::Turn).unwrap().maximum_points(), 2000.0);
        let task1 = s.for_task(Task::StopRotation).unwrap();
        assert_eq!((task1.steps, task1.fitness.kind), (500, FitnessKind::Incremental));
        // Scored on the original fitness: task 1 apart, task 3 already evolved on it.
        assert!(s.rescored(Task::StopRotation) && !s.rescored(Task::StopAtPosition));
        assert_eq!(
            s.scoring_for(Task::StopRotation).unwrap().fitness.kind,
            FitnessKind::Original
        );
        s.task1.scoring = Some(Scoring::Evolution);
        assert!(!s.rescored(Task::StopRotation));
        assert_eq!(
            s.scoring_for(Task::StopRotation).unwrap().fitness.kind,
            FitnessKind::Incremental
        );
        s.task2.steps = Some(0);
        let error = s.validate().unwrap_err().to_string();
        assert!(error.contains("task2.steps = 0"), "{error}");
    }
}

#[test]
fn each_task_setting_is_read_by_exactly_one_task_and_every_other_setting_by_all() {
    // Every field of TaskSettings, as a run's config.toml names it: a field
    // added without its task's `taskN_` prefix fails here.
    let fields = serde_json::to_value(TaskSettings::default()).unwrap();
    let fields = fields.as_object().unwrap();
    assert!(fields.len() >= 8, "{fields:?}");
    for name in fields.keys() {
        let setting = format!("problem.tasks.{name}");
        let readers: Vec<Task> = Task::VARIANTS
            .iter()
            .copied()
            .filter(|t| t.reads_setting(&setting))
            .collect();
        assert_eq!(readers.len(), 1, "{setting} is read by {readers:?}");
        assert!(name.starts_with(&format!("task{}_", readers[0].number())), "{setting}");
    }
    assert!(!Task::StopRotation.reads_setting("problem.tasks.task2_spin"));
    assert!(Task::Turn.reads_setting("problem.tasks.task2_spin"));
    // A `[problem.taskN]` table is task N's alone, as is each key in it.
    for setting in ["problem.task2", "problem.task2.steps", "problem.task2.scoring"] {
        let readers: Vec<Task> = Task::VARIANTS
            .iter()
            .copied()
            .filter(|t| t.reads_setting(setting))
            .collect();
        assert_eq!(readers, [Task::Turn], "{setting}");
    }
    assert!(Task::VARIANTS.iter().copied().all(|t| t.reads_setting("problem.tasks")));
    for setting in ["problem.sensors.heading_wrap", "esp.stagnation", "problem.body.density"] {
        assert!(
            Task::VARIANTS.iter().copied().all(|t| t.reads_setting(setting)),
            "{setting}"
        );
    }
}
