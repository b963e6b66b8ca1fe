//! Poles on a cart, as in the pole-balancing benchmarks of Gomez,
//! Schmidhuber & Miikkulainen, "Accelerated Neural Evolution through
//! Cooperatively Coevolved Synapses" (JMLR 9, 2008), appendix A: Wieland's
//! equations of motion for any number of poles hinged side by side on one
//! cart, with the cart's friction on the track and each hinge's friction,
//! integrated by fourth-order Runge-Kutta.
//!
//! The constants are those of the paper and of ESP's own cart-pole code:
//! gravity -9.8 m/s² (Wieland's sign), a 1 kg cart on a 4.8 m track,
//! friction coefficients 0.0005 (cart) and 0.000002 (hinges), forces of up
//! to 10 N, and Runge-Kutta steps of 0.01 s.

/// Gravity (Wieland's sign convention: negative).
pub const G: f64 = -9.8;
/// Mass of the cart (kg).
pub const CART_MASS: f64 = 1.0;
/// Friction coefficient of the cart on the track.
pub const CART_FRICTION: f64 = 0.0005;
/// Friction coefficient of every pole's hinge.
pub const HINGE_FRICTION: f64 = 0.000002;
/// The largest force on the cart (N).
pub const MAX_FORCE: f64 = 10.0;
/// One Runge-Kutta step (s).
pub const DT: f64 = 0.01;
/// The cart fails beyond this distance from the track's centre (m).
pub const TRACK_LIMIT: f64 = 2.4;

/// A pole: its mass (kg) and half its length (m).
#[derive(Debug, Clone, Copy)]
pub struct Pole {
    /// Mass (kg).
    pub mass: f64,
    /// Half the pole's length (m).
    pub half_length: f64,
}

/// The long pole of every task: 1 m, 0.1 kg.
pub const LONG_POLE: Pole = Pole {
    mass: 0.1,
    half_length: 0.5,
};

/// The double pole's short pole: 0.1 m, 0.01 kg.
pub const SHORT_POLE: Pole = Pole {
    mass: 0.01,
    half_length: 0.05,
};

/// The cart's position and velocity, then each pole's angle from vertical
/// (rad) and angular velocity: `2 + 2 N` numbers for `N` poles.
pub type State<const S: usize> = [f64; S];

/// The sign as ESP's code takes it: +1 for 0.
fn sign(x: f64) -> f64 {
    if x >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// The most poles on a cart.
pub const MAX_POLES: usize = 4;

/// Wieland's equations: the state's derivative under `force` on the cart.
///
/// # Panics
/// With more than [`MAX_POLES`] poles, or a state not `2 + 2 x` their number long.
fn derivatives<const S: usize>(poles: &[Pole], state: State<S>, force: f64) -> State<S> {
    assert!(
        poles.len() <= MAX_POLES && S == 2 + 2 * poles.len(),
        "a state of 2 + 2 per pole"
    );
    let velocity = state[1];
    // Each pole's sine, cosine and hinge friction term, and its effective
    // force and mass on the cart.
    let mut terms = [(0.0, 0.0, 0.0); MAX_POLES];
    let (mut pole_forces, mut pole_masses) = (0.0, 0.0);
    for (i, pole) in poles.iter().enumerate() {
        let spin = state[3 + 2 * i];
        let (sin, cos) = state[2 + 2 * i].sin_cos();
        let moment = pole.mass * pole.half_length;
        let hinge = HINGE_FRICTION * spin / moment;
        terms[i] = (sin, cos, hinge);
        pole_forces += moment * spin * spin * sin + 0.75 * pole.mass * cos * (hinge + G * sin);
        pole_masses += pole.mass * (1.0 - 0.75 * cos * cos);
    }
    let acceleration = (force - CART_FRICTION * sign(velocity) + pole_forces) / (CART_MASS + pole_masses);
    let mut derivative = [0.0; S];
    derivative[0] = velocity;
    derivative[1] = acceleration;
    for (i, (pole, (sin, cos, hinge))) in poles.iter().zip(terms).enumerate() {
        derivative[2 + 2 * i] = state[3 + 2 * i];
        derivative[3 + 2 * i] = -0.75 * (acceleration * cos + G * sin + hinge) / pole.half_length;
    }
    derivative
}

/// One fourth-order Runge-Kutta step of [`DT`] under `force`.
pub fn rk4<const S: usize>(poles: &[Pole], state: State<S>, force: f64) -> State<S> {
    let along = |s: State<S>, d: State<S>, h: f64| -> State<S> { std::array::from_fn(|i| s[i] + h * d[i]) };
    let k1 = derivatives(poles, state, force);
    let k2 = derivatives(poles, along(state, k1, DT / 2.0), force);
    let k3 = derivatives(poles, along(state, k2, DT / 2.0), force);
    let k4 = derivatives(poles, along(state, k3, DT), force);
    std::array::from_fn(|i| state[i] + DT / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// Whether the cart has left the track or a pole leans beyond `angle_limit`.
pub fn failed<const S: usize>(state: &State<S>, angle_limit: f64) -> bool {
    state[0].abs() > TRACK_LIMIT || state[2..].iter().step_by(2).any(|angle| angle.abs() > angle_limit)
}
