//! `psa-esp bench`'s ODE lockstep rows: ns per network-step of the ODE
//! lockstep path by the number of bodies flown in one world (1 is one
//! world per network's cost in the same code), on one thread.

use std::time::Instant;

use anyhow::Result;
use serde::Serialize;

use super::bench_runs::median;
use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::{stream, Stream};
use psa_sim::psa::{OdeLockstepRunner, PsaSettings, Task};

/// The world sizes measured.
pub const WORLD_SIZES: [usize; 6] = [1, 4, 8, 16, 32, 64];

/// The lockstep path's speed with `bodies` bodies in one world.
#[derive(Debug, Serialize)]
pub struct LockstepTiming {
    /// Bodies (networks) per world.
    pub bodies: usize,
    /// ns per network-step, 1 thread (median of the rounds).
    pub ns_per_network_step: f64,
}

/// ns per network-step of the ODE lockstep path on task 1 (default
/// settings) for every size of [`WORLD_SIZES`]: `networks` evaluated in
/// batches of that many, `rounds` rounds, the sizes interleaved in each
/// round so that machine noise hits them alike.
pub fn lockstep_by_world_size(networks: &[Network], rounds: u64) -> Result<Vec<LockstepTiming>> {
    let settings = PsaSettings::default();
    let mut runner = OdeLockstepRunner::new(&settings, Task::StopRotation)?;
    let steps = (networks.len() * settings.steps) as f64;
    let mut samples = vec![Vec::new(); WORLD_SIZES.len()];
    for _ in 0..rounds {
        for (&size, samples) in WORLD_SIZES.iter().zip(&mut samples) {
            let mut rngs: Vec<Stream> = (0..networks.len() as u64).map(|j| stream(j, &[])).collect();
            let start = Instant::now();
            for first in (0..networks.len()).step_by(size) {
                let end = (first + size).min(networks.len());
                std::hint::black_box(runner.evaluate(networks, first..end, &mut rngs[first..end])?);
            }
            samples.push(start.elapsed().as_nanos() as f64 / steps);
        }
    }
    Ok(WORLD_SIZES
        .iter()
        .zip(samples)
        .map(|(&bodies, s)| LockstepTiming {
            bodies,
            ns_per_network_step: median(s),
        })
        .collect())
}
