//! Many ODE worlds stepped at once on rayon threads, each world built on the
//! thread that steps it, give bit-identical results to stepping them one by one.

use psa_sim::ode::thread_pool;
use psa_sim::physics::{create_backend, random_thrust_sequence, trajectory, BackendKind, BodyState, StepSettings};
use psa_sim::psa::BodySettings;
use rayon::prelude::*;

fn run(kind: BackendKind, index: u64) -> Vec<BodyState> {
    let model = BodySettings::default().model().unwrap();
    let mut backend = create_backend(kind, &model, &StepSettings::default()).unwrap();
    let commands = random_thrust_sequence(99, index, 500, 4);
    let start = BodyState {
        omega: 1.0,
        ..BodyState::default()
    };
    trajectory(backend.as_mut(), &start, &commands).unwrap()
}

#[test]
fn parallel_worlds_are_bit_identical_to_serial_ones() {
    const WORLDS: u64 = 96;
    for kind in BackendKind::available() {
        let serial: Vec<_> = (0..WORLDS).map(|i| run(kind, i)).collect();
        for threads in [2, 4, 8] {
            let pool = thread_pool(threads).unwrap();
            let parallel: Vec<_> = pool.install(|| (0..WORLDS).into_par_iter().map(|i| run(kind, i)).collect());
            assert!(serial == parallel, "{kind}: {threads} threads differ from serial");
        }
    }
}

#[test]
fn worlds_on_plain_threads_need_no_set_up_by_the_caller() {
    // ODE's per-thread data is allocated by the first world of each thread.
    let handles: Vec<_> = (0..4)
        .map(|i| std::thread::spawn(move || run(BackendKind::Ode, i)))
        .collect();
    for (i, h) in handles.into_iter().enumerate() {
        assert!(h.join().unwrap() == run(BackendKind::Ode, i as u64));
    }
}
