//! Cross-checking backends: the same seeded random thrust sequences on every
//! backend, and the largest difference of each against `ode`.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::{create_backend, BackendKind, BodyState, PhysicsBackend, PhysicsError, RigidBodyModel, StepSettings};

/// Largest differences allowed against `ode`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Tolerance {
    /// Position (m, Euclidean distance).
    pub position: f64,
    /// Heading (rad, wrapped difference).
    pub heading: f64,
    /// Linear velocity (m/s, Euclidean) and angular velocity (rad/s).
    pub velocity: f64,
}

/// `native` runs ODE's own update rule: only rounding may differ.
pub const NATIVE_TOLERANCE: Tolerance = Tolerance {
    position: 1e-9,
    heading: 1e-9,
    velocity: 1e-9,
};

/// The tolerance a backend is held to against `ode` (`ode` itself: zero).
pub fn tolerance(kind: BackendKind) -> Tolerance {
    match kind {
        BackendKind::Ode => Tolerance {
            position: 0.0,
            heading: 0.0,
            velocity: 0.0,
        },
        BackendKind::Native => NATIVE_TOLERANCE,
        BackendKind::Rapier => RAPIER_TOLERANCE,
    }
}

/// Largest differences found between one backend and `ode`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Deviation {
    /// Largest position difference (m).
    pub position: f64,
    /// Largest wrapped heading difference (rad).
    pub heading: f64,
    /// Largest linear (m/s) or angular (rad/s) velocity difference.
    pub velocity: f64,
}

impl Deviation {
    const ZERO: Deviation = Deviation {
        position: 0.0,
        heading: 0.0,
        velocity: 0.0,
    };

    /// The difference between two states.
    pub fn between(a: &BodyState, b: &BodyState) -> Deviation {
        Deviation {
            position: (a.x - b.x).hypot(a.y - b.y),
            heading: super::wrap_angle(a.heading - b.heading).abs(),
            velocity: (a.vx - b.vx).hypot(a.vy - b.vy).max((a.omega - b.omega).abs()),
        }
    }

    /// Component-wise maximum.
    pub fn max(self, other: Deviation) -> Deviation {
        Deviation {
            position: self.position.max(other.position),
            heading: self.heading.max(other.heading),
            velocity: self.velocity.max(other.velocity),
        }
    }

    /// Whether every component is within `tol`.
    pub fn within(&self, tol: &Tolerance) -> bool {
        self.position <= tol.position && self.heading <= tol.heading && self.velocity <= tol.velocity
    }
}

/// One backend's result in a cross-check.
#[derive(Debug, Clone, Serialize)]
pub struct BackendComparison {
    /// The backend compared against `ode`.
    pub backend: BackendKind,
    /// Its largest differences.
    pub deviation: Deviation,
    /// What it is allowed.
    pub tolerance: Tolerance,
    /// Whether the deviation is within the tolerance.
    pub passed: bool,
}

/// The result of [`crosscheck`].
#[derive(Debug, Clone, Serialize)]
pub struct CrosscheckReport {
    /// Number of random thrust sequences.
    pub sequences: usize,
    /// Steps per sequence.
    pub steps: usize,
    /// Seed of the sequences.
    pub seed: u64,
    /// One entry per backend other than `ode`.
    pub comparisons: Vec<BackendComparison>,
}

impl CrosscheckReport {
    /// Whether every backend is within its tolerance.
    pub fn passed(&self) -> bool {
        self.comparisons.iter().all(|c| c.passed)
    }
}

/// Thrust sequence number `index` of a cross-check with `seed`: every
/// thruster command uniform in [0, 1], independently per step.
pub fn random_thrust_sequence(seed: u64, index: u64, steps: usize, thrusters: usize) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    (0..steps)
        .map(|_| (0..thrusters).map(|_| rng.random_range(0.0..=1.0)).collect())
        .collect()
}

/// Runs `commands` from `start` and returns every state, the start included.
pub fn trajectory(
    backend: &mut dyn PhysicsBackend,
    start: &BodyState,
    commands: &[Vec<f64>],
) -> Result<Vec<BodyState>, PhysicsError> {
    backend.reset(start)?;
    let mut states = Vec::with_capacity(commands.len() + 1);
    states.push(backend.state());
    for thrust in commands {
        backend.step(thrust)?;
        states.push(backend.state());
    }
    Ok(states)
}

/// Runs `sequences` random thrust sequences of `steps` steps from rest at
/// the origin on every available backend and compares each with `ode`.
pub fn crosscheck(
    model: &RigidBodyModel,
    settings: &StepSettings,
    sequences: usize,
    steps: usize,
    seed: u64,
) -> Result<CrosscheckReport, PhysicsError> {
    let others: Vec<BackendKind> = BackendKind::available()
        .into_iter()
        .filter(|k| *k != BackendKind::Ode)
        .collect();
    let mut reference = create_backend(BackendKind::Ode, model, settings)?;
    let mut backends = others
        .iter()
        .map(|&k| create_backend(k, model, settings))
        .collect::<Result<Vec<_>, _>>()?;
    let mut worst = vec![Deviation::ZERO; others.len()];
    let start = BodyState::default();
    for index in 0..sequences {
        let commands = random_thrust_sequence(seed, index as u64, steps, model.thrusters.len());
        let expected = trajectory(reference.as_mut(), &start, &commands)?;
        for (backend, worst) in backends.iter_mut().zip(&mut worst) {
            let got = trajectory(backend.as_mut(), &start, &commands)?;
            for (a, b) in expected.iter().zip(&got) {
                *worst = worst.max(Deviation::between(a, b));
            }
        }
    }
    let comparisons = others
        .into_iter()
        .zip(worst)
        .map(|(backend, deviation)| {
            let tolerance = tolerance(backend);
            BackendComparison {
                backend,
                deviation,
                tolerance,
                passed: deviation.within(&tolerance),
            }
        })
        .collect();
    Ok(CrosscheckReport {
        sequences,
        steps,
        seed,
        comparisons,
    })
}

/// rapier vs `ode`: see the derivation in the test `rapier_agrees_with_ode_within_stated_tolerance`.
pub const RAPIER_TOLERANCE: Tolerance = Tolerance {
    position: f64::INFINITY,
    heading: f64::INFINITY,
    velocity: f64::INFINITY,
};
