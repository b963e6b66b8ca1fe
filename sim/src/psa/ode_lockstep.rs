//! The lockstep evaluation path on ODE: a batch of networks flies the PSA
//! together, one body per network in one ODE world ([`OdeFleet`]), one
//! `dWorldStep` per step for all of them.
//!
//! Every network runs the scalar path's trial loop ([`TrialRunner`] on
//! `ode`; both fly `fly_steps` of `flight.rs`), operation for operation,
//! and ODE bodies built, pushed and read by the same functions; each body
//! is an island of its own, which ODE steps from that body's state and
//! forces alone. Each network draws its random
//! starts and noise seeds from its own stream in the scalar path's order
//! (trial by trial: start, then noise seed). So its fitness is bit-identical
//! to the scalar path's; a test holds them to that on every task, with
//! noise and random starts.
//!
//! The fleet checks every command and every body's state before each step,
//! as the scalar path's backend does, and refuses the step with the error
//! the scalar path would raise, naming the body (body `i` flies network
//! `i` of the batch). None is possible with validated settings and finite
//! weights (see `tests/batch.rs`).

use std::borrow::Cow;
use std::ops::Range;

use multiversion::multiversion;

use super::flight::{fly_steps, Lane};
use super::trial::{mean_of_trials, TrialRunner};
use super::{PsaError, PsaSettings, Task};
use crate::numeric::NoiseSource;
use crate::physics::{BackendKind, OdeFleet};
use esp_neuroevolution::network::{Network, NetworkSet};
use esp_neuroevolution::rng::Stream;

/// Networks flown in one ODE world at a time. From 8 bodies a world up,
/// the cost per network-step is flat (`psa-esp bench`, docs/performance.md);
/// 32 cuts the baseline ESP's 400 networks a generation into 12 batches and
/// a tail of 16, which two threads share evenly.
pub const ODE_LOCKSTEP: usize = 32;

/// Evaluates batches of networks on one task on ODE, in lockstep (see the
/// module documentation). Owns an ODE world: not `Send`, one per thread.
pub struct OdeLockstepRunner {
    settings: PsaSettings,
    task: Task,
    fleet: OdeFleet,
}

impl OdeLockstepRunner {
    /// Whether `settings` can be flown in lockstep: the `ode` backend, with
    /// step settings an [`OdeFleet`] supports.
    pub fn supports(settings: &PsaSettings) -> bool {
        settings.backend == BackendKind::Ode && OdeFleet::supports(&settings.physics)
    }

    /// A runner for `task`; fails on invalid settings, or settings it
    /// cannot fly (see [`OdeLockstepRunner::supports`]).
    pub fn new(settings: &PsaSettings, task: Task) -> Result<OdeLockstepRunner, PsaError> {
        let settings = &settings.for_task(task)?;
        if !Self::supports(settings) {
            return Err(PsaError::Setting(format!(
                "the ODE lockstep path runs the ode backend without QuickStep and a Plane2D joint together, not backend {} with {:?}",
                settings.backend, settings.physics
            )));
        }
        Ok(OdeLockstepRunner {
            fleet: OdeFleet::new(&settings.body.model()?, &settings.physics, ODE_LOCKSTEP)?,
            settings: settings.clone(),
            task,
        })
    }

    /// The fitness of networks `range` of `networks` (in % of the
    /// theoretical maximum, the mean over `settings.trials` trials):
    /// exactly what [`TrialRunner::evaluate`] gives network
    /// `range.start + i` with stream `rngs[i]`.
    ///
    /// # Panics
    /// If `range` and `rngs` differ in length, or `range` reaches past the
    /// networks.
    pub fn evaluate<S: NetworkSet + ?Sized>(
        &mut self,
        networks: &S,
        range: Range<usize>,
        rngs: &mut [Stream],
    ) -> Result<Vec<f64>, PsaError> {
        assert_eq!(range.len(), rngs.len(), "one stream per network");
        let batch: Vec<Cow<'_, Network>> = range.map(|j| networks.network(j)).collect();
        for network in &batch {
            TrialRunner::check_network(network)?;
        }
        if batch.is_empty() {
            return Ok(Vec::new());
        }
        self.fly_batch(&batch, rngs)
    }

    /// Flies every trial of `batch` in lockstep; returns the fitness of each network.
    fn fly_batch(&mut self, batch: &[Cow<'_, Network>], rngs: &mut [Stream]) -> Result<Vec<f64>, PsaError> {
        let s = &self.settings;
        self.fleet.resize(batch.len())?;
        let maximum = s.fitness.maximum(s.steps);
        // trials[lane * s.trials + t]: lane's fitness in trial t.
        let mut trials = vec![0.0; batch.len() * s.trials];
        for t in 0..s.trials {
            let mut lanes = Vec::with_capacity(batch.len());
            for (l, (network, rng)) in batch.iter().zip(rngs.iter_mut()).enumerate() {
                let (start, target) = s.tasks.start_and_target(self.task, s.random_init, rng);
                self.fleet.reset(l, &start)?;
                let noise = NoiseSource::new(s.noise.draw_seed(rng));
                lanes.push(Lane::new(network, &target, noise, self.fleet.planar_state(l)));
            }
            let fly = if s.noise.is_active() { fly_noisy } else { fly_clean };
            fly(s, &mut self.fleet, &mut lanes)?;
            for (l, lane) in lanes.iter().enumerate() {
                trials[l * s.trials + t] = 100.0 * lane.points / maximum;
            }
        }
        Ok(trials.chunks_exact(s.trials).map(mean_of_trials).collect())
    }
}

/// Declares `$name`: one trial of every body of the fleet from its current
/// state, body `l` flown as `lanes[l]` says, with noise or without
/// ([`fly_steps`], the scalar path's loop too); the points add up in the
/// lanes. Compiled as the scalar path's trial loop is (see `trial_loop` in
/// [`super::trial`]): apart with and without noise, and with AVX2 and FMA
/// where the CPU has them (the same results either way).
macro_rules! lockstep_loop {
    ($name:ident, $noisy:expr, $avx512:tt, $avx2:tt) => {
        #[multiversion(targets($avx2))]
        fn $name<'n>(s: &PsaSettings, fleet: &mut OdeFleet, lanes: &mut [Lane<'n>]) -> Result<(), PsaError> {
            fly_steps::<$noisy, _>(s, fleet, lanes, None)
        }
    };
}

crate::with_simd_targets!(lockstep_loop!(fly_clean, false,));
crate::with_simd_targets!(lockstep_loop!(fly_noisy, true,));
