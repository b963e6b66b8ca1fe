//! Random networks, settings and the scalar reference shared by the
//! batched path's tests and the `cuda` kernel's (on the host and on a GPU).
#![allow(dead_code)] // each test file uses its own share

use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::{stream, Stream};
use psa_sim::numeric::Exponential;
use psa_sim::physics::BackendKind;
use psa_sim::psa::cuda::{evaluate_with, TrialBatch, TrialPoints};
use psa_sim::psa::settings::readings::every_test_value;
use psa_sim::psa::{FitnessKind, NoiseSettings, PsaError, PsaSettings, Task, TrialRunner};
use rand::RngExt;
use strum::VariantArray;

/// A random 7-H-4 network: H in 1..=9, weights uniform in a range of scale
/// 0.3 to 30 (from nearly linear to fully saturated units), and now and
/// then a lesioned neuron.
pub fn random_network(seed: u64) -> Network {
    let mut rng = stream(seed, &[1]);
    let hidden = rng.random_range(1..=9);
    let scale = [0.3, 1.0, 3.0, 6.0, 30.0][rng.random_range(0..5)];
    let genes = (0..hidden * 11).map(|_| rng.random_range(-scale..scale)).collect();
    let mut network = Network::from_genes(7, 4, genes).unwrap();
    if hidden > 1 && rng.random_bool(0.2) {
        network.set_lesioned(rng.random_range(0..hidden), true);
    }
    network
}

/// `settings` on the `native` backend.
pub fn native(settings: PsaSettings) -> PsaSettings {
    PsaSettings {
        backend: BackendKind::Native,
        ..settings
    }
}

/// Noise on inputs and outputs, random starts and 3 trials an evaluation.
pub fn noisy_settings() -> PsaSettings {
    native(PsaSettings {
        trials: 3,
        random_init: true,
        noise: NoiseSettings {
            input_sd: 0.05,
            output_sd: 0.1,
            ..NoiseSettings::default()
        },
        ..PsaSettings::default()
    })
}

/// The paper's original fitness function, on 300 steps.
pub fn original_fitness_settings() -> PsaSettings {
    let mut original = native(PsaSettings::default());
    original.fitness.kind = FitnessKind::Original;
    original.steps = 300;
    original
}

/// Every reading of the inputs and the fitness at a value other than its
/// default, together: the test value of each row of
/// [`READINGS`](psa_sim::psa::settings::readings::READINGS), whatever rows
/// the table holds (a new row joins without a line here); first with noise
/// on the inputs, the outputs and random starts, then clean.
pub fn reading_settings() -> [(&'static str, PsaSettings); 2] {
    let readings = every_test_value(noisy_settings());
    let clean = PsaSettings {
        noise: NoiseSettings::default(),
        random_init: false,
        trials: 1,
        ..readings.clone()
    };
    [("every reading, noisy", readings), ("every reading, clean", clean)]
}

/// One evaluation stream per network seed.
pub fn streams(seeds: std::ops::Range<u64>) -> Vec<Stream> {
    seeds.map(|s| stream(s, &[2])).collect()
}

/// The fitness of networks `seeds` on the scalar path, the reference.
pub fn scalar_fitness(settings: &PsaSettings, task: Task, seeds: std::ops::Range<u64>) -> Vec<f64> {
    let mut runner = TrialRunner::new(settings, task).unwrap();
    seeds
        .clone()
        .map(random_network)
        .zip(streams(seeds))
        .map(|(n, mut rng)| runner.evaluate(&n, &mut rng).unwrap())
        .collect()
}

/// Asserts that `other` holds the bits of `scalar`, naming the networks that differ.
pub fn assert_bit_identical(scalar: &[f64], other: &[f64], what: &str) {
    assert_eq!(scalar.len(), other.len());
    let differing: Vec<usize> = (0..scalar.len())
        .filter(|&i| scalar[i].to_bits() != other[i].to_bits())
        .collect();
    assert!(
        differing.is_empty(),
        "{what}: {} of {} networks differ, first {:?}: scalar {} other {}",
        differing.len(),
        scalar.len(),
        differing.first(),
        scalar[differing[0]],
        other[differing[0]]
    );
}

/// Asserts that the `cuda` trial kernel, its trials flown by `fly` (the
/// host build or a GPU), gives the scalar path's fitness bit for bit on
/// 2,100 random networks: 400 per task clean, 200 per task on tasks 1 and
/// 3 with noise on inputs and outputs, random starts and 3 trials, 100
/// with the original fitness, 400 with the accurate exponential, and 150
/// per task under every other reading ([`reading_settings`]).
pub fn assert_kernel_gives_the_scalar_paths_bits(fly: impl Fn(&TrialBatch) -> Result<TrialPoints, PsaError>) {
    let kernel = |settings: &PsaSettings, task: Task, seeds: std::ops::Range<u64>| {
        let networks: Vec<Network> = seeds.clone().map(random_network).collect();
        let refs: Vec<&Network> = networks.iter().collect();
        evaluate_with(settings, task, &refs[..], 0..refs.len(), &mut streams(seeds), &fly).unwrap()
    };
    let check = |settings: &PsaSettings, task: Task, seeds: std::ops::Range<u64>, what: &str| {
        assert_bit_identical(
            &scalar_fitness(settings, task, seeds.clone()),
            &kernel(settings, task, seeds),
            what,
        )
    };
    let clean = native(PsaSettings::default());
    for &task in Task::VARIANTS {
        check(&clean, task, 9000..9400, &format!("clean task {task}"));
    }
    let noisy = noisy_settings();
    for task in [Task::StopRotation, Task::StopAtPosition] {
        check(&noisy, task, 9500..9700, &format!("noisy task {task}"));
    }
    check(&original_fitness_settings(), Task::Turn, 9800..9900, "original fitness");
    let accurate = PsaSettings {
        exponential: Exponential::Accurate,
        ..clean
    };
    check(&accurate, Task::StopAtPosition, 9000..9400, "accurate exponential");
    for (what, settings) in reading_settings() {
        for &task in Task::VARIANTS {
            let settings = PsaSettings {
                random_init: settings.random_init && task.has_random_init(),
                ..settings.clone()
            };
            check(&settings, task, 9400..9550, &format!("{what}, task {task}"));
        }
    }
}
