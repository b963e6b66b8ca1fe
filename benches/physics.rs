//! ns per physics step of each backend on the PSA body (criterion).
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

criterion_group!(benches, physics_step);
criterion_main!(benches);
