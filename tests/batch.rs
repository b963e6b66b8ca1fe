//! The batched (SIMD) evaluation path against the scalar reference: the
//! same fitness, bit for bit, on thousands of seeded random networks, on
//! every task, with noise, random starts and several trials, and on every
//! SIMD level (the portable fallback included); and the `cuda` path's
//! trial kernel, built for the host, against the same reference.

mod kernel_cases;

use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::stream;
use kernel_cases::{
    assert_bit_identical, native, noisy_settings, original_fitness_settings, random_network, scalar_fitness, streams,
};
use psa_sim::evaluator::{trial_scores, EvalPath};
use psa_sim::numeric::{Exponential, SimdLevel};
use psa_sim::physics::BackendKind;
use psa_sim::psa::batch::{LANES, NARROW_LANES, SMALL_LANES};
use psa_sim::psa::cuda::{evaluate_with, fly_on_host};
use psa_sim::psa::{BatchRunner, PsaSettings, Task, TrialRunner};
use strum::VariantArray;

/// Fitness of networks `seeds` by the scalar path and by the batched path on `level`.
fn both_paths(
    settings: &PsaSettings,
    task: Task,
    seeds: std::ops::Range<u64>,
    level: SimdLevel,
) -> (Vec<f64>, Vec<f64>) {
    let scalar = scalar_fitness(settings, task, seeds.clone());
    let networks: Vec<Network> = seeds.clone().map(random_network).collect();
    let refs: Vec<&Network> = networks.iter().collect();
    let batched = BatchRunner::new(settings, task)
        .unwrap()
        .with_level(level)
        .evaluate(&refs[..], 0..refs.len(), &mut streams(seeds))
        .unwrap();
    (scalar, batched)
}

#[test]
fn batched_fitness_equals_the_scalar_path_on_thousands_of_random_networks() {
    let settings = native(PsaSettings::default());
    for &task in Task::VARIANTS {
        let (scalar, batched) = both_paths(&settings, task, 0..1200, SimdLevel::detect());
        assert_bit_identical(&scalar, &batched, &format!("task {task}"));
        // The sample is not degenerate: fitness values spread out.
        let distinct = scalar
            .iter()
            .map(|f| f.to_bits())
            .collect::<std::collections::HashSet<_>>();
        assert!(
            distinct.len() >= 30,
            "task {task}: only {} distinct fitness values",
            distinct.len()
        );
    }
}

#[test]
fn batched_fitness_equals_the_scalar_path_with_noise_random_starts_trials_and_the_original_fitness() {
    let noisy = noisy_settings();
    for task in [Task::StopRotation, Task::StopAtPosition] {
        let (scalar, batched) = both_paths(&noisy, task, 5000..5300, SimdLevel::detect());
        assert_bit_identical(&scalar, &batched, &format!("noisy task {task}"));
    }
    let original = original_fitness_settings();
    let (scalar, batched) = both_paths(&original, Task::Turn, 7000..7300, SimdLevel::detect());
    assert_bit_identical(&scalar, &batched, "original fitness");
}

#[test]
fn batched_fitness_equals_the_scalar_path_under_every_reading_of_the_inputs_and_fitness() {
    for (what, settings) in kernel_cases::reading_settings() {
        for &task in Task::VARIANTS {
            let settings = PsaSettings {
                random_init: settings.random_init && task.has_random_init(),
                ..settings.clone()
            };
            let (scalar, batched) = both_paths(&settings, task, 7300..7500, SimdLevel::detect());
            assert_bit_identical(&scalar, &batched, &format!("{what}, task {task}"));
        }
    }
}

/// Networks whose thrusters turn on the last bits of one logistic unit:
/// hidden unit 0 sees only the bias (net input `x`), unit 1 nothing (its
/// output is 1/2 with either exponential), and output `o` gets
/// `w (h0 - c)` with `c` the accurate exponential's h0 and `w` chosen to
/// make the fast one's difference 10. So the accurate exponential gives
/// that thruster a command of about 1/2, the fast one about 0 or 1.
fn networks_that_tell_the_exponentials_apart() -> Vec<Network> {
    use psa_sim::numeric::sigmoid_with;
    let mut networks = Vec::new();
    for (i, x) in [0.5, 1.25, -0.75, 2.0, -1.5].into_iter().enumerate() {
        let (accurate, fast) = (
            sigmoid_with(x, Exponential::Accurate),
            sigmoid_with(x, Exponential::Fast),
        );
        assert_ne!(accurate, fast, "the exponentials agree at {x}");
        let w = 10.0 / (fast - accurate);
        let o = i % 4;
        let mut genes = vec![0.0; 2 * 11];
        genes[6] = x;
        genes[7 + o] = w;
        genes[11 + 7 + o] = -2.0 * w * accurate;
        networks.push(Network::from_genes(7, 4, genes).unwrap());
    }
    networks
}

