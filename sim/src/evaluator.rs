//! The PSA control problem as an [`Evaluator`] for the search algorithms.

use std::ops::Range;
use std::sync::Arc;

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

/// Networks per batch on the cuda kernel: more than any run asks at once,
/// so that a run's generation goes to the device in one launch.
pub const CUDA_BATCH: usize = 1 << 20;

/// How a [`PsaEvaluator`] flies its trials, named by its caller. Every path
/// gives the same results, bit for bit: the choice changes speed only.
#[derive(Debug, Clone, Default)]
pub enum EvalPath {
    /// The fastest path of the backend: on `native` the batched path at the
    /// processor's best SIMD level, on `ode` the lockstep path where the
    /// settings allow it, else one network at a time.
    #[default]
    Fastest,
    /// One network at a time (on `ode` one world per network): the reference.
    Scalar,
    /// `native`'s batched path at this SIMD level.
    Simd(SimdLevel),
    /// `ode`'s lockstep path: a batch of networks as bodies of one world.
    OdeLockstep,
    /// `native`'s trials flown by the cuda kernel built for the host: the
    /// GPU path's plumbing without a GPU, slowly.
    KernelOnHost,
    /// `native`'s trials flown by a kernel flier (`--backend cuda`: a GPU).
    Kernel(Arc<dyn TrialFlier>),
}

impl EvalPath {
    /// The names `EvalPath` is read from (its `FromStr`): every path but
    /// [`EvalPath::Kernel`], which needs a device.
    pub const NAMES: [&'static str; 7] = [
        "fastest",
        "scalar",
        "portable",
        "avx2",
        "avx512",
        "ode-lockstep",
        "kernel-host",
    ];

    /// The backend the path flies on, if it needs one.
    fn backend(&self) -> Option<BackendKind> {
        match self {
            EvalPath::Fastest | EvalPath::Scalar => None,
            EvalPath::OdeLockstep => Some(BackendKind::Ode),
            EvalPath::Simd(_) | EvalPath::KernelOnHost | EvalPath::Kernel(_) => Some(BackendKind::Native),
        }
    }
}

impl std::str::FromStr for EvalPath {
    type Err = String;
    fn from_str(name: &str) -> Result<EvalPath, String> {
        match name {
            "fastest" => Ok(EvalPath::Fastest),
            "scalar" => Ok(EvalPath::Scalar),
            "ode-lockstep" => Ok(EvalPath::OdeLockstep),
            "kernel-host" => Ok(EvalPath::KernelOnHost),
            _ => name.parse().map(EvalPath::Simd).map_err(|_| {
                format!(
                    "unknown evaluation path {name:?} (expected one of {})",
                    EvalPath::NAMES.join(", ")
                )
            }),
        }
    }
}

/// Each trial's score (in % of the theoretical maximum) of `network` on
/// `task` under `settings`, with `rng` (as [`TrialRunner::evaluate_trials`]
/// gives them, bit for bit): on `path`'s kernel (a GPU, or the host build)
/// in one launch where it has one, else on the scalar path. The robustness
/// tests' many trials of a champion.
pub fn trial_scores(
    settings: &PsaSettings,
    task: Task,
    network: &Network,
    rng: &mut Stream,
    path: &EvalPath,
) -> Result<Vec<f64>> {
    let flier: Arc<dyn TrialFlier> = match path {
        EvalPath::Kernel(flier) => flier.clone(),
        EvalPath::KernelOnHost => Arc::new(HostTrials),
        _ => return Ok(TrialRunner::new(settings, task)?.evaluate_trials(network, rng)?),
    };
    Ok(cuda::trial_scores_with(settings, task, network, rng, |batch| {
        flier.fly(batch)
    })?)
}

