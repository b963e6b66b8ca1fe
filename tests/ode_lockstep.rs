//! The ODE lockstep path (many bodies in one ODE world, one `dWorldStep`
//! for all) against one world per body: the same states and the same
//! fitness, bit for bit, on every task, with noise, random starts, several
//! trials, both steppers, the Plane2D joint and the gyroscopic term.

mod kernel_cases;

use esp_neuroevolution::network::Network;
use kernel_cases::{random_network, streams};
use psa_sim::physics::{
    random_thrust_sequence, BodyState, OdeBackend, OdeFleet, PhysicsBackend, PlanarState, PlaneConstraint,
    StepSettings, Stepper,
};
use psa_sim::psa::ode_lockstep::ODE_LOCKSTEP;
use psa_sim::psa::{BodySettings, NoiseSettings, OdeLockstepRunner, PsaSettings, Task, TrialRunner};
use strum::VariantArray;

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| v.to_bits()).collect()
}

fn state_bits(s: &PlanarState<f64>) -> Vec<u64> {
    bits(&[
        s.position[0],
        s.position[1],
        s.velocity[0],
        s.velocity[1],
        s.quaternion[0],
        s.quaternion[1],
        s.omega,
    ])
}

/// The fitness of networks `seeds` with one ODE world per network, and in
/// lockstep in batches of `batch` networks (the last one shorter).
fn both_paths(settings: &PsaSettings, task: Task, seeds: std::ops::Range<u64>, batch: usize) -> (Vec<f64>, Vec<f64>) {
    let networks: Vec<Network> = seeds.clone().map(random_network).collect();
    let mut runner = TrialRunner::new(settings, task).unwrap();
    let scalar = networks
        .iter()
        .zip(streams(seeds.clone()))
        .map(|(n, mut rng)| runner.evaluate(n, &mut rng).unwrap())
        .collect();
    let mut lockstep = OdeLockstepRunner::new(settings, task).unwrap();
    let mut rngs = streams(seeds);
    let mut fitness = Vec::new();
    for start in (0..networks.len()).step_by(batch) {
        let end = (start + batch).min(networks.len());
        fitness.extend(
            lockstep
                .evaluate(&networks[..], start..end, &mut rngs[start..end])
                .unwrap(),
        );
    }
    (scalar, fitness)
}

fn assert_same(settings: &PsaSettings, task: Task, seeds: std::ops::Range<u64>, batch: usize, what: &str) {
    let (scalar, lockstep) = both_paths(settings, task, seeds, batch);
    assert_eq!(
        bits(&scalar),
        bits(&lockstep),
        "{what}: scalar {scalar:?}\nlockstep {lockstep:?}"
    );
    let distinct: std::collections::HashSet<u64> = bits(&scalar).into_iter().collect();
    assert!(
        distinct.len() >= scalar.len() / 8,
        "{what}: the sample is degenerate: {} distinct of {}",
        distinct.len(),
        scalar.len()
    );
}

#[test]
fn lockstep_fitness_equals_one_world_per_network_on_every_task() {
    let settings = PsaSettings::default();
    for &task in Task::VARIANTS {
        assert_same(&settings, task, 0..100, ODE_LOCKSTEP, &format!("task {task}"));
    }
}

#[test]
fn lockstep_fitness_equals_one_world_per_network_with_noise_random_starts_and_trials() {
    let noisy = PsaSettings {
        trials: 3,
        random_init: true,
        noise: NoiseSettings {
            input_sd: 0.05,
            output_sd: 0.1,
            ..NoiseSettings::default()
        },
        steps: 200,
        ..PsaSettings::default()
    };
    for task in [Task::StopRotation, Task::StopAtPosition] {
        // Batches of 7 leave a shorter last one (the fleet shrinks).
        assert_same(&noisy, task, 500..540, 7, &format!("noisy task {task}"));
    }
    let noise_only = PsaSettings {
        random_init: false,
        ..noisy
    };
    assert_same(&noise_only, Task::Turn, 600..640, 32, "noisy task 2");
}

#[test]
fn lockstep_fitness_equals_one_world_per_network_under_every_reading_of_the_inputs_and_fitness() {
    for (what, settings) in kernel_cases::reading_settings() {
        for &task in Task::VARIANTS {
            let settings = PsaSettings {
                backend: psa_sim::physics::BackendKind::Ode,
                random_init: settings.random_init && task.has_random_init(),
                steps: 200,
                ..settings.clone()
            };
            assert_same(&settings, task, 700..730, 8, &format!("{what}, task {task}"));
        }
    }
}

#[test]
fn lockstep_fitness_equals_one_world_per_network_on_every_supported_step_setting() {
    for (stepper, plane_constraint, ode_gyroscopic) in [
        (Stepper::Quick, PlaneConstraint::None, false),
        (Stepper::Exact, PlaneConstraint::Plane2dJoint, false),
        (Stepper::Exact, PlaneConstraint::None, true),
    ] {
        let settings = PsaSettings {
            physics: StepSettings {
                stepper,
                plane_constraint,
                ode_gyroscopic,
                ..StepSettings::default()
            },
            steps: 200,
            random_init: true,
            ..PsaSettings::default()
        };
        let what = format!("{stepper:?}, {plane_constraint:?}, gyroscopic {ode_gyroscopic}");
        assert_same(&settings, Task::StopAtPosition, 700..740, 16, &what);
    }
}

