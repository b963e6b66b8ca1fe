//! `psa-esp simulate`: the PSA under given thrust, trajectory as CSV.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use super::PhysicsArgs;
use crate::physics::{create_backend, trajectory, BackendKind, BodyState};
use crate::psa::{BodySettings, THRUSTER_COUNT};

/// Arguments of `simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    /// Physics backend.
    #[arg(long, value_enum, default_value_t = BackendKind::Ode)]
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
    /// Number of steps (default 500 with --thrust; the file's rows with --thrust-file).
    #[arg(long)]
    pub steps: Option<usize>,
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
const DEFAULT_STEPS: usize = 500;

fn read_thrust_file(path: &PathBuf) -> Result<Vec<Vec<f64>>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read thrust file {}", path.display()))?;
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

fn commands(args: &SimulateArgs) -> Result<Vec<Vec<f64>>> {
    match (&args.thrust, &args.thrust_file) {
        (Some(thrust), _) => {
            if thrust.len() != THRUSTER_COUNT {
                bail!(
                    "--thrust takes {THRUSTER_COUNT} comma-separated values u0,u1,u2,u3, got {}",
                    thrust.len()
                );
            }
            Ok(vec![thrust.clone(); args.steps.unwrap_or(DEFAULT_STEPS)])
        }
        (None, Some(path)) => {
            let mut rows = read_thrust_file(path)?;
            if let Some(steps) = args.steps {
                if steps > rows.len() {
                    bail!("--steps {steps} exceeds the {} rows of {}", rows.len(), path.display());
                }
                rows.truncate(steps);
            }
            Ok(rows)
        }
        (None, None) => bail!("give --thrust or --thrust-file"),
    }
}

/// Runs `simulate`.
pub fn run(args: SimulateArgs) -> Result<i32> {
    let settings = args.physics.settings()?;
    let model = BodySettings::default().model()?;
    let commands = commands(&args)?;
    let [x, y, heading, vx, vy, omega] = args.start[..] else {
        bail!("--start takes six values: x,y,heading,vx,vy,omega");
    };
    let start = BodyState {
        x,
        y,
        heading,
        vx,
        vy,
        omega,
    };
    let mut backend = create_backend(args.backend, &model, &settings)?;
    let states = trajectory(backend.as_mut(), &start, &commands)?;
    let csv = super::trajectory_csv(&states, settings.dt, "", |_| String::new());
    match &args.out {
        Some(path) => {
            crate::io::write_atomic(path, csv.as_bytes())?;
            eprintln!("wrote {} states to {}", states.len(), path.display());
        }
        None => say!("{}", csv.trim_end()),
    }
    Ok(0)
}
