//! `psa-esp simulate`: the PSA under given thrust, trajectory as CSV.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

use super::choice::choice;
use super::{PhysicsArgs, TRAJECTORY_HEADER};
use psa_sim::physics::{create_backend, for_each_state, BackendKind, BodyState, PhysicsBackend};
use psa_sim::psa::settings::limits;
use psa_sim::psa::{BodySettings, THRUSTER_COUNT};

/// Arguments of `simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    /// Physics backend.
    #[arg(long, value_parser = choice::<BackendKind>(), default_value_t = BackendKind::Ode)]
    pub backend: BackendKind,
    /// Constant thrust of the four thrusters, each in [0, 1]: u0,u1,u2,u3.
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        conflicts_with = "thrust_file",
        required_unless_present = "thrust_file"
    )]
    pub thrust: Option<Vec<f64>>,
    /// A file with one row of four thrust values per step (comma or
    /// whitespace separated; '#' starts a comment).
    #[arg(long)]
    pub thrust_file: Option<PathBuf>,
    /// Number of steps (default 500 with --thrust; the file's rows with
    /// --thrust-file), at most 1e9. The trajectory is written as it goes.
    #[arg(long, value_parser = clap::value_parser!(u64).range(0..=MAX_STEPS))]
    pub steps: Option<u64>,
    /// Start state x,y,heading,vx,vy,omega (m, rad, m/s, rad/s).
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        default_value = "0,0,0,0,0,0"
    )]
    pub start: Vec<f64>,
    /// Write the trajectory here instead of standard output.
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub physics: PhysicsArgs,
}

/// The default number of steps of a trial (`[chosen]` 500 x 0.05 s = 25 s).
const DEFAULT_STEPS: u64 = 500;

/// The most bytes a trajectory row takes: seven numbers of at most 19
/// characters each (a float's shortest round trip, sign and exponent
/// included) and their separators.
const MAX_BYTES_PER_STATE: u64 = 7 * 19 + 7;

/// `bytes` in kB, MB or GB (decimal, one decimal place).
fn size_label(bytes: u64) -> String {
    let b = bytes as f64;
    match bytes {
        0..=999_999 => format!("{:.1} kB", b / 1e3),
        1_000_000..=999_999_999 => format!("{:.1} MB", b / 1e6),
        _ => format!("{:.1} GB", b / 1e9),
    }
}

/// The most steps of one simulation: at most 140 GB of CSV and an hour or two
/// of ODE; the trajectory is streamed, so only time and disk grow with it.
pub const MAX_STEPS: u64 = 1_000_000_000;

fn read_thrust_file(path: &Path) -> Result<Vec<Vec<f64>>> {
    let text = psa_sim::io::read_input(path, "thrust file")?;
    let mut rows = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let values = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| s.parse::<f64>())
            .collect::<Result<Vec<f64>, _>>()
            .map_err(|e| anyhow::anyhow!("{}: line {}: {e}", path.display(), number + 1))?;
        if values.len() != THRUSTER_COUNT {
            bail!(
                "{}: line {}: expected {THRUSTER_COUNT} thrust values, found {}",
                path.display(),
                number + 1,
                values.len()
            );
        }
        rows.push(values);
    }
    if rows.is_empty() {
        bail!("{}: no thrust rows", path.display());
    }
    Ok(rows)
}

/// The thrust of every step: `rows` in turn, cycling, `steps` in all.
struct Commands {
    rows: Vec<Vec<f64>>,
    steps: u64,
}

impl Commands {
    fn iter(&self) -> impl Iterator<Item = &[f64]> {
        self.rows.iter().map(Vec::as_slice).cycle().take(self.steps as usize)
    }
}

