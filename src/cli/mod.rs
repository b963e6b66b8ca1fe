//! The `psa-esp` command line (clap).

/// `println!` to standard output that ends the process quietly when the
/// reader has gone (`psa-esp ... | head`) instead of panicking.
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::cli::write_stdout(format_args!($($arg)*))?
    };
}

mod backend;
pub mod bench;
pub mod bench_floor;
pub mod bench_kernel;
pub mod bench_networks;
pub mod bench_ode;
pub mod bench_paths;
pub mod bench_runs;
mod choice;
mod crosscheck;
mod evolve;
mod replay;
mod replicate;
mod report;
mod rescore;
mod simulate;
mod sweep;
mod traces;

use choice::choice;
use clap::{Parser, Subcommand};
use psa_sim::physics::{PlaneConstraint, Stepper};

/// The exit code of a run whose checks failed (a cross-check out of tolerance).
pub const EXIT_CHECK_FAILED: i32 = 1;
/// The exit code of a run stopped by bad input or an I/O error.
pub const EXIT_ERROR: i32 = 2;

/// Evolving neural controllers for the Personal Satellite Assistant.
#[derive(Debug, Parser)]
#[command(name = "psa-esp", version = psa_experiment::version(), about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate the PSA under given thrust and write its trajectory as CSV.
    Simulate(simulate::SimulateArgs),
    /// Run random thrust sequences on every backend and compare each with ODE.
    Crosscheck(crosscheck::CrosscheckArgs),
    /// Evolve a controller: one run of a preset on a task.
    Evolve(evolve::EvolveArgs),
    /// Run the paper's experiment grid (resumable).
    Replicate(replicate::ReplicateArgs),
    /// Run the grid once for each value (or combination of values) of any settings (resumable).
    Sweep(sweep::SweepArgs),
    /// Compare a grid's results with the paper's tables: report.md, figures, and CSV or JSON.
    Report(report::ReportArgs),
    /// Test a finished grid's champions again under other scoring settings, into a new grid folder (resumable).
    Rescore(rescore::RescoreArgs),
    /// Fly a saved network on a task: fitness, trajectory CSV, pictures, animation.
    Replay(replay::ReplayArgs),
    /// Summarise `evolve --trace` files, a group per folder: when runs first find a first-pass landing, how often they lose it, how mean credit ranks its neurons.
    Traces(traces::TracesArgs),
    /// Measure physics steps and network evaluations of every backend in one run.
    Bench(bench::BenchArgs),
}

/// Runs a parsed command line; `Ok(code)` is the process exit code.
pub fn run(cli: Cli) -> anyhow::Result<i32> {
    match cli.command {
        Command::Simulate(args) => simulate::run(args),
        Command::Crosscheck(args) => crosscheck::run(args),
        Command::Evolve(args) => evolve::run(args),
        Command::Replicate(args) => replicate::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::Report(args) => report::run(args),
        Command::Rescore(args) => rescore::run(args),
        Command::Replay(args) => replay::run(args),
        Command::Traces(args) => traces::run(args),
        Command::Bench(args) => bench::run(args),
    }
}

/// Physics options shared by the subcommands that simulate.
#[derive(Debug, Clone, clap::Args)]
pub struct PhysicsArgs {
    /// Time step (s).
    #[arg(long, default_value_t = psa_sim::physics::StepSettings::default().dt, allow_negative_numbers = true)]
    pub dt: f64,
    /// ODE stepper: exact (dWorldStep) or quick (dWorldQuickStep).
    #[arg(long, value_parser = choice::<Stepper>(), default_value_t = Stepper::Exact)]
    pub stepper: Stepper,
    /// How ODE keeps the body in the plane: none, or plane2d_joint (a
    /// Plane2D joint), as `physics.plane_constraint` spells them.
    #[arg(long, value_parser = choice::<PlaneConstraint>(), default_value_t = PlaneConstraint::None)]
    pub plane: PlaneConstraint,
}

impl PhysicsArgs {
    /// The step settings these options describe; `--dt` must be in the
    /// range of `physics.dt` ([`psa_sim::psa::settings::limits`]).
    pub fn settings(&self) -> anyhow::Result<psa_sim::physics::StepSettings> {
        psa_sim::psa::settings::limits::check_as("physics.dt", "--dt", self.dt).map_err(anyhow::Error::msg)?;
        let settings = psa_sim::physics::StepSettings {
            dt: self.dt,
            stepper: self.stepper,
            plane_constraint: self.plane,
            ..psa_sim::physics::StepSettings::default()
        };
        settings.validate()?;
        Ok(settings)
    }
}

/// The header of a trajectory CSV: `t,x,y,heading,vx,vy,omega` (SI
/// units), then the columns named in `extra_header` (which starts with a
/// comma when not empty).
pub const TRAJECTORY_HEADER: &str = "t,x,y,heading,vx,vy,omega";

/// Row `i` of a trajectory CSV (state `s` at time `i dt`), with `extra`
/// appended.
pub fn trajectory_row(
    out: &mut impl std::fmt::Write,
    i: u64,
    dt: f64,
    s: &psa_sim::physics::BodyState,
    extra: &str,
) -> std::fmt::Result {
    writeln!(
        out,
        "{},{},{},{},{},{},{}{extra}",
        i as f64 * dt,
        s.x,
        s.y,
        s.heading,
        s.vx,
        s.vy,
        s.omega
    )
}

/// A trajectory as CSV: [`TRAJECTORY_HEADER`], then the columns named in
/// `extra_header` (which starts with a comma when not empty) filled per row
/// by `extra(row)`.
pub fn trajectory_csv(
    states: &[psa_sim::physics::BodyState],
    dt: f64,
    extra_header: &str,
    extra: impl Fn(usize) -> String,
) -> String {
    let mut csv = format!("{TRAJECTORY_HEADER}{extra_header}\n");
    for (i, s) in states.iter().enumerate() {
        let _ = trajectory_row(&mut csv, i as u64, dt, s, &extra(i));
    }
    csv
}

/// One rule for every output folder (`--out` of every command that writes
/// a folder): its name must be UTF-8, so that every later command (`replay`
/// reading a champion, `report` a grid) can name the files written there.
pub fn require_utf8_folder(option: &str, path: &std::path::Path) -> anyhow::Result<()> {
    if path.to_str().is_none() {
        anyhow::bail!(
            "{option} {}: the folder name is not UTF-8, so later commands (`replay` reading a champion, `report` a grid) could not name the files written there; choose a UTF-8 name",
            path.display()
        );
    }
    Ok(())
}

/// Writes one line to standard output; a closed pipe ends the process with success.
pub fn write_stdout(args: std::fmt::Arguments) -> std::io::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out
        .write_fmt(args)
        .and_then(|_| out.write_all(b"\n"))
        .and_then(|_| out.flush())
    {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        result => result,
    }
}
