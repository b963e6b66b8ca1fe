//! 1 against 2 threads (criterion): PSA network evaluations on every path
//! (ode one world per network and in lockstep, native scalar, native batched on each SIMD level the CPU has,
//! rapier); `evolve`, one baseline ESP run of task 3 on `native`; and
//! `replicate`, a grid of 12 runs on `native` (baseline and max-credit, 3
//! tasks, 2 seeds) with 50-trial robustness tests. The speed-up is the ratio of a
//! workload's two times. `psa-esp bench` measures the same in one run and
//! prints it, with the machine.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use esp_neuroevolution::evaluate_all;
use psa_esp::cli::bench::machine;
use psa_esp::cli::bench_networks::random_networks;
use psa_esp::cli::bench_paths::EvaluationPath;
use psa_esp::cli::bench_runs::{evolve_workload, replicate_workload};
use psa_sim::ode::thread_pool;

/// Networks per timed iteration: two full blocks of the batched path per thread.
const NETWORKS: u64 = 128;
/// Generations of the timed `evolve` and `replicate` runs.
const GENERATIONS: usize = 20;

/// "`what` on 1 thread", "`what` on 2 threads".
fn on_threads(what: &str, threads: usize) -> String {
    format!("{what} on {threads} thread{}", if threads == 1 { "" } else { "s" })
}

fn evaluations(c: &mut Criterion) {
    eprintln!("machine: {}", machine());
    let networks = random_networks(NETWORKS).expect("random networks");
    let mut group = c.benchmark_group("psa_evaluation_threads");
    group.sample_size(10);
    group.throughput(Throughput::Elements(NETWORKS));
    for path in EvaluationPath::all() {
        let evaluator = path.evaluator().expect("evaluator");
        for threads in [1, 2] {
            let pool = thread_pool(threads).expect("thread pool");
            group.bench_function(on_threads(&path.label(), threads), |b| {
                b.iter(|| {
                    pool.install(|| evaluate_all(&evaluator, &networks[..], 0, &[]))
                        .expect("evaluate")
                })
            });
        }
    }
    group.finish();
}

fn runs(c: &mut Criterion) {
    let mut group = c.benchmark_group("runs_threads");
    group.sample_size(10);
    for workload in [
        evolve_workload(GENERATIONS).expect("evolve workload"),
        replicate_workload(GENERATIONS).expect("replicate workload"),
    ] {
        for threads in [1, 2] {
            group.bench_function(on_threads(workload.name, threads), |b| {
                b.iter(|| workload.run(threads).expect("run"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, evaluations, runs);
criterion_main!(benches);