/// A start state of body `i`: spread over position, heading and speeds.
fn start(i: usize) -> BodyState {
    let f = i as f64;
    BodyState {
        x: 0.3 * f - 1.0,
        y: 0.7 - 0.2 * f,
        heading: 0.4 * f - 2.0,
        vx: 0.01 * f,
        vy: -0.02 * f,
        omega: 0.5 - 0.1 * f,
    }
}

#[test]
fn every_body_of_a_fleet_moves_as_a_body_alone_in_its_world() {
    let model = BodySettings::default().model().unwrap();
    for stepper in [Stepper::Exact, Stepper::Quick] {
        let settings = StepSettings {
            stepper,
            ..StepSettings::default()
        };
        let bodies = 9;
        let thrust: Vec<Vec<Vec<f64>>> = (0..bodies)
            .map(|i| random_thrust_sequence(i as u64, 1, 400, model.thrusters.len()))
            .collect();
        let mut fleet = OdeFleet::new(&model, &settings, 3).unwrap();
        // Grown and shrunk before use: bodies come and go in the world.
        fleet.resize(20).unwrap();
        fleet.resize(bodies).unwrap();
        assert_eq!(fleet.len(), bodies);
        for i in 0..bodies {
            fleet.reset(i, &start(i)).unwrap();
        }
        let mut alone: Vec<OdeBackend> = (0..bodies)
            .map(|i| {
                let mut backend = OdeBackend::new(&model, &settings).unwrap();
                backend.reset(&start(i)).unwrap();
                backend
            })
            .collect();
        assert_eq!(fleet.mass_properties(), alone[0].mass_properties());
        for step in 0..400 {
            let commands: Vec<&Vec<f64>> = thrust.iter().map(|t| &t[step]).collect();
            fleet.step(&commands).unwrap();
            for (i, backend) in alone.iter_mut().enumerate() {
                backend.step(commands[i]).unwrap();
                assert_eq!(
                    state_bits(&fleet.planar_state(i)),
                    state_bits(&backend.planar_state()),
                    "{stepper:?}, body {i}, step {step}"
                );
            }
        }
        // The bodies went different ways.
        assert_ne!(fleet.planar_state(0), fleet.planar_state(1));
    }
}

#[test]
fn a_fleet_checks_every_command_and_state_before_calling_ode() {
    let model = BodySettings::default().model().unwrap();
    let mut fleet = OdeFleet::new(&model, &StepSettings::default(), 3).unwrap();
    for i in 0..3 {
        fleet.reset(i, &start(i)).unwrap();
    }
    let before: Vec<_> = (0..3).map(|i| fleet.planar_state(i)).collect();
    let good = vec![0.5; 4];
    for (bad, expected) in [
        (vec![0.5, f64::NAN, 0.5, 0.5], "body 2: thruster 1"),
        (vec![0.5, 1.5, 0.5, 0.5], "body 2: thruster 1"),
        (vec![0.5; 3], "body 2: expected 4 values"),
    ] {
        let err = fleet.step(&[&good, &good, &bad]).unwrap_err().to_string();
        assert!(err.contains(expected), "{err}");
    }
    let err = fleet.step(&[&good, &good]).unwrap_err().to_string();
    assert!(err.contains("one per body"), "{err}");
    // Refused steps changed nothing.
    assert_eq!((0..3).map(|i| fleet.planar_state(i)).collect::<Vec<_>>(), before);
    // A state beyond what the engines integrate is refused at reset.
    let wild = BodyState {
        omega: 1e300,
        ..BodyState::default()
    };
    assert!(fleet.reset(1, &wild).is_err());
    let nan = BodyState {
        x: f64::NAN,
        ..BodyState::default()
    };
    assert!(fleet.reset(0, &nan).is_err());
    assert!(OdeFleet::new(&model, &StepSettings::default(), 0).is_err());
    let quick_joint = StepSettings {
        stepper: Stepper::Quick,
        plane_constraint: PlaneConstraint::Plane2dJoint,
        ..StepSettings::default()
    };
    assert!(!OdeFleet::supports(&quick_joint));
    assert!(OdeFleet::new(&model, &quick_joint, 2).is_err());
}

#[test]
fn an_esp_run_on_ode_is_the_same_in_lockstep_and_one_world_per_network_on_any_thread_count() {
    use esp_neuroevolution::{Esp, EspSettings};
    use psa_sim::evaluator::{EvalPath, PsaEvaluator};
    let settings = PsaSettings {
        steps: 150,
        ..PsaSettings::default()
    };
    let esp = Esp::new(
        EspSettings {
            subpop_size: 8,
            generations: 6,
            stagnation: 2,
            ..psa_experiment::paper_esp_settings()
        },
        11,
    )
    .unwrap();
    let run = |lockstep: bool, threads: usize| {
        let path = if lockstep {
            EvalPath::OdeLockstep
        } else {
            EvalPath::Scalar
        };
        let evaluator = PsaEvaluator::new(settings.clone(), Task::StopAtPosition, &path).unwrap();
        let pool = psa_sim::ode::thread_pool(threads).unwrap();
        let result = pool.install(|| esp.run(&evaluator, |_| {})).unwrap();
        (
            result.records,
            result.champion.network,
            result.champion.fitness.to_bits(),
        )
    };
    let reference = run(false, 1);
    for (lockstep, threads) in [(true, 1), (true, 2)] {
        assert_eq!(
            run(lockstep, threads),
            reference,
            "lockstep {lockstep} on {threads} threads"
        );
    }
}
