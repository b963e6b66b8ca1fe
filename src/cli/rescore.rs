//! `psa-esp rescore`: a finished grid's champions tested again under other
//! scoring settings, without re-evolving them.

use std::path::PathBuf;

use anyhow::Result;

use super::replicate::read_overrides;
use psa_experiment::grid::rescore::{check_out, check_rescoring_acts, rescore, rescored_spec};
use psa_experiment::grid::GridSpec;
use psa_sim::ode::MAX_THREADS;
use psa_sim::psa::settings::limits::MAX_TRIALS;

/// Arguments of `rescore`.
#[derive(Debug, clap::Args)]
pub struct RescoreArgs {
    /// The finished (or partly finished) grid directory to re-score.
    pub grid: PathBuf,
    /// A TOML file of problem settings laid over every run's configuration
    /// for its champion's tests and reported score only (e.g. `[problem.fitness]
    /// scoring = "original"`); recorded in the new grid.json as `rescoring`.
    #[arg(long)]
    pub config: PathBuf,
    /// Trials of each robustness test (default: the grid's).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_TRIALS))]
    pub robustness_trials: Option<u64>,
    /// Worker threads (0 = one per core). Results do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=MAX_THREADS as u64))]
    pub threads: u64,
    /// The new grid's directory; running the same command again resumes it.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `rescore`.
pub fn run(args: RescoreArgs) -> Result<i32> {
    super::require_utf8_folder("--out", &args.out)?;
    let overlay = read_overrides(&args.config)?;
    let source = GridSpec::load(&args.grid)?;
    let spec = rescored_spec(&source, &overlay, args.robustness_trials.map(|t| t as usize))?;
    check_out(&args.grid, &args.out)?;
    check_rescoring_acts(&args.grid, &source, &overlay)?;
    let summary = rescore(&args.grid, &args.out, &spec, args.threads as usize)?;
    say!(
        "rescore {} -> {}: {} finished runs, {} already re-scored, {} re-scored now, {} unfinished left out, in {:.1} s",
        args.grid.display(),
        args.out.display(),
        summary.total,
        summary.skipped,
        summary.ran,
        summary.unfinished,
        summary.seconds
    );
    say!("next: psa-esp report {}", args.out.display());
    Ok(0)
}