#[test]
fn both_paths_fly_the_exponential_the_settings_name() {
    let fast = native(PsaSettings::default());
    assert_eq!(fast.exponential, Exponential::Fast);
    let accurate = PsaSettings {
        exponential: Exponential::Accurate,
        ..fast.clone()
    };
    let networks = networks_that_tell_the_exponentials_apart();
    let refs: Vec<&Network> = networks.iter().collect();
    let rngs = || streams(0..networks.len() as u64);
    let scalar = |settings: &PsaSettings, task: Task| -> Vec<f64> {
        let mut runner = TrialRunner::new(settings, task).unwrap();
        (networks.iter().zip(&mut rngs()))
            .map(|(n, rng)| runner.evaluate(n, rng).unwrap())
            .collect()
    };
    let batched = |settings: &PsaSettings, task: Task| {
        let runner = BatchRunner::new(settings, task).unwrap();
        runner.evaluate(&refs[..], 0..refs.len(), &mut rngs()).unwrap()
    };
    let kernel = |settings: &PsaSettings, task: Task| {
        evaluate_with(settings, task, &refs[..], 0..refs.len(), &mut rngs(), fly_on_host).unwrap()
    };
    let mut moved = 0;
    for &task in Task::VARIANTS {
        let (fast_scalar, accurate_scalar) = (scalar(&fast, task), scalar(&accurate, task));
        for (settings, reference, what) in [(&fast, &fast_scalar, "fast"), (&accurate, &accurate_scalar, "accurate")] {
            assert_bit_identical(reference, &batched(settings, task), &format!("{what}, batched"));
            assert_bit_identical(
                reference,
                &kernel(settings, task),
                &format!("{what}, cuda kernel on the host"),
            );
        }
        moved += fast_scalar.iter().zip(&accurate_scalar).filter(|(a, b)| a != b).count();
    }
    assert!(moved >= 3, "only {moved} fitness values told the exponentials apart");
}

#[test]
fn every_simd_level_computes_the_same_bits_the_portable_fallback_included() {
    // A level the CPU lacks runs the portable code, so this holds anywhere;
    // on an AVX-512 machine it compares all three instruction sets.
    let settings = native(PsaSettings::default());
    let (scalar, _) = both_paths(&settings, Task::StopAtPosition, 100..400, SimdLevel::Portable);
    for &level in SimdLevel::VARIANTS {
        let (_, batched) = both_paths(&settings, Task::StopAtPosition, 100..400, level);
        assert_bit_identical(&scalar, &batched, &format!("level {level}"));
    }
}

#[test]
fn blocks_of_every_width_and_ranges_of_a_set_give_the_same_fitness_as_a_full_block() {
    let settings = native(PsaSettings::default());
    let runner = BatchRunner::new(&settings, Task::StopRotation).unwrap();
    // A full wide block, then a padded wide one (more than NARROW_LANES left).
    let count = (LANES + NARROW_LANES + 5) as u64;
    let networks: Vec<Network> = (0..count).map(random_network).collect();
    let refs: Vec<&Network> = networks.iter().collect();
    let all = runner
        .evaluate(&refs[..], 0..refs.len(), &mut streams(0..count))
        .unwrap();
    let bits = |f: &[f64]| f.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    for &level in SimdLevel::VARIANTS {
        let runner = runner.clone().with_level(level);
        for (i, network) in networks.iter().enumerate() {
            // Alone, a network flies in a padded small block.
            let alone = runner
                .evaluate(&[network][..], 0..1, &mut [stream(i as u64, &[2])])
                .unwrap();
            assert_eq!(alone[0].to_bits(), all[i].to_bits(), "network {i}, {level}");
            // The same network as a one-network range of the whole set.
            let in_place = runner
                .evaluate(&networks[..], i..i + 1, &mut [stream(i as u64, &[2])])
                .unwrap();
            assert_eq!(in_place[0].to_bits(), all[i].to_bits(), "network {i} in place, {level}");
        }
        // Ranges from mid-set: a wide and a padded small block, a padded
        // narrow block, a wide and a full small block.
        for range in [3..LANES + 9, 5..5 + SMALL_LANES + 4, 10..10 + LANES + SMALL_LANES] {
            let part = runner
                .evaluate(
                    &networks[..],
                    range.clone(),
                    &mut streams(range.start as u64..range.end as u64),
                )
                .unwrap();
            assert_eq!(bits(&part), bits(&all[range.clone()]), "{range:?}, {level}");
        }
    }
}

