//! The PSA control problem as an [`Evaluator`] for the search algorithms.

use std::ops::Range;
use std::sync::Arc;

use anyhow::Result;

use strum::VariantArray;

use crate::named::Named;
use crate::numeric::SimdLevel;
use crate::physics::BackendKind;
use crate::psa::batch::LANES;
use crate::psa::cuda::{self, HostTrials, KernelPart, TrialFlier};
use crate::psa::ode_lockstep::ODE_LOCKSTEP;
use crate::psa::{BatchRunner, OdeLockstepRunner, PsaSettings, Task, TrialRunner, INPUT_COUNT, THRUSTER_COUNT};
use esp_neuroevolution::network::{Network, NetworkSet};
use esp_neuroevolution::rng::{Stream, StreamFamily};
use esp_neuroevolution::{evaluate_each, evaluate_each_part, Evaluator, Part};

/// Networks per batch on the cuda kernel: more than any run asks at once,
/// so that a run's generation goes to the device in one launch.
pub const CUDA_BATCH: usize = 1 << 20;

/// How a [`PsaEvaluator`] flies its trials, named by its caller. Every path
/// gives the same results, bit for bit: the choice changes speed only.
/// [`EvalPathKind`] lists its variants, so that a new one must be given
/// its names ([`EvalPath::readable`]) to compile.
#[derive(Debug, Clone, Default, strum::EnumDiscriminants)]
#[strum_discriminants(name(EvalPathKind), derive(strum::VariantArray))]
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
    /// The paths of `kind` that can be read by name: every SIMD level of
    /// the batched path, none of [`EvalPath::Kernel`], which needs a device.
    pub fn readable(kind: EvalPathKind) -> Vec<EvalPath> {
        match kind {
            EvalPathKind::Fastest => vec![EvalPath::Fastest],
            EvalPathKind::Scalar => vec![EvalPath::Scalar],
            EvalPathKind::Simd => SimdLevel::VARIANTS.iter().map(|&level| EvalPath::Simd(level)).collect(),
            EvalPathKind::OdeLockstep => vec![EvalPath::OdeLockstep],
            EvalPathKind::KernelOnHost => vec![EvalPath::KernelOnHost],
            EvalPathKind::Kernel => Vec::new(),
        }
    }

    /// Every path that can be read by name ([`EvalPath::readable`]), in
    /// the order of the variants.
    pub fn all_readable() -> Vec<EvalPath> {
        EvalPathKind::VARIANTS
            .iter()
            .flat_map(|&kind| EvalPath::readable(kind))
            .collect()
    }

    /// The names `EvalPath` is read from (its `FromStr`): those of
    /// [`EvalPath::all_readable`]; a SIMD level by its name.
    pub fn names() -> Vec<&'static str> {
        EvalPath::all_readable().iter().map(EvalPath::name).collect()
    }

    /// The path's name, as [`EvalPath::names`] spells it (`"kernel"` for
    /// [`EvalPath::Kernel`], which has none to be read from).
    pub fn name(&self) -> &'static str {
        match self {
            EvalPath::Fastest => "fastest",
            EvalPath::Scalar => "scalar",
            EvalPath::Simd(level) => level.name(),
            EvalPath::OdeLockstep => "ode-lockstep",
            EvalPath::KernelOnHost => "kernel-host",
            EvalPath::Kernel(_) => "kernel",
        }
    }

    /// The backend the path flies on, if it needs one.
    pub fn backend(&self) -> Option<BackendKind> {
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
        EvalPath::all_readable()
            .into_iter()
            .find(|path| path.name() == name)
            .ok_or_else(|| {
                format!(
                    "unknown evaluation path {name:?} (expected one of {})",
                    EvalPath::names().join(", ")
                )
            })
    }
}

/// Each trial's score (in % of the theoretical maximum) of `network` on
/// `task` under `settings`, with `rng` (as [`TrialRunner::evaluate_trials`]
/// gives them, bit for bit), on `path` ([`PsaEvaluator::trial_scores`]):
/// the robustness tests' many trials of a champion.
pub fn trial_scores(
    settings: &PsaSettings,
    task: Task,
    network: &Network,
    rng: &mut Stream,
    path: &EvalPath,
) -> Result<Vec<f64>> {
    PsaEvaluator::new(settings.clone(), task, path)?.trial_scores(network, rng)
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
    /// The path, resolved once from the [`EvalPath`] and the backend.
    route: Route,
}

