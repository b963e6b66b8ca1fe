//! `--backend` of the commands that evolve: a physics backend, or `cuda`,
//! the `native` backend's physics with every trial flown on the GPU.

use anyhow::Result;
use std::sync::Arc;

use crate::evaluator::fly_trials_on;
use crate::physics::BackendKind;
use crate::psa::cuda::CudaTrials;

/// Where the trials of a run fly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BackendArg {
    /// The Open Dynamics Engine (the faithful reference).
    Ode,
    /// Pure Rust, ODE's step bit for bit, batched in SIMD.
    Native,
    /// rapier2d-f64.
    Rapier,
    /// `native`'s physics on an NVIDIA GPU (the `cuda` build feature):
    /// the same results bit for bit; a grid runs in lockstep, every run's
    /// generation in one launch.
    Cuda,
}

impl BackendArg {
    /// The physics backend the runs record and simulate: `native` for `cuda`.
    pub fn physics(self) -> BackendKind {
        match self {
            BackendArg::Ode => BackendKind::Ode,
            BackendArg::Native | BackendArg::Cuda => BackendKind::Native,
            BackendArg::Rapier => BackendKind::Rapier,
        }
    }

    /// For `cuda`: opens the GPU, compiles the kernel and makes every
    /// evaluator of the process use it, printing the device to standard
    /// error; an error naming what is missing (the feature, the driver,
    /// NVRTC or a device) where it cannot. Nothing for the others.
    pub fn prepare(self) -> Result<()> {
        if self == BackendArg::Cuda {
            let gpu = CudaTrials::open().map_err(|e| anyhow::anyhow!("--backend cuda: {e}"))?;
            eprintln!("evaluating on {}", gpu.device());
            fly_trials_on(Arc::new(gpu));
        }
        Ok(())
    }
}
