//! ESP on a classic benchmark: the single pole with velocities, task 1a of
//! Gomez, Schmidhuber & Miikkulainen, "Accelerated Neural Evolution through
//! Cooperatively Coevolved Synapses" (JMLR 9, 2008).
//!
//! A pole hinged on a cart that runs on a 4.8 m track; the network sees the
//! cart's position and velocity and the pole's angle and angular velocity,
//! and pushes the cart with a force of up to 10 N either way. The dynamics
//! are Wieland's equations (with the cart's and the hinge's friction),
//! integrated by fourth-order Runge-Kutta in steps of 0.01 s, two per
//! control step (`support/poles.rs`); a trial fails when the cart leaves
//! the track or the pole leans more than 36 degrees, and a network that
//! balances the pole for 100,000 control steps (about half an hour) solves
//! the task. The pole starts 4.5 degrees from vertical, everything else at
//! rest.
//!
//! ESP (Gomez's settings, sub-populations of 20) runs until a network
//! solves the task, and the example prints the evaluations it took for each
//! seed and their mean beside the published ESP figure.
//!
//! ```sh
//! cargo run --release -p esp-neuroevolution --example cart_pole        # 50 seeds
//! cargo run --release -p esp-neuroevolution --example cart_pole -- 5   # 5 seeds
//! ```
//!
//! It exits with an error when a seed does not solve the task within its
//! budget of evaluations.

#[path = "support/poles.rs"]
#[allow(dead_code)] // the double pole uses the rest
mod poles;
#[path = "support/solve.rs"]
mod solve;

use std::error::Error;

use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::Stream;
use esp_neuroevolution::{EspSettings, FnEvaluator};
use poles::{failed, rk4, LONG_POLE, MAX_FORCE};

/// Control steps a solution balances the pole for.
const STEPS_TO_SOLVE: u32 = 100_000;
/// Evaluations a seed may spend before it counts as a failure.
const BUDGET: u64 = 200_000;
/// ESP's mean evaluations to solve task 1a, as published (Gomez et al. 2008).
const PUBLISHED_ESP: f64 = 289.0;
/// The pole fails beyond this angle from vertical (rad): 36 degrees.
const ANGLE_LIMIT: f64 = 36.0 * std::f64::consts::PI / 180.0;

/// Control steps `network` keeps the pole up, at most [`STEPS_TO_SOLVE`].
fn balance(network: &Network) -> u32 {
    let mut state = [0.0, 0.0, 4.5_f64.to_radians(), 0.0];
    let mut output = [0.0];
    for step in 0..STEPS_TO_SOLVE {
        if failed(&state, ANGLE_LIMIT) {
            return step;
        }
        let [x, velocity, angle, spin] = state;
        // Inputs scaled to about [-1, 1], and a bias.
        network.activate(&[x / 4.8, velocity / 2.0, angle / 0.52, spin / 2.0, 1.0], &mut output);
        let force = MAX_FORCE * (2.0 * output[0] - 1.0);
        state = rk4(&[LONG_POLE], rk4(&[LONG_POLE], state, force), force);
    }
    STEPS_TO_SOLVE
}

fn main() -> Result<(), Box<dyn Error>> {
    let seeds: u64 = match std::env::args().nth(1) {
        Some(n) => n.parse().map_err(|e| format!("the number of seeds, {n:?}: {e}"))?,
        None => 50,
    };
    let evaluator = FnEvaluator::new(5, 1, |network: &Network, _: &mut Stream| {
        Ok(f64::from(balance(network)))
    });
    let settings = EspSettings {
        subpop_size: 20,
        generations: 10_000,
        ..EspSettings::gomez()
    };
    let outcomes = solve::solve(&settings, &evaluator, seeds, f64::from(STEPS_TO_SOLVE), BUDGET, false)?;
    let (solved, mean, sd, median) = solve::summary(&outcomes).ok_or("no seed solved the task")?;
    println!(
        "\nsolved {solved} of {seeds} seeds; evaluations to solve: mean {mean:.0} (sd {sd:.0}), median {median:.0}; \
         published ESP (Gomez et al. 2008): {PUBLISHED_ESP:.0}"
    );
    if solved as u64 != seeds {
        return Err(format!("{} seeds did not solve the task", seeds - solved as u64).into());
    }
    Ok(())
}