fn commands(args: &SimulateArgs) -> Result<Commands> {
    match (&args.thrust, &args.thrust_file) {
        (Some(thrust), _) => {
            if thrust.len() != THRUSTER_COUNT {
                bail!(
                    "--thrust takes {THRUSTER_COUNT} comma-separated values u0,u1,u2,u3, got {}",
                    thrust.len()
                );
            }
            Ok(Commands {
                rows: vec![thrust.clone()],
                steps: args.steps.unwrap_or(DEFAULT_STEPS),
            })
        }
        (None, Some(path)) => {
            let mut rows = read_thrust_file(path)?;
            if let Some(steps) = args.steps {
                if steps > rows.len() as u64 {
                    bail!("--steps {steps} exceeds the {} rows of {}", rows.len(), path.display());
                }
                rows.truncate(steps as usize);
            }
            let steps = rows.len() as u64;
            Ok(Commands { rows, steps })
        }
        (None, None) => bail!("give --thrust or --thrust-file"),
    }
}

/// The start state of `--start`, each value in the range of its `start.*`
/// row of [`limits`].
fn start_state(values: &[f64]) -> Result<BodyState> {
    let [x, y, heading, vx, vy, omega] = values[..] else {
        bail!(
            "--start takes six values: x,y,heading,vx,vy,omega, got {}",
            values.len()
        );
    };
    for (name, value) in ["x", "y", "heading", "vx", "vy", "omega"].iter().zip(values) {
        limits::check_as(&format!("start.{name}"), &format!("--start {name}"), *value).map_err(anyhow::Error::msg)?;
    }
    Ok(BodyState {
        x,
        y,
        heading,
        vx,
        vy,
        omega,
    })
}

/// Writes the trajectory CSV of `commands` from `start` to `out` as the
/// backend flies it; returns the number of states written.
fn write_trajectory(
    out: &mut dyn Write,
    backend: &mut dyn PhysicsBackend,
    start: &BodyState,
    commands: &Commands,
    dt: f64,
) -> Result<u64> {
    writeln!(out, "{TRAJECTORY_HEADER}")?;
    let mut row = String::new();
    let mut written = 0;
    for_each_state(backend, start, commands.iter(), |state| -> Result<()> {
        row.clear();
        super::trajectory_row(&mut row, written, dt, state, "")?;
        out.write_all(row.as_bytes())?;
        written += 1;
        Ok(())
    })?;
    Ok(written)
}

/// Runs `simulate`.
pub fn run(args: SimulateArgs) -> Result<i32> {
    let settings = args.physics.settings()?;
    let model = BodySettings::default().model()?;
    let start = start_state(&args.start)?;
    let commands = commands(&args)?;
    let mut backend = create_backend(args.backend, &model, &settings)?;
    // The output grows with the steps (up to about 140 GB at MAX_STEPS):
    // its size is said before the first state is written, once the file
    // can be written.
    if let Some(path) = &args.out {
        psa_sim::io::check_output_file(path)?;
    }
    let states = commands.steps + 1;
    eprintln!(
        "simulate: {states} states, at most {} of trajectory to {}",
        size_label(states * MAX_BYTES_PER_STATE),
        args.out
            .as_ref()
            .map_or("standard output".to_string(), |p| p.display().to_string())
    );
    match &args.out {
        Some(path) => {
            let mut written = 0;
            psa_sim::io::write_atomic_with(path, |out| {
                written = write_trajectory(out, backend.as_mut(), &start, &commands, settings.dt)?;
                Ok(())
            })?;
            eprintln!("wrote {written} states to {}", path.display());
        }
        None => {
            let mut out = std::io::BufWriter::new(std::io::stdout().lock());
            let result = write_trajectory(&mut out, backend.as_mut(), &start, &commands, settings.dt)
                .and_then(|_| Ok(out.flush()?));
            if let Err(e) = result {
                // The reader has gone (`psa-esp simulate ... | head`): done.
                if e.downcast_ref::<std::io::Error>()
                    .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
                {
                    std::process::exit(0);
                }
                return Err(e);
            }
        }
    }
    Ok(0)
}
