//! ns per physics step of each backend, our ODE path against the bare ODE
//! calls, PSA network evaluations on every path (ode, native scalar,
//! native batched on each SIMD level the CPU has, rapier) and the logistic
//! function alone as the batched path computes it (criterion); the
//! 2-thread figures are in `threads.rs`. `psa-esp bench` measures the same
//! in one run and prints a table.

use criterion::{criterion_group, criterion_main, Criterion};
use psa_sim::named::Named;
use psa_sim::physics::{create_backend, BackendKind, BodyState, StepSettings};
use psa_sim::psa::BodySettings;
use strum::VariantArray;

fn physics_step(c: &mut Criterion) {
    let model = BodySettings::default().model().expect("default body is valid");
    let settings = StepSettings::default();
    let mut group = c.benchmark_group("physics_step");
    for kind in BackendKind::available() {
        let mut backend = create_backend(kind, &model, &settings).expect("backend builds");
        let thrust = [0.3, 0.7, 0.2, 0.5];
        let mut steps = 0u32;
        group.bench_function(kind.name(), |b| {
            b.iter(|| {
                // Keep the state bounded: restart every 500 steps, as a trial does.
                if steps % 500 == 0 {
                    backend.reset(&BodyState::default()).expect("reset");
                }
                steps += 1;
                backend.step(std::hint::black_box(&thrust)).expect("step");
            })
        });
    }
    group.finish();
}

/// 500 steps of our ODE path (`step` + `planar_state`) and of the bare ODE calls.
fn ode_path(c: &mut Criterion) {
    use psa_sim::physics::{random_thrust_sequence, OdeBackend, PhysicsBackend};
    let model = BodySettings::default().model().expect("default body is valid");
    let thrust = random_thrust_sequence(1, 0, 500, model.thrusters.len());
    let mut group = c.benchmark_group("ode_path_500_steps");
    // Both sides run on from wherever the last iteration left the body
    // (ODE's cost does not depend on the state of a free body).
    let mut backend = OdeBackend::new(&model, &StepSettings::default()).expect("backend builds");
    group.bench_function("ours", |b| {
        b.iter(|| {
            for row in &thrust {
                backend.step(row).expect("step");
                std::hint::black_box(backend.planar_state());
            }
        })
    });
    let reference = OdeBackend::new(&model, &StepSettings::default()).expect("backend builds");
    let bare = reference.bare_loop(&thrust).expect("valid thrust");
    group.bench_function("bare", |b| {
        b.iter(|| {
            bare.run(thrust.len(), |s| {
                std::hint::black_box(s.planar_values());
            })
        })
    });
    group.finish();
}

/// One PSA network evaluation (a 500-step trial of task 1) per path; the
/// batched path evaluates 32 networks per iteration, reported per network.
fn psa_evaluation(c: &mut Criterion) {
    use esp_neuroevolution::network::Network;
    use esp_neuroevolution::operators::random_genes;
    use psa_sim::numeric::SimdLevel;
    use psa_sim::psa::{BatchRunner, PsaSettings, Task, TrialRunner};
    let mut rng = esp_neuroevolution::rng::stream(1, &[]);
    let networks: Vec<Network> = (0..32)
        .map(|_| Network::from_genes(7, 4, random_genes(&mut rng, 55, 6.0)).expect("valid network"))
        .collect();
    let network = &networks[0];
    let mut group = c.benchmark_group("psa_evaluation");
    group.sample_size(20);
    for kind in BackendKind::available() {
        let settings = PsaSettings {
            backend: kind,
            ..PsaSettings::default()
        };
        let mut runner = TrialRunner::new(&settings, Task::StopRotation).expect("runner");
        let name = if kind == BackendKind::Native {
            "native scalar"
        } else {
            kind.name()
        };
        group.bench_function(name, |b| {
            b.iter(|| {
                runner
                    .evaluate(network, &mut esp_neuroevolution::rng::stream(0, &[]))
                    .expect("evaluate")
            })
        });
    }
    let settings = PsaSettings {
        backend: BackendKind::Native,
        ..PsaSettings::default()
    };
    group.throughput(criterion::Throughput::Elements(networks.len() as u64));
    for level in SimdLevel::VARIANTS.iter().copied().filter(|l| l.is_supported()) {
        let runner = BatchRunner::new(&settings, Task::StopRotation)
            .expect("runner")
            .with_level(level);
        group.bench_function(format!("native batched {level} (32 networks)"), |b| {
            b.iter(|| {
                let mut rngs: Vec<_> = (0..networks.len())
                    .map(|_| esp_neuroevolution::rng::stream(0, &[]))
                    .collect();
                runner
                    .evaluate(&networks[..], 0..networks.len(), &mut rngs)
                    .expect("evaluate")
            })
        });
    }
    group.finish();
}

/// The logistic function over blocks of the batched path's width, on the
/// CPU's best SIMD level; reported per value.
fn logistic_function(c: &mut Criterion) {
    use psa_esp::cli::bench::{logistic_arguments, logistic_rounds, LOGISTIC_BLOCKS};
    use psa_sim::psa::batch::LANES;
    let mut values = logistic_arguments(LOGISTIC_BLOCKS);
    let mut group = c.benchmark_group("logistic_function");
    group.throughput(criterion::Throughput::Elements((LOGISTIC_BLOCKS * LANES) as u64));
    group.bench_function(format!("{LOGISTIC_BLOCKS} blocks of {LANES} values"), |b| {
        b.iter(|| logistic_rounds(std::hint::black_box(&mut values), 1))
    });
    group.finish();
}

criterion_group!(benches, physics_step, ode_path, psa_evaluation, logistic_function);
criterion_main!(benches);
