//! The evaluation paths the bench times (every backend and [`EvalPath`]
//! on it, with or without input noise), and one round's evaluation rate on
//! one of them: shared by the full bench ([`super::bench`]) and its
//! speed-up check ([`super::bench_floor`]).

use std::time::Instant;

use anyhow::Result;
use serde::Serialize;
use strum::VariantArray;

use esp_neuroevolution::evaluate_all;
use esp_neuroevolution::network::Network;
use psa_experiment::PAPER_NOISE_SD;
use psa_sim::evaluator::{EvalPath, EvalPathKind, PsaEvaluator};
use psa_sim::numeric::SimdLevel;
use psa_sim::physics::BackendKind;
use psa_sim::psa::{PsaSettings, Task};

/// A way of evaluating networks: a backend and the [`EvalPath`] on it (on
/// `native` the scalar reference or the batched path on one SIMD level, on
/// `ode` one world per network or the lockstep path, many bodies in one
/// world), with or without input noise. Written to JSON as `backend`,
/// `simd` (the batched path's level, `null` otherwise), `ode_lockstep` and
/// `input_noise`.
#[derive(Debug, Clone)]
pub struct EvaluationPath {
    /// The physics backend.
    pub backend: BackendKind,
    /// The path on it: [`EvalPath::Scalar`], [`EvalPath::Simd`] or
    /// [`EvalPath::OdeLockstep`].
    pub path: EvalPath,
    /// Under the paper's input noise (sd 0.05), as in its noisy configurations.
    pub input_noise: bool,
}

impl Serialize for EvaluationPath {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        // Every path by name, with no `_`: a new one is a compile error
        // here until it is written apart from the others.
        let simd = match self.path {
            EvalPath::Simd(level) => Some(level),
            EvalPath::Fastest
            | EvalPath::Scalar
            | EvalPath::OdeLockstep
            | EvalPath::KernelOnHost
            | EvalPath::Kernel(_) => None,
        };
        let ode_lockstep = match self.path {
            EvalPath::OdeLockstep => true,
            EvalPath::Fastest | EvalPath::Scalar | EvalPath::Simd(_) | EvalPath::KernelOnHost | EvalPath::Kernel(_) => {
                false
            }
        };
        let mut row = serializer.serialize_struct("EvaluationPath", 4)?;
        row.serialize_field("backend", &self.backend)?;
        row.serialize_field("simd", &simd)?;
        row.serialize_field("ode_lockstep", &ode_lockstep)?;
        row.serialize_field("input_noise", &self.input_noise)?;
        row.end()
    }
}

impl EvaluationPath {
    /// The path's name in the bench's table.
    pub fn label(&self) -> String {
        let backend = self.backend;
        let path = match &self.path {
            EvalPath::Scalar => match backend {
                BackendKind::Native => "native scalar".into(),
                BackendKind::Ode => "ode one world each".into(),
                BackendKind::Rapier => "rapier".into(),
            },
            EvalPath::Simd(level) => format!("{backend} batched {level}"),
            EvalPath::OdeLockstep => format!("{backend} lockstep"),
            EvalPath::Fastest => format!("{backend} fastest"),
            EvalPath::KernelOnHost => format!("{backend} kernel-host"),
            EvalPath::Kernel(_) => format!("{backend} kernel"),
        };
        if self.input_noise {
            format!("{path}, input noise")
        } else {
            path
        }
    }

    /// ode one world per network and in lockstep, native scalar, native
    /// batched on every level the CPU has, rapier; then native scalar and
    /// batched on the CPU's best level under input noise.
    pub fn all() -> Vec<EvaluationPath> {
        let on = |backend, path| EvaluationPath {
            backend,
            path,
            input_noise: false,
        };
        let mut paths = Vec::new();
        for backend in BackendKind::available() {
            // Every kind of path by name: a new one is a compile error here
            // until the bench times it or says why not.
            for kind in EvalPathKind::VARIANTS {
                match kind {
                    // One of the paths below, picked at run time.
                    EvalPathKind::Fastest => {}
                    EvalPathKind::Scalar => paths.push(on(backend, EvalPath::Scalar)),
                    EvalPathKind::Simd if backend == BackendKind::Native => paths.extend(
                        SimdLevel::VARIANTS
                            .iter()
                            .filter(|l| l.is_supported())
                            .map(|&level| on(backend, EvalPath::Simd(level))),
                    ),
                    EvalPathKind::OdeLockstep if backend == BackendKind::Ode => {
                        paths.push(on(backend, EvalPath::OdeLockstep))
                    }
                    // Only native is batched and only ode in lockstep.
                    EvalPathKind::Simd | EvalPathKind::OdeLockstep => {}
                    // Timed by the kernel's rows (`bench_kernel`).
                    EvalPathKind::KernelOnHost | EvalPathKind::Kernel => {}
                }
            }
        }
        let native = |p: &&EvaluationPath| p.backend == BackendKind::Native;
        let scalar = paths.iter().find(|p| native(p) && matches!(p.path, EvalPath::Scalar));
        let best_batched = paths.iter().rfind(|p| native(p) && matches!(p.path, EvalPath::Simd(_)));
        let noisy: Vec<_> = [scalar, best_batched]
            .into_iter()
            .flatten()
            .map(|path| EvaluationPath {
                input_noise: true,
                ..path.clone()
            })
            .collect();
        paths.extend(noisy);
        paths
    }

    /// The evaluator of the benchmark's task (task 1, default settings) on this path.
    pub fn evaluator(&self) -> Result<PsaEvaluator> {
        let mut settings = PsaSettings {
            backend: self.backend,
            ..PsaSettings::default()
        };
        if self.input_noise {
            settings.noise.input_sd = PAPER_NOISE_SD;
        }
        PsaEvaluator::new(settings, Task::StopRotation, &self.path)
    }
}

/// Evaluations per second of one round of `networks` on `evaluator`, on
/// the thread pool it is called in (the round seeds the trials).
pub fn evaluation_rate(evaluator: &PsaEvaluator, networks: &[Network], round: u64) -> Result<f64> {
    let start = Instant::now();
    evaluate_all(evaluator, networks, round, &[])?;
    Ok(networks.len() as f64 / start.elapsed().as_secs_f64())
}
