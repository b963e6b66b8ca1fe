//! `psa-esp bench`: ns per physics step of every backend, measured in one
//! run with the backends interleaved so that machine noise hits them alike.

use std::time::Instant;

use anyhow::Result;
use serde::Serialize;

use crate::physics::{create_backend, random_thrust_sequence, BackendKind, BodyState, PhysicsBackend};
use crate::psa::BodySettings;

/// Arguments of `bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Physics steps per backend and round.
    #[arg(long, default_value_t = 50_000, value_parser = clap::value_parser!(u64).range(500..))]
    pub steps: u64,
    /// Interleaved rounds; the median round is reported.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..))]
    pub rounds: u64,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
}

/// One backend's timing.
#[derive(Debug, Serialize)]
struct StepTiming {
    backend: BackendKind,
    median_ns_per_step: f64,
    min_ns_per_step: f64,
    relative_to_ode: f64,
}

/// The machine the numbers were measured on.
#[derive(Debug, Serialize)]
struct Machine {
    cpu: String,
    cores: usize,
}

fn machine() -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    Machine { cpu, cores }
}

/// Times `steps` steps, restarting every 500 steps as a trial does.
fn time_steps(backend: &mut dyn PhysicsBackend, commands: &[Vec<f64>], steps: u64) -> Result<f64> {
    let start = Instant::now();
    for i in 0..steps as usize {
        let k = i % commands.len();
        if k == 0 {
            backend.reset(&BodyState::default())?;
        }
        backend.step(std::hint::black_box(&commands[k]))?;
    }
    std::hint::black_box(backend.state());
    Ok(start.elapsed().as_nanos() as f64 / steps as f64)
}

/// Runs `bench`.
pub fn run(args: BenchArgs) -> Result<i32> {
    let model = BodySettings::default().model()?;
    let settings = crate::physics::StepSettings::default();
    let commands = random_thrust_sequence(1, 0, 500, model.thrusters.len());
    let kinds = BackendKind::available();
    let mut backends = kinds
        .iter()
        .map(|&k| create_backend(k, &model, &settings))
        .collect::<Result<Vec<_>, _>>()?;
    let mut samples = vec![Vec::new(); kinds.len()];
    for _ in 0..args.rounds {
        for (backend, samples) in backends.iter_mut().zip(&mut samples) {
            samples.push(time_steps(backend.as_mut(), &commands, args.steps)?);
        }
    }
    let median = |s: &mut Vec<f64>| {
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    };
    let medians: Vec<f64> = samples.iter_mut().map(median).collect();
    let ode = medians[0];
    let timings: Vec<StepTiming> = kinds
        .iter()
        .zip(&samples)
        .zip(&medians)
        .map(|((&backend, s), &m)| StepTiming {
            backend,
            median_ns_per_step: m,
            min_ns_per_step: s[0],
            relative_to_ode: m / ode,
        })
        .collect();
    let machine = machine();
    if args.json {
        let out = serde_json::json!({ "machine": machine, "steps_per_round": args.steps, "rounds": args.rounds, "physics_step": timings });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!("machine: {} ({} cores)", machine.cpu, machine.cores);
        println!(
            "physics step, PSA body, dt {} s ({} rounds x {} steps, median):",
            settings.dt, args.rounds, args.steps
        );
        println!("{:<8} {:>10} {:>10} {:>8}", "backend", "ns/step", "min", "vs ode");
        for t in &timings {
            println!(
                "{:<8} {:>10.1} {:>10.1} {:>7.3}x",
                t.backend.name(),
                t.median_ns_per_step,
                t.min_ns_per_step,
                t.relative_to_ode
            );
        }
    }
    Ok(0)
}
