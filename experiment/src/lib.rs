//! psa-experiment: experiments on the simulated PSA (`psa-sim`): run
//! configurations and presets, single evolution runs written to disk, the
//! replication grid and its executors, robustness tests, the results
//! model, statistics, the report beside the paper's tables, and plots.
//!
//! It sits between the simulator and the command line: it may not depend
//! on the command line (`clap`) or the `psa-esp` binary, and the simulator
//! may not depend on it. `.ci/run` checks its `cargo tree`.
//!
//! Its modules, by concern: [`grid`], the grid and everything that runs it
//! (its executors, replicate, sweep and rescore, shards and claims for
//! batch jobs); [`results`], what a run and a grid leave (the results
//! model, `runs.csv`, the column tables, statistics); [`champion`], the
//! tests of a run's champion (robustness, the ODE check); [`report`] and
//! [`plots`]; and at the root the configuration, the earlier models
//! ([`models`]) and the single run.

pub mod champion;
mod config;
pub mod grid;
pub mod models;
pub mod plots;
pub mod report;
pub mod results;
mod run;
pub mod trace;

pub use config::{
    paper_esp_settings, Algorithm, GridConfig, GridConfigKind, Preset, RunConfig, BASELINE, PAPER_NOISE_SD,
    PAPER_NOISY_TRIALS,
};
pub use report::{write_report, ReportFormat, ReportOutcome};
pub use results::EvolveOutcome;
pub use run::{records_csv, run_evolution, run_evolution_traced, RunFiles, RunStart};

/// The build's identity, recorded in every result file: this crate's
/// version, the git commit (stamped by this crate's `build.rs`, with
/// `-dirty` for uncommitted changes) and the libode version.
pub fn build_info() -> psa_sim::provenance::BuildInfo {
    psa_sim::provenance::BuildInfo {
        tool_version: env!("CARGO_PKG_VERSION").into(),
        git_commit: env!("PSA_ESP_GIT_COMMIT").into(),
        libode_version: psa_sim::ode::libode_version().into(),
        defaults: Some(psa_sim::psa::settings::defaults::rows() as u64),
    }
}

/// What `psa-esp --version` prints after the name: the version, the commit
/// and the libode version of [`build_info`].
pub fn version() -> String {
    let build = build_info();
    format!(
        "{} (commit {}, libode {})",
        build.tool_version, build.git_commit, build.libode_version
    )
}
