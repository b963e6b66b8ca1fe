//! ESP on a classic benchmark: the single pole with velocities, task 1a of
//! Gomez, Schmidhuber & Miikkulainen, "Accelerated Neural Evolution through
//! Cooperatively Coevolved Synapses" (JMLR 9, 2008).
//!
//! A pole hinged on a cart that runs on a 4.8 m track; the network sees the
//! cart's position and velocity and the pole's angle and angular velocity,
//! and pushes the cart with a force of up to 10 N either way. The dynamics
//! are Wieland's equations (with the cart's and the hinge's friction),
//! integrated by fourth-order Runge-Kutta in steps of 0.01 s, two per
//! control step; a trial fails when the cart leaves the track or the pole
//! leans more than 36 degrees, and a network that balances the pole for
//! 100,000 control steps (about half an hour) solves the task. The pole
//! starts 4.5 degrees from vertical, everything else at rest.
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

use std::error::Error;

use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::Stream;
use esp_neuroevolution::{Ending, Esp, EspSettings, FnEvaluator, StopAt};

/// Control steps a solution balances the pole for.
const STEPS_TO_SOLVE: u32 = 100_000;
/// Evaluations a seed may spend before it counts as a failure.
const BUDGET: u64 = 200_000;
/// ESP's mean evaluations to solve task 1a, as published (Gomez et al. 2008).
const PUBLISHED_ESP: f64 = 289.0;

/// Gravity (Wieland's sign convention).
const G: f64 = -9.8;
/// Mass of the cart (kg).
const CART_MASS: f64 = 1.0;
/// Mass of the pole (kg).
const POLE_MASS: f64 = 0.1;
/// Half the pole's length (m).
const HALF_LENGTH: f64 = 0.5;
/// Friction of the cart on the track.
const CART_FRICTION: f64 = 0.0005;
/// Friction of the pole's hinge.
const HINGE_FRICTION: f64 = 0.000002;
/// The largest force on the cart (N).
const MAX_FORCE: f64 = 10.0;
/// Runge-Kutta step (s); two make a control step.
const DT: f64 = 0.01;
/// The cart fails beyond this distance from the track's centre (m).
const TRACK_LIMIT: f64 = 2.4;
/// The pole fails beyond this angle from vertical (rad): 36 degrees.
const ANGLE_LIMIT: f64 = 36.0 * std::f64::consts::PI / 180.0;

/// Cart position and velocity, pole angle and angular velocity.
type State = [f64; 4];

/// Wieland's equations of a cart with one pole under `force`.
fn derivatives([_, velocity, angle, spin]: State, force: f64) -> State {
    let (sin, cos) = angle.sin_cos();
    let hinge = HINGE_FRICTION * spin / (POLE_MASS * HALF_LENGTH);
    let pole_force = POLE_MASS * HALF_LENGTH * spin * spin * sin + 0.75 * POLE_MASS * cos * (hinge + G * sin);
    let pole_mass = POLE_MASS * (1.0 - 0.75 * cos * cos);
    let acceleration = (force - CART_FRICTION * velocity.signum() + pole_force) / (CART_MASS + pole_mass);
    let angular_acceleration = -0.75 * (acceleration * cos + G * sin + hinge) / HALF_LENGTH;
    [velocity, acceleration, spin, angular_acceleration]
}

/// One fourth-order Runge-Kutta step of `DT`.
fn rk4(state: State, force: f64) -> State {
    let along = |s: State, d: State, h: f64| -> State { std::array::from_fn(|i| s[i] + h * d[i]) };
    let k1 = derivatives(state, force);
    let k2 = derivatives(along(state, k1, DT / 2.0), force);
    let k3 = derivatives(along(state, k2, DT / 2.0), force);
    let k4 = derivatives(along(state, k3, DT), force);
    std::array::from_fn(|i| state[i] + DT / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// Control steps `network` keeps the pole up, at most [`STEPS_TO_SOLVE`].
fn balance(network: &Network) -> u32 {
    let mut state: State = [0.0, 0.0, 4.5_f64.to_radians(), 0.0];
    let mut output = [0.0];
    for step in 0..STEPS_TO_SOLVE {
        let [x, velocity, angle, spin] = state;
        if x.abs() > TRACK_LIMIT || angle.abs() > ANGLE_LIMIT {
            return step;
        }
        // Inputs scaled to about [-1, 1], and a bias.
        network.activate(&[x / 4.8, velocity / 2.0, angle / 0.52, spin / 2.0, 1.0], &mut output);
        let force = MAX_FORCE * (2.0 * output[0] - 1.0);
        state = rk4(rk4(state, force), force);
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
    let stop = StopAt {
        goal: Some(f64::from(STEPS_TO_SOLVE)),
        evaluations: Some(BUDGET),
    };
    let mut solved = Vec::new();
    for seed in 1..=seeds {
        let result = Esp::new(settings.clone(), seed)?
            .stop_at(stop)
            .run(&evaluator, |_| {})?;
        match result.ending {
            Ending::Goal => {
                let champion = &result.champion;
                println!(
                    "seed {seed:>3}: solved at evaluation {:>6} (generation {}, {} hidden neurons)",
                    champion.evaluation,
                    champion.generation,
                    champion.network.hidden()
                );
                solved.push(champion.evaluation as f64);
            }
            _ => println!(
                "seed {seed:>3}: not solved in {} evaluations (best {} steps)",
                result.evaluations(),
                result.champion.fitness
            ),
        }
    }
    if solved.is_empty() {
        return Err("no seed solved the task".into());
    }
    let mean = solved.iter().sum::<f64>() / solved.len() as f64;
    let sd = (solved.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (solved.len() as f64 - 1.0).max(1.0)).sqrt();
    let mut sorted = solved.clone();
    sorted.sort_by(f64::total_cmp);
    println!(
        "\nsolved {} of {seeds} seeds; evaluations to solve: mean {mean:.0} (sd {sd:.0}), median {:.0}; \
         published ESP (Gomez et al. 2008): {PUBLISHED_ESP:.0}",
        solved.len(),
        sorted[sorted.len() / 2]
    );
    if solved.len() as u64 != seeds {
        return Err(format!("{} seeds did not solve the task", seeds - solved.len() as u64).into());
    }
    Ok(())
}
