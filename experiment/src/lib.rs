//! Experiments: the PSA as an evaluation function, run configurations and
//! presets, and single evolution runs written to disk.

pub mod claim;
mod config;
mod evaluator;
pub mod grid;
pub mod lockstep;
pub mod ode_check;
pub mod replicate;
pub mod report;
pub mod robustness;
mod run;
pub mod runs_table;
pub mod shard;
pub mod stats;
pub mod sweep;

pub use config::{paper_esp_settings, Algorithm, GridConfig, Preset, RunConfig, PAPER_NOISE_SD, PAPER_NOISY_TRIALS};
pub use evaluator::{fly_trials_on, PsaEvaluator, PsaWorker, CUDA_BATCH, KERNEL_ON_HOST, SIMD_VARIABLE};
pub use report::{write_report, ReportFormat, ReportOutcome};
pub use run::{records_csv, run_evolution, EvolveOutcome, RunFiles, RunStart};
