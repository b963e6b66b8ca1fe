//! The PSA control problem as an [`Evaluator`] for the search algorithms.

use std::ops::Range;
use std::sync::{Arc, OnceLock};

use anyhow::Result;

use crate::evolution::{evaluate_each, evaluate_each_part, Evaluator, Part};
use crate::network::{Network, NetworkSet};
use crate::numeric::SimdLevel;
use crate::physics::BackendKind;
use crate::psa::batch::LANES;
use crate::psa::cuda::{self, HostTrials, KernelPart, TrialFlier};
use crate::psa::ode_lockstep::ODE_LOCKSTEP;
use crate::psa::{BatchRunner, OdeLockstepRunner, PsaSettings, Task, TrialRunner, INPUT_COUNT, THRUSTER_COUNT};
use crate::rng::{Stream, StreamFamily};

/// The environment variable that picks the evaluation path: `scalar` (one
/// network at a time, on `ode` one world per network), a SIMD level
/// (`portable`, `avx2`, `avx512`) for `native`'s batched path, or
/// `kernel-host` for `native` flown by the cuda path's kernel built for
/// the host (the GPU path's plumbing without a GPU, slowly); unset, the
/// best level of the CPU, and on `ode` the lockstep path. It changes speed
/// only: every path gives the same results, bit for bit.
pub const SIMD_VARIABLE: &str = "PSA_ESP_SIMD";

/// The [`SIMD_VARIABLE`] value for the cuda kernel built for the host.
pub const KERNEL_ON_HOST: &str = "kernel-host";

/// Networks per batch on the cuda kernel: more than any run asks at once,
/// so that a run's generation goes to the device in one launch.
pub const CUDA_BATCH: usize = 1 << 20;

/// What every `native` evaluator of the process flies its trials on, once
/// [`fly_trials_on`] has set it.
static FLIER: OnceLock<Arc<dyn TrialFlier>> = OnceLock::new();

/// Makes every [`PsaEvaluator`] made from now on with the `native`
/// backend fly its trials on `flier` (`--backend cuda`: the GPU). Like
/// [`SIMD_VARIABLE`], it changes speed only: the kernel computes the
/// batched path's results bit for bit. A second call keeps the first.
pub fn fly_trials_on(flier: Arc<dyn TrialFlier>) {
    let _ = FLIER.set(flier);
}

/// Scores a network by its fitness on a task (in % of the theoretical
/// maximum, the mean over `settings.trials` trials). Each worker thread
/// owns its physics worlds, reused between evaluations. On the `native`
/// backend, networks are evaluated in lockstep by the batched SIMD path
/// ([`BatchRunner`]); on `ode`, in lockstep as bodies of one world
/// ([`OdeLockstepRunner`]). Both give the scalar path's results bit for bit.
#[derive(Debug, Clone)]
pub struct PsaEvaluator {
    settings: PsaSettings,
    task: Task,
    /// The batched runner, built once and used by every worker thread.
    batch: Option<BatchRunner>,
    /// Whether `ode` runs batches in lockstep (each worker its own world).
    ode_lockstep: bool,
    /// The cuda kernel's flier (a GPU, or the host build), where one is set (`native` only).
    kernel: Option<Arc<dyn TrialFlier>>,
}

/// A worker thread's state: its runners, which own the thread's physics
/// worlds, each made when first needed. The batched `native` runner holds
/// no state of its own and is shared by every thread.
pub struct PsaWorker {
    scalar: Option<TrialRunner>,
    lockstep: Option<OdeLockstepRunner>,
}

impl PsaEvaluator {
    fn scalar<'w>(&self, worker: &'w mut PsaWorker) -> Result<&'w mut TrialRunner> {
        if worker.scalar.is_none() {
            worker.scalar = Some(TrialRunner::new(&self.settings, self.task)?);
        }
        Ok(worker.scalar.as_mut().expect("just made"))
    }
}

impl PsaEvaluator {
    /// An evaluator of `task`; fails on invalid settings.
    pub fn new(settings: PsaSettings, task: Task) -> Result<PsaEvaluator> {
        // Building one runner checks every setting (and random init vs task) up front.
        TrialRunner::new(&settings, task)?;
        let batch = match settings.backend {
            BackendKind::Native => Some(BatchRunner::new(&settings, task)?),
            _ => None,
        };
        let ode_lockstep = OdeLockstepRunner::supports(&settings);
        let kernel = FLIER.get().filter(|_| settings.backend == BackendKind::Native).cloned();
        let evaluator = PsaEvaluator {
            settings,
            task,
            batch,
            ode_lockstep,
            kernel,
        };
        Ok(match std::env::var(SIMD_VARIABLE) {
            Err(_) => evaluator,
            Ok(choice) if choice == "scalar" => evaluator.with_batching(None).with_ode_lockstep(false),
            Ok(choice) if choice == KERNEL_ON_HOST => evaluator.with_kernel_on_host(),
            Ok(choice) => {
                evaluator.with_batching(Some(choice.parse().map_err(|e| {
                    anyhow::anyhow!("{SIMD_VARIABLE}={choice:?}: {e} (or scalar for the scalar path)")
                })?))
            }
        })
    }

