//! `psa-esp crosscheck`: every backend against ODE on random thrust sequences.

use anyhow::Result;
use psa_sim::named::Named;

use super::{PhysicsArgs, EXIT_CHECK_FAILED};
use psa_sim::physics::crosscheck;
use psa_sim::psa::settings::limits::MAX_STEPS;
use psa_sim::psa::BodySettings;

/// The most random thrust sequences of one cross-check (only time grows with them).
const MAX_SEQUENCES: u64 = 100_000;

/// Arguments of `crosscheck`.
#[derive(Debug, clap::Args)]
pub struct CrosscheckArgs {
    /// Number of random thrust sequences (at most 100,000).
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..=MAX_SEQUENCES))]
    pub sequences: u64,
    /// Steps per sequence (at most 100,000, as a trial; each sequence's
    /// trajectories are held in memory).
    #[arg(long, default_value_t = 500, value_parser = clap::value_parser!(u64).range(1..=MAX_STEPS))]
    pub steps: u64,
    /// Seed of the thrust sequences.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub physics: PhysicsArgs,
}

/// Runs `crosscheck`; exits with [`EXIT_CHECK_FAILED`] when a backend is out of tolerance.
pub fn run(args: CrosscheckArgs) -> Result<i32> {
    let settings = args.physics.settings()?;
    let model = BodySettings::default().model()?;
    let report = crosscheck(
        &model,
        &settings,
        args.sequences as usize,
        args.steps as usize,
        args.seed,
    )?;
    if args.json {
        say!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say!(
            "{} random thrust sequences x {} steps (seed {}): largest difference from the reference",
            report.sequences,
            report.steps,
            report.seed
        );
        say!(
            "{:<8} {:<34} {:>11} {:>11} {:>11}  {:>9}  result",
            "backend",
            "reference",
            "position/m",
            "heading/rad",
            "velocity",
            "tolerance"
        );
        for c in &report.comparisons {
            say!(
                "{:<8} {:<34} {:>11.3e} {:>11.3e} {:>11.3e}  {:>9.1e}  {}",
                c.backend.name(),
                c.reference,
                c.deviation.position,
                c.deviation.heading,
                c.deviation.velocity,
                c.tolerance.position.max(c.tolerance.heading).max(c.tolerance.velocity),
                if c.passed { "ok" } else { "OUT OF TOLERANCE" }
            );
        }
        for c in report.comparisons.iter().filter(|c| c.reference != "ode") {
            say!(
                "{:<8} {:<34} {:>11.3e} {:>11.3e} {:>11.3e}  (for information: see RAPIER_TOLERANCE)",
                c.backend.name(),
                "ode itself",
                c.raw_vs_ode.position,
                c.raw_vs_ode.heading,
                c.raw_vs_ode.velocity
            );
        }
    }
    Ok(if report.passed() { 0 } else { EXIT_CHECK_FAILED })
}