/// Scores a network by its fitness on a task (in % of the theoretical
/// maximum, the mean over `settings.trials` trials), on the [`EvalPath`] it
/// was made with: on `native` the batched SIMD path ([`BatchRunner`]) or a
/// kernel, on `ode` the lockstep path ([`OdeLockstepRunner`]), or one
/// network at a time. Each worker thread owns its physics worlds, reused
/// between evaluations. Every path gives the scalar path's results bit for
/// bit.
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
    /// An evaluator of `task` on `path`; fails on invalid settings, and on
    /// a path the backend does not have (a SIMD level or a kernel on
    /// anything but `native`, the lockstep path on anything but `ode` with
    /// step settings it supports).
    pub fn new(settings: PsaSettings, task: Task, path: &EvalPath) -> Result<PsaEvaluator> {
        // Building one runner checks every setting (and random init vs task) up front.
        TrialRunner::new(&settings, task)?;
        if let Some(backend) = path.backend().filter(|&b| b != settings.backend) {
            anyhow::bail!(
                "the evaluation path {path:?} runs on the {backend} backend, not on {}",
                settings.backend
            );
        }
        let native = settings.backend == BackendKind::Native;
        let batch = match path {
            EvalPath::Scalar | EvalPath::OdeLockstep => None,
            EvalPath::Simd(level) => Some(BatchRunner::new(&settings, task)?.with_level(*level)),
            EvalPath::Fastest | EvalPath::KernelOnHost | EvalPath::Kernel(_) if native => {
                Some(BatchRunner::new(&settings, task)?)
            }
            EvalPath::Fastest | EvalPath::KernelOnHost | EvalPath::Kernel(_) => None,
        };
        let ode_lockstep = match path {
            EvalPath::Fastest => OdeLockstepRunner::supports(&settings),
            EvalPath::OdeLockstep => {
                OdeLockstepRunner::new(&settings, task)?;
                true
            }
            _ => false,
        };
        let kernel: Option<Arc<dyn TrialFlier>> = match path {
            EvalPath::KernelOnHost => Some(Arc::new(HostTrials)),
            EvalPath::Kernel(flier) => Some(flier.clone()),
            _ => None,
        };
        Ok(PsaEvaluator {
            settings,
            task,
            batch,
            ode_lockstep,
            kernel,
        })
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
        if self.kernel.is_none() && self.batch.is_none() && !self.ode_lockstep {
            return evaluate_each(self, worker, networks, range, streams);
        }
        let mut rngs: Vec<Stream> = range.clone().map(|j| streams.stream(j)).collect();
        self.evaluate_with_streams(worker, networks, range, &mut rngs)
    }
}

impl PsaEvaluator {
    /// The fitness of networks `range` of `networks`, network
    /// `range.start + i` with the stream `rngs[i]` (any streams, such as
    /// one per network from a seed of its own), on this evaluator's path:
    /// what [`Evaluator::evaluate`] gives each with its stream, bit for bit.
    /// [`Evaluator::evaluate_batch`] is this with the streams of a
    /// [`StreamFamily`]; a caller evaluating networks with streams of its
    /// own (the Python binding's `evaluate`, which flies every network as
    /// `psa-esp replay` does) cuts them into [`Evaluator::batch_size`]
    /// pieces, each with its worker.
    ///
    /// # Panics
    /// If `range` and `rngs` differ in length.
    pub fn evaluate_with_streams<S: NetworkSet + ?Sized>(
        &self,
        worker: &mut PsaWorker,
        networks: &S,
        range: Range<usize>,
        rngs: &mut [Stream],
    ) -> Result<Vec<f64>> {
        assert_eq!(range.len(), rngs.len(), "one stream per network");
        if let Some(flier) = &self.kernel {
            let (settings, task) = (&self.settings, self.task);
            return Ok(cuda::evaluate_with(settings, task, networks, range, rngs, |batch| {
                flier.fly(batch)
            })?);
        }
        if let Some(batch) = &self.batch {
            return Ok(batch.evaluate(networks, range, rngs)?);
        }
        if self.ode_lockstep {
            if worker.lockstep.is_none() {
                worker.lockstep = Some(OdeLockstepRunner::new(&self.settings, self.task)?);
            }
            let lockstep = worker.lockstep.as_mut().expect("just made");
            return Ok(lockstep.evaluate(networks, range, rngs)?);
        }
        range
            .zip(rngs)
            .map(|(j, rng)| self.evaluate(worker, &networks.network(j), rng))
            .collect()
    }
}