    /// The same evaluator on `native` with the batched path on `level`, or
    /// with `None` the scalar reference: for benchmarks and cross-checks
    /// (every choice gives the same results). Other backends stay scalar.
    pub fn with_batching(mut self, level: Option<SimdLevel>) -> PsaEvaluator {
        self.batch = match (self.batch.take(), level) {
            (Some(batch), Some(level)) => Some(batch.with_level(level)),
            (Some(_), None) => None,
            (None, _) => BatchRunner::new(&self.settings, self.task)
                .ok()
                .zip(level)
                .map(|(b, l)| b.with_level(l)),
        };
        self
    }

    /// The same evaluator on `native` flying its trials through the cuda
    /// kernel built for the host (where no GPU is set already), for
    /// checks (the same results, slowly). Other backends are unchanged.
    pub fn with_kernel_on_host(mut self) -> PsaEvaluator {
        if self.settings.backend == BackendKind::Native && self.kernel.is_none() {
            self.kernel = Some(Arc::new(HostTrials));
        }
        self
    }

    /// The same evaluator with `ode`'s lockstep path on (where the settings
    /// allow it: see [`OdeLockstepRunner::supports`]) or off (one world per
    /// network, the reference): for benchmarks and cross-checks (both give
    /// the same results). Other backends are unchanged.
    pub fn with_ode_lockstep(mut self, on: bool) -> PsaEvaluator {
        self.ode_lockstep = on && OdeLockstepRunner::supports(&self.settings);
        self
    }
}

impl Evaluator for PsaEvaluator {
    type Worker = PsaWorker;
    fn inputs(&self) -> usize {
        INPUT_COUNT
    }
    fn outputs(&self) -> usize {
        THRUSTER_COUNT
    }
    fn worker(&self) -> Result<PsaWorker> {
        // ODE worlds belong to their thread: make the runners here (or later, on it).
        Ok(PsaWorker {
            scalar: if self.batch.is_none() && !self.ode_lockstep {
                Some(TrialRunner::new(&self.settings, self.task)?)
            } else {
                None
            },
            lockstep: None,
        })
    }
    fn evaluate(&self, worker: &mut PsaWorker, network: &Network, rng: &mut Stream) -> Result<f64> {
        Ok(self.scalar(worker)?.evaluate(network, rng)?)
    }
    fn batch_size(&self) -> usize {
        if self.kernel.is_some() {
            CUDA_BATCH
        } else if self.batch.is_some() {
            LANES
        } else if self.ode_lockstep {
            ODE_LOCKSTEP
        } else {
            1
        }
    }
    fn narrowest_batch(&self) -> usize {
        if self.kernel.is_some() {
            // A generation goes to the device whole, not cut between the threads.
            return CUDA_BATCH;
        }
        self.batch.as_ref().map_or(1, BatchRunner::narrowest_block)
    }
    fn takes_parts_together(&self) -> bool {
        self.kernel.is_some()
    }
    fn evaluate_parts<S: NetworkSet + ?Sized>(
        &self,
        worker: &mut PsaWorker,
        parts: &[Part<'_, S>],
    ) -> Vec<Result<Vec<f64>>> {
        let Some(flier) = &self.kernel else {
            return evaluate_each_part(self, worker, parts);
        };
        // Every part's trials in one flight of the kernel: one GPU launch.
        let mut rngs: Vec<Vec<Stream>> = parts
            .iter()
            .map(|part| part.range.clone().map(|j| part.streams.stream(j)).collect())
            .collect();
        let mut kernel_parts: Vec<KernelPart<'_, S>> = parts
            .iter()
            .zip(&mut rngs)
            .map(|(part, rngs)| KernelPart {
                networks: part.networks,
                range: part.range.clone(),
                rngs,
            })
            .collect();
        match cuda::evaluate_parts_with(&self.settings, self.task, &mut kernel_parts, |batch| flier.fly(batch)) {
            Ok(results) => results.into_iter().map(|r| Ok(r?)).collect(),
            Err(e) => {
                let message = e.to_string();
                parts.iter().map(|_| Err(anyhow::anyhow!("{message}"))).collect()
            }
        }
    }
    fn evaluate_batch<S: NetworkSet + ?Sized>(
        &self,
        worker: &mut PsaWorker,
        networks: &S,
        range: Range<usize>,
        streams: &StreamFamily,
    ) -> Result<Vec<f64>> {
        let rngs = || -> Vec<Stream> { range.clone().map(|j| streams.stream(j)).collect() };
        if let Some(flier) = &self.kernel {
            let (settings, task) = (&self.settings, self.task);
            return Ok(cuda::evaluate_with(
                settings,
                task,
                networks,
                range.clone(),
                &mut rngs(),
                |batch| flier.fly(batch),
            )?);
        }
        if let Some(batch) = &self.batch {
            return Ok(batch.evaluate(networks, range.clone(), &mut rngs())?);
        }
        if self.ode_lockstep {
            if worker.lockstep.is_none() {
                worker.lockstep = Some(OdeLockstepRunner::new(&self.settings, self.task)?);
            }
            let lockstep = worker.lockstep.as_mut().expect("just made");
            return Ok(lockstep.evaluate(networks, range.clone(), &mut rngs())?);
        }
        evaluate_each(self, worker, networks, range, streams)
    }
}