/// How a [`PsaEvaluator`] flies its networks: its [`EvalPath`] resolved
/// against the settings' backend, once, when it is made.
#[derive(Debug, Clone)]
enum Route {
    /// One network at a time, each worker with its own [`TrialRunner`].
    Scalar,
    /// `native`'s batched path, the runner shared by every worker thread.
    Batched(Box<BatchRunner>),
    /// `ode`'s lockstep path, each worker with its own world.
    OdeLockstep,
    /// The cuda kernel's flier (a GPU, or the host build), on `native`.
    Kernel(Arc<dyn TrialFlier>),
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
        let kernel = |flier: Arc<dyn TrialFlier>| -> Result<Route> {
            // The batched runner checks the settings as the kernel's host side reads them.
            BatchRunner::new(&settings, task)?;
            Ok(Route::Kernel(flier))
        };
        let route = match path {
            EvalPath::Scalar => Route::Scalar,
            EvalPath::Simd(level) => Route::Batched(Box::new(BatchRunner::new(&settings, task)?.with_level(*level))),
            EvalPath::OdeLockstep => {
                OdeLockstepRunner::new(&settings, task)?;
                Route::OdeLockstep
            }
            EvalPath::KernelOnHost => kernel(Arc::new(HostTrials))?,
            EvalPath::Kernel(flier) => kernel(flier.clone())?,
            EvalPath::Fastest => match settings.backend {
                BackendKind::Native => Route::Batched(Box::new(BatchRunner::new(&settings, task)?)),
                BackendKind::Ode if OdeLockstepRunner::supports(&settings) => Route::OdeLockstep,
                BackendKind::Ode | BackendKind::Rapier => Route::Scalar,
            },
        };
        Ok(PsaEvaluator { settings, task, route })
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
        let scalar = match self.route {
            Route::Scalar => Some(TrialRunner::new(&self.settings, self.task)?),
            Route::Batched(_) | Route::OdeLockstep | Route::Kernel(_) => None,
        };
        Ok(PsaWorker { scalar, lockstep: None })
    }
    fn evaluate(&self, worker: &mut PsaWorker, network: &Network, rng: &mut Stream) -> Result<f64> {
        Ok(self.scalar(worker)?.evaluate(network, rng)?)
    }
    fn batch_size(&self) -> usize {
        match self.route {
            Route::Scalar => 1,
            Route::Batched(_) => LANES,
            Route::OdeLockstep => ODE_LOCKSTEP,
            Route::Kernel(_) => CUDA_BATCH,
        }
    }
    fn narrowest_batch(&self) -> usize {
        match &self.route {
            Route::Scalar | Route::OdeLockstep => 1,
            Route::Batched(batch) => batch.narrowest_block(),
            // A generation goes to the device whole, not cut between the threads.
            Route::Kernel(_) => CUDA_BATCH,
        }
    }
    fn takes_parts_together(&self) -> bool {
        match self.route {
            Route::Scalar | Route::Batched(_) | Route::OdeLockstep => false,
            Route::Kernel(_) => true,
        }
    }
    fn evaluate_parts<S: NetworkSet + ?Sized>(
        &self,
        worker: &mut PsaWorker,
        parts: &[Part<'_, S>],
    ) -> Vec<Result<Vec<f64>>> {
        let flier = match &self.route {
            Route::Scalar | Route::Batched(_) | Route::OdeLockstep => return evaluate_each_part(self, worker, parts),
            Route::Kernel(flier) => flier,
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
        match self.route {
            Route::Scalar => evaluate_each(self, worker, networks, range, streams),
            Route::Batched(_) | Route::OdeLockstep | Route::Kernel(_) => {
                let mut rngs: Vec<Stream> = range.clone().map(|j| streams.stream(j)).collect();
                self.evaluate_with_streams(worker, networks, range, &mut rngs)
            }
        }
    }
}

impl PsaEvaluator {
    /// Each trial's score (in % of the theoretical maximum) of `network`
    /// with `rng`, as [`TrialRunner::evaluate_trials`] gives them, bit for
    /// bit: on the batched path side by side, one trial per lane
    /// ([`BatchRunner::evaluate_trials`]); on a kernel in one launch; else
    /// one trial after another.
    pub fn trial_scores(&self, network: &Network, rng: &mut Stream) -> Result<Vec<f64>> {
        match &self.route {
            Route::Batched(batch) => Ok(batch.evaluate_trials(network, rng)?),
            Route::Kernel(flier) => Ok(cuda::trial_scores_with(
                &self.settings,
                self.task,
                network,
                rng,
                |batch| flier.fly(batch),
            )?),
            Route::Scalar | Route::OdeLockstep => {
                Ok(TrialRunner::new(&self.settings, self.task)?.evaluate_trials(network, rng)?)
            }
        }
    }

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
        match &self.route {
            Route::Kernel(flier) => {
                let (settings, task) = (&self.settings, self.task);
                Ok(cuda::evaluate_with(settings, task, networks, range, rngs, |batch| {
                    flier.fly(batch)
                })?)
            }
            Route::Batched(batch) => Ok(batch.evaluate(networks, range, rngs)?),
            Route::OdeLockstep => {
                if worker.lockstep.is_none() {
                    worker.lockstep = Some(OdeLockstepRunner::new(&self.settings, self.task)?);
                }
                let lockstep = worker.lockstep.as_mut().expect("just made");
                Ok(lockstep.evaluate(networks, range, rngs)?)
            }
            Route::Scalar => range
                .zip(rngs)
                .map(|(j, rng)| self.evaluate(worker, &networks.network(j), rng))
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_reads_back_as_the_path_of_that_name() {
        // The names of earlier builds, which command lines and scripts
        // spell: a new path adds its name, none changes.
        assert_eq!(
            EvalPath::names(),
            [
                "fastest",
                "scalar",
                "portable",
                "avx2",
                "avx512",
                "ode-lockstep",
                "kernel-host"
            ]
        );
        for name in EvalPath::names() {
            let path: EvalPath = name.parse().unwrap();
            assert_eq!(path.name(), name);
        }
        assert!("kernel".parse::<EvalPath>().unwrap_err().contains("kernel-host"));
    }
}
