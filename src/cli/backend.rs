//! `--backend` of the commands that evolve: a physics backend, or `cuda`,
//! the `native` backend's physics with every trial flown on the GPU.

use anyhow::Result;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use std::sync::Arc;

use psa_sim::evaluator::EvalPath;
use psa_sim::named::Named;
use psa_sim::physics::BackendKind;
use psa_sim::psa::cuda::CudaTrials;

/// Where the trials of a run fly: a physics backend (every
/// [`BackendKind`], by its name), or `cuda`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BackendArg {
    /// The runs fly on this backend.
    Physics(BackendKind),
    /// `native`'s physics on an NVIDIA GPU (the `cuda` build feature):
    /// the same results bit for bit; a grid runs in lockstep, every run's
    /// generation in one launch.
    Cuda,
}

impl BackendArg {
    /// The name of [`BackendArg::Cuda`].
    const CUDA: &'static str = "cuda";

    /// The parser of `--backend`: every backend's name, then `cuda`.
    pub fn parser() -> impl TypedValueParser<Value = BackendArg> {
        let mut names = BackendKind::names();
        names.push(Self::CUDA);
        PossibleValuesParser::new(names).map(|name| match name.as_str() {
            Self::CUDA => BackendArg::Cuda,
            backend => BackendArg::Physics(backend.parse().expect("clap admits only the backends' names")),
        })
    }

    /// The physics backend the runs record and simulate: `native` for `cuda`.
    pub fn physics(self) -> BackendKind {
        match self {
            BackendArg::Physics(kind) => kind,
            BackendArg::Cuda => BackendKind::Native,
        }
    }

    /// The evaluation path of the runs: for `cuda` the GPU (opened, the
    /// kernel compiled, the device printed to standard error; an error
    /// naming what is missing, the feature, the driver, NVRTC or a device,
    /// where it cannot be), else `requested` (`--eval-path`).
    pub fn eval_path(backend: Option<BackendArg>, requested: EvalPath) -> Result<EvalPath> {
        if backend != Some(BackendArg::Cuda) {
            return Ok(requested);
        }
        if !matches!(requested, EvalPath::Fastest) {
            anyhow::bail!("--backend cuda flies every trial on the GPU: leave out --eval-path");
        }
        let gpu = CudaTrials::open().map_err(|e| anyhow::anyhow!("--backend cuda: {e}"))?;
        eprintln!("evaluating on {}", gpu.device());
        Ok(EvalPath::Kernel(Arc::new(gpu)))
    }
}

/// `--eval-path` of the commands that evolve.
#[derive(Debug, Clone, clap::Args)]
pub struct EvalPathArg {
    /// Where the networks are evaluated: fastest (on native the processor's
    /// best SIMD level, on ode the lockstep path), scalar (the reference),
    /// a SIMD level of native (portable, avx2, avx512), ode-lockstep, or
    /// kernel-host (native's trials through the cuda kernel built for the
    /// host, slowly). Results do not depend on it.
    #[arg(long, value_parser = eval_path_parser(), default_value = "fastest")]
    pub eval_path: EvalPath,
}

/// The parser of `--eval-path`: one of [`EvalPath::names`].
fn eval_path_parser() -> impl TypedValueParser<Value = EvalPath> {
    PossibleValuesParser::new(EvalPath::names()).map(|name| name.parse().expect("clap admits only the names"))
}