#[test]
fn a_networks_trials_flown_side_by_side_are_the_scalar_trials_bit_for_bit_on_every_path() {
    // The robustness tests' many trials of one champion, one trial per
    // lane: every width (a padded small block alone, small and narrow
    // remainders, full wide blocks), with noise and random starts and
    // without, on every SIMD level and through every evaluation path of
    // native (each of `EvalPath::all_readable` but the ODE paths).
    let clean = native(PsaSettings::default());
    let cases = [
        (clean.clone(), Task::Turn),
        (noisy_settings(), Task::StopAtPosition),
        (original_fitness_settings(), Task::StopRotation),
    ];
    let paths: Vec<EvalPath> = EvalPath::all_readable()
        .into_iter()
        .filter(|path| path.backend() != Some(BackendKind::Ode))
        .collect();
    for (settings, task) in cases {
        for trials in [1, SMALL_LANES + 1, NARROW_LANES + 3, 2 * LANES + 5] {
            let settings = PsaSettings {
                trials,
                ..settings.clone()
            };
            for seed in 0..3 {
                let network = random_network(9000 + seed);
                let mut rng = stream(seed, &[4]);
                let scalar = TrialRunner::new(&settings, task)
                    .unwrap()
                    .evaluate_trials(&network, &mut rng)
                    .unwrap();
                assert_eq!(scalar.len(), trials);
                for path in &paths {
                    let mut batched_rng = stream(seed, &[4]);
                    let batched = trial_scores(&settings, task, &network, &mut batched_rng, path).unwrap();
                    let what = format!("task {task}, {trials} trials, network {seed}, path {}", path.name());
                    assert_bit_identical(&scalar, &batched, &what);
                    assert_eq!(
                        batched_rng.get_word_pos(),
                        rng.get_word_pos(),
                        "{what}: the stream moved apart"
                    );
                }
            }
        }
    }
    let runner = BatchRunner::new(&clean, Task::Turn).unwrap();
    let wrong = Network::from_genes(3, 4, vec![0.0; 7]).unwrap();
    let err = runner.evaluate_trials(&wrong, &mut stream(0, &[])).unwrap_err();
    assert!(err.to_string().contains("needs 7"), "{err}");
}

#[test]
fn an_input_scale_that_could_make_a_nan_thrust_is_refused_by_both_paths() {
    // Every sum of a network is a fused multiply-add, so finite weights on
    // finite inputs never make NaN; only an absurd input scale could (on
    // task 3 it made the y input -inf, and 0 x -inf is NaN). Both the
    // scalar and the batched runner now refuse that scale by name before
    // any trial, with and without output noise (the noisy kernel is
    // compiled apart).
    for output_sd in [0.0, 0.1] {
        let mut settings = native(PsaSettings::default());
        settings.sensors.position_scale = 1e308;
        settings.noise.output_sd = output_sd;
        let Err(scalar) = TrialRunner::new(&settings, Task::StopAtPosition) else {
            panic!("the scalar runner took position_scale = 1e308");
        };
        let Err(batched) = BatchRunner::new(&settings, Task::StopAtPosition) else {
            panic!("the batched runner took position_scale = 1e308");
        };
        assert_eq!(batched.to_string(), scalar.to_string());
        assert!(scalar.to_string().contains("sensors.position_scale"), "{scalar}");
    }
}

#[test]
fn the_batched_path_refuses_other_backends_and_bad_networks() {
    let err = BatchRunner::new(&PsaSettings::default(), Task::Turn).unwrap_err();
    assert!(err.to_string().contains("native"), "{err}");
    let runner = BatchRunner::new(&native(PsaSettings::default()), Task::Turn).unwrap();
    let wrong = Network::from_genes(3, 4, vec![0.0; 7]).unwrap();
    let err = runner.evaluate(&[&wrong][..], 0..1, &mut [stream(0, &[])]).unwrap_err();
    assert!(err.to_string().contains("needs 7"), "{err}");
}

#[test]
fn an_esp_run_on_native_is_the_same_on_every_path_and_thread_count() {
    use esp_neuroevolution::{Esp, EspSettings};
    use psa_sim::evaluator::{EvalPath, PsaEvaluator};
    let settings = native(PsaSettings::default());
    let esp = Esp::new(
        EspSettings {
            subpop_size: 12,
            generations: 12,
            stagnation: 3,
            ..psa_experiment::paper_esp_settings()
        },
        7,
    )
    .unwrap();
    let run = |level: Option<SimdLevel>, threads: usize| {
        let path = level.map_or(EvalPath::Scalar, EvalPath::Simd);
        let evaluator = PsaEvaluator::new(settings.clone(), Task::StopAtPosition, &path).unwrap();
        let pool = psa_sim::ode::thread_pool(threads).unwrap();
        let result = pool.install(|| esp.run(&evaluator, |_| {})).unwrap();
        (
            result.records,
            result.champion.network,
            result.champion.fitness.to_bits(),
        )
    };
    let reference = run(None, 1);
    assert!(reference.0.iter().any(|r| r.burst), "the run exercises burst mutation");
    for (level, threads) in [
        (Some(SimdLevel::detect()), 1),
        (Some(SimdLevel::detect()), 2),
        (Some(SimdLevel::Portable), 2),
    ] {
        assert_eq!(run(level, threads), reference, "{level:?} on {threads} threads");
    }
}

/// Fitness of networks `seeds` by the `cuda` path's kernel built for the host.
#[test]
fn the_cuda_kernel_built_for_the_host_computes_the_scalar_paths_bits() {
    kernel_cases::assert_kernel_gives_the_scalar_paths_bits(psa_sim::psa::cuda::fly_on_host);
}
