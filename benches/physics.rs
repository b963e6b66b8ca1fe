//! ns per physics step and per PSA network evaluation of each backend (criterion).
//! `psa-esp bench` measures the same in one run and prints a table.

use criterion::{criterion_group, criterion_main, Criterion};
use psa_esp::physics::{create_backend, BackendKind, BodyState, StepSettings};
use psa_esp::psa::BodySettings;

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

/// One PSA network evaluation (a 500-step trial of task 1) per backend.
fn psa_evaluation(c: &mut Criterion) {
    use psa_esp::evolution::operators::random_genes;
    use psa_esp::network::Network;
    use psa_esp::psa::{PsaSettings, Task, TrialRunner};
    let mut rng = psa_esp::rng::stream(1, &[]);
    let network = Network::from_genes(7, 4, random_genes(&mut rng, 55, 6.0)).expect("valid network");
    let mut group = c.benchmark_group("psa_evaluation");
    group.sample_size(20);
    for kind in BackendKind::available() {
        let settings = PsaSettings {
            backend: kind,
            ..PsaSettings::default()
        };
        let mut runner = TrialRunner::new(&settings, Task::StopRotation).expect("runner");
        group.bench_function(kind.name(), |b| {
            b.iter(|| {
                runner
                    .evaluate(&network, &mut psa_esp::rng::stream(0, &[]))
                    .expect("evaluate")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, physics_step, psa_evaluation);
criterion_main!(benches);
