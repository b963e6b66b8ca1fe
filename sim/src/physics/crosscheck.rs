//! Cross-checking backends: the same seeded random thrust sequences on every
//! backend, and the largest difference of each against `ode`.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::{
    create_backend, BackendKind, BodyState, NativeBackend, PhysicsBackend, PhysicsError, RigidBodyModel, RotationRule,
    StepSettings,
};

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
    /// What it is held to: `ode` itself, or (rapier) ODE's model with the
    /// backend's own rotation rule; see `RAPIER_TOLERANCE`.
    pub reference: &'static str,
    /// Its largest differences from the reference.
    pub deviation: Deviation,
    /// Its largest differences from `ode` itself (equal to `deviation`
    /// when the reference is `ode`).
    pub raw_vs_ode: Deviation,
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
    /// Seed of the sequences (a string in JSON: see [`crate::io::u64_string`]).
    #[serde(serialize_with = "crate::io::u64_string::serialize")]
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
    let mut states = Vec::with_capacity(commands.len() + 1);
    for_each_state(backend, start, commands.iter().map(Vec::as_slice), |s| {
        states.push(*s);
        Ok::<_, PhysicsError>(())
    })?;
    Ok(states)
}

/// Runs `commands` from `start`, handing every state, the start included,
/// to `visit` as it comes (so that a long run needs no memory for them).
pub fn for_each_state<'a, E: From<PhysicsError>>(
    backend: &mut dyn PhysicsBackend,
    start: &BodyState,
    commands: impl IntoIterator<Item = &'a [f64]>,
    mut visit: impl FnMut(&BodyState) -> Result<(), E>,
) -> Result<(), E> {
    backend.reset(start)?;
    visit(&backend.state())?;
    for thrust in commands {
        backend.step(thrust)?;
        visit(&backend.state())?;
    }
    Ok(())
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
    let mut ode = create_backend(BackendKind::Ode, model, settings)?;
    let mut linearized = NativeBackend::with_rotation_rule(model, settings, RotationRule::Linearized)?;
    let mut backends = others
        .iter()
        .map(|&k| create_backend(k, model, settings))
        .collect::<Result<Vec<_>, _>>()?;
    let mut worst = vec![(Deviation::ZERO, Deviation::ZERO); others.len()];
    let start = BodyState::default();
    let max = |worst: &mut Deviation, a: &[BodyState], b: &[BodyState]| {
        for (p, q) in a.iter().zip(b) {
            *worst = worst.max(Deviation::between(p, q));
        }
    };
    for index in 0..sequences {
        let commands = random_thrust_sequence(seed, index as u64, steps, model.thrusters.len());
        let expected = trajectory(ode.as_mut(), &start, &commands)?;
        let expected_linearized = trajectory(&mut linearized, &start, &commands)?;
        for ((backend, kind), (worst, raw)) in backends.iter_mut().zip(&others).zip(&mut worst) {
            let got = trajectory(backend.as_mut(), &start, &commands)?;
            max(raw, &expected, &got);
            let reference = if *kind == BackendKind::Rapier {
                &expected_linearized
            } else {
                &expected
            };
            max(worst, reference, &got);
        }
    }
    let comparisons = others
        .into_iter()
        .zip(worst)
        .map(|(backend, (deviation, raw_vs_ode))| {
            let tolerance = tolerance(backend);
            BackendComparison {
                backend,
                reference: if backend == BackendKind::Rapier {
                    RAPIER_REFERENCE
                } else {
                    "ode"
                },
                deviation,
                raw_vs_ode,
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

/// What rapier is compared with: see [`RAPIER_TOLERANCE`].
pub const RAPIER_REFERENCE: &str = "ode model, rapier's rotation rule";

/// rapier's tolerance, against ODE's model with rapier's rotation rule.
///
/// rapier integrates everything as ODE's `dWorldStep` does (semi-implicit
/// Euler; omega agrees with ODE to 1e-14) except the rotation: per step its
/// angle advances by atan(w dt), ODE's by 2 atan(w dt / 2), a difference of
/// about (w dt)^3 / 4. Random thrust sequences spin the body up to
/// |w| of about 15 rad/s, so at dt = 0.05 s that is about 0.1 rad per step:
/// after 500 steps headings differ by up to pi and positions by metres.
/// No constant tolerance on raw ODE-vs-rapier differences would both pass
/// and catch a fault, so rapier is held, to rounding (1e-9, as `native`),
/// to ODE's model run with rapier's rotation rule: the `native` backend
/// with [`RotationRule::Linearized`], which differs from the `native`
/// backend that matches ODE to 1e-11 in that one line only. Together the
/// two checks pin rapier's mass, inertia, forces, torques and integrator to
/// ODE's; the raw differences from ODE are reported beside them.
pub const RAPIER_TOLERANCE: Tolerance = NATIVE_TOLERANCE;
