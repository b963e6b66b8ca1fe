//! `psa-esp sweep`: the grid for each value, or each combination of values, of any settings.

use std::path::PathBuf;

use anyhow::Result;

use super::choice::choice;
use super::replicate::{report_gpu_share, report_held, GridArgs, Progress};
use psa_experiment::grid::sweep::{parse_vary, sweep, SweepMode, SweepSpec};

/// Arguments of `sweep`.
#[derive(Debug, clap::Args)]
pub struct SweepArgs {
    /// A setting and its values, KEY=V1,V2,... with KEY as in a configuration
    /// file (e.g. esp.stagnation=20,40,70 or problem.tasks.task2_spin=0,1);
    /// repeat for more settings.
    #[arg(long = "vary", required = true)]
    pub vary: Vec<String>,
    /// combinations: every combination of the values; one-at-a-time: each
    /// setting alone (the others at the base), plus the base.
    #[arg(long, value_parser = choice::<SweepMode>(), default_value_t = SweepMode::Combinations)]
    pub mode: SweepMode,
    /// The grid each variant runs.
    #[command(flatten)]
    pub grid: GridArgs,
    /// The sweep's directory; running the same command again resumes it.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `sweep`.
pub fn run(args: SweepArgs) -> Result<i32> {
    let vary = args.vary.iter().map(|v| parse_vary(v)).collect::<Result<Vec<_>>>()?;
    let spec = SweepSpec::new(args.grid.spec()?, vary, args.mode)?;
    let progress = Progress::new(args.grid.quiet, true);
    let options = args.grid.options()?;
    let clock = std::time::Instant::now();
    super::require_utf8_folder("--out", &args.out)?;
    let summary = sweep(&args.out, &spec, &options, &progress);
    progress.bar.finish_and_clear();
    report_gpu_share(&options.eval_path, clock.elapsed().as_secs_f64())?;
    let summary = summary?;
    report_held(summary.held.iter().map(|(variant, h)| (format!("{variant}: "), h)));
    say!(
        "sweep {}: {} variants, {} runs ({} of them shared with an earlier variant, run once: {} written from it now), {} already finished, {} run now, {} left to other processes, in {:.0} s",
        args.out.display(),
        summary.variants,
        summary.total,
        summary.shared,
        summary.written_from_shared,
        summary.skipped,
        summary.ran,
        summary.held.len(),
        summary.seconds
    );
    say!("next: psa-esp report {}", args.out.display());
    Ok(0)
}
