//! `psa-esp bench`: in one run, ns per physics step of every backend
//! (interleaved so that machine noise hits them alike), ns per
//! network-step and evaluations per second of every evaluation path (ode
//! one world per network and in lockstep, native scalar, native batched on
//! each SIMD level, rapier) on 1 and 2 threads, the ODE lockstep path by
//! bodies per world (see [`super::bench_ode`]), the logistic function
//! alone on the batched path (the bulk of
//! its arithmetic), and the 2-thread speed-up and algorithm overhead of
//! `evolve` and `replicate` (see [`super::bench_runs`]).

use std::time::Instant;

use anyhow::Result;
use multiversion::multiversion;
use serde::Serialize;

use super::bench_kernel::{kernel_rows, KernelBench, KERNEL_NETWORKS};
use super::bench_networks::{random_networks, HIDDEN};
use super::bench_paths::{evaluation_rate, EvaluationPath};
use super::bench_runs::{algorithm_overhead, evolve_workload, median, replicate_workload};
use super::choice::choice;
use esp_neuroevolution::network::Network;
use psa_sim::evaluator::EvalPath;
use psa_sim::named::Named;
use psa_sim::numeric::{sigmoid, Lanes, SimdLevel};
use psa_sim::physics::{create_backend, random_thrust_sequence, BackendKind, BodyState, OdeBackend, PhysicsBackend};
use psa_sim::psa::batch::LANES;
use psa_sim::psa::{BodySettings, PsaSettings, THRUSTER_COUNT};

/// Arguments of `bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Physics steps per backend and round (at most 1e9).
    #[arg(long, default_value_t = 50_000, value_parser = clap::value_parser!(u64).range(500..=1_000_000_000))]
    pub steps: u64,
    /// Interleaved rounds; the median round is reported (at most 1000).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub rounds: u64,
    /// Networks per round of the evaluation benchmark (at most 100,000).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub networks: u64,
    /// Generations of the `evolve` and `replicate` scaling runs (5 times
    /// as many for the algorithm overhead). Fewer make runs of a few
    /// hundredths of a second, whose speed-ups scatter (at most 100,000).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(2..=100_000))]
    pub generations: u64,
    /// Networks per launch of the cuda kernel's rows, beside `native`
    /// (measured only where a GPU is, or with --kernel-host).
    #[arg(long, value_delimiter = ',', default_values_t = KERNEL_NETWORKS,
          value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub kernel_networks: Vec<u64>,
    /// Time the cuda kernel's rows on the kernel built for the host instead
    /// of a GPU (the rows' plumbing without one, slowly).
    #[arg(long)]
    pub kernel_host: bool,
    /// Time only the cuda kernel's rows (for a GPU machine's short lease).
    #[arg(long)]
    pub kernel_only: bool,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
    /// Only check that the batched path's speed-up over the scalar path
    /// (`native`, 1 thread, --networks networks, --rounds interleaved
    /// rounds) reaches RATIO, and exit 1 when it does not: CI's guard
    /// against a build whose batched path falls back to slow code.
    #[arg(long, value_name = "RATIO",
          conflicts_with_all = ["steps", "generations", "kernel_networks", "kernel_host", "kernel_only"])]
    pub speedup_floor: Option<f64>,
    /// The SIMD level --speedup-floor times (default: the CPU's best).
    #[arg(long, requires = "speedup_floor", value_parser = choice::<SimdLevel>())]
    pub speedup_level: Option<SimdLevel>,
}

/// One path's speed at whole network evaluations (one 500-step trial each).
#[derive(Debug, Serialize)]
struct EvaluationTiming {
    path: EvaluationPath,
    evaluations_per_second_1_thread: f64,
    evaluations_per_second_2_threads: f64,
    speedup_2_threads: f64,
    ns_per_network_step_1_thread: f64,
}

/// Evaluations per second of `networks` on task 1 with `threads` threads
/// (median of `rounds` rounds).
fn evaluations_per_second(path: &EvaluationPath, networks: &[Network], threads: usize, rounds: u64) -> Result<f64> {
    let evaluator = path.evaluator()?;
    let pool = psa_sim::ode::thread_pool(threads)?;
    let rates = (0..rounds)
        .map(|round| pool.install(|| evaluation_rate(&evaluator, networks, round)))
        .collect::<Result<Vec<f64>>>()?;
    Ok(median(rates))
}

/// The logistic function alone, as the batched path computes it: blocks of
/// [`LANES`] values on the CPU's best SIMD level.
#[derive(Debug, Serialize)]
struct LogisticTiming {
    ns_per_value: f64,
    /// Logistic units in a network-step: the hidden and the output neurons.
    per_network_step: usize,
    /// Their share of the batched path's network-step on the best level.
    percent_of_batched_network_step: f64,
}

/// Declares `logistic_rounds`, compiled for the batched path's targets.
macro_rules! logistic_rounds {
    ($avx512:tt, $avx2:tt) => {
        /// Applies the logistic function `rounds` times over to every value, on the
        /// CPU's best SIMD level.
        #[multiversion(targets($avx512, $avx2))]
        pub fn logistic_rounds(values: &mut [Lanes<LANES>], rounds: usize) {
            for _ in 0..rounds {
                for v in values.iter_mut() {
                    *v = sigmoid(*v);
                }
            }
        }
    };
}
psa_sim::with_simd_targets!(logistic_rounds!());

/// Blocks of [`LANES`] values in the logistic function's benchmark (16 KiB,
/// which stay in the first-level cache).
pub const LOGISTIC_BLOCKS: usize = 64;

/// `blocks` blocks of arguments for [`logistic_rounds`], spread over [-4, 4],
/// where the function is not saturated.
pub fn logistic_arguments(blocks: usize) -> Vec<Lanes<LANES>> {
    (0..blocks)
        .map(|b| Lanes(std::array::from_fn(|l| ((b * LANES + l) % 97) as f64 / 12.0 - 4.0)))
        .collect()
}

/// ns per value of the logistic function (median of `rounds` rounds of
/// about 4 million values, which stay in the first-level cache).
fn logistic_ns_per_value(rounds: u64) -> f64 {
    const REPEATS: usize = 2000;
    let mut values = logistic_arguments(LOGISTIC_BLOCKS);
    let samples: Vec<f64> = (0..rounds)
        .map(|_| {
            let start = Instant::now();
            logistic_rounds(std::hint::black_box(&mut values), REPEATS);
            start.elapsed().as_nanos() as f64 / (LOGISTIC_BLOCKS * LANES * REPEATS) as f64
        })
        .collect();
    std::hint::black_box(&values);
    median(samples)
}

/// One backend's timing.
#[derive(Debug, Serialize)]
struct StepTiming {
    backend: BackendKind,
    median_ns_per_step: f64,
    min_ns_per_step: f64,
    relative_to_ode: f64,
}

/// Our ODE path (`step` and `planar_state` through the backend trait)
/// against the bare sequence of ODE calls it makes.
#[derive(Debug, Serialize)]
struct OdePathTiming {
    ours_ns_per_step: f64,
    bare_ns_per_step: f64,
    overhead_percent: f64,
}

/// The machine the numbers were measured on.
#[derive(Debug, Serialize)]
pub struct Machine {
    /// The CPU's model name (the architecture where it is not known).
    pub cpu: String,
    /// Cores (hardware threads) available to the process.
    pub cores: usize,
}

impl std::fmt::Display for Machine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({} cores)", self.cpu, self.cores)
    }
}

/// This machine.
pub fn machine() -> Machine {
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
    if let Some(floor) = args.speedup_floor {
        return super::bench_floor::run(floor, args.speedup_level, args.networks, args.rounds, args.json);
    }
    if args.kernel_only {
        let kernel = kernel_rows(&args.kernel_networks, args.rounds, args.kernel_host)?;
        if args.json {
            say!(
                "{}",
                serde_json::to_string_pretty(&serde_json::json!({ "cuda_kernel": kernel }))?
            );
        } else {
            print_kernel_rows(&kernel)?;
        }
        return Ok(0);
    }
    let model = BodySettings::default().model()?;
    let settings = psa_sim::physics::StepSettings::default();
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
    let medians: Vec<f64> = samples.iter().map(|s| median(s.clone())).collect();
    let ode = medians[0];
    let timings: Vec<StepTiming> = kinds
        .iter()
        .zip(&samples)
        .zip(&medians)
        .map(|((&backend, s), &m)| StepTiming {
            backend,
            median_ns_per_step: m,
            min_ns_per_step: s.iter().copied().fold(f64::INFINITY, f64::min),
            relative_to_ode: m / ode,
        })
        .collect();
    let (ours, bare) = OdeBackend::overhead_sample(
        &model,
        &settings,
        &commands,
        args.steps as usize,
        3 * args.rounds as usize,
    )?;
    let ode_path = OdePathTiming {
        ours_ns_per_step: ours.as_nanos() as f64 / args.steps as f64,
        bare_ns_per_step: bare.as_nanos() as f64 / args.steps as f64,
        overhead_percent: 100.0 * (ours.as_secs_f64() / bare.as_secs_f64() - 1.0),
    };
    let networks = random_networks(args.networks)?;
    let steps_per_evaluation = PsaSettings::default().steps as f64;
    let evaluations = EvaluationPath::all()
        .into_iter()
        .map(|path| {
            let one = evaluations_per_second(&path, &networks, 1, args.rounds)?;
            let two = evaluations_per_second(&path, &networks, 2, args.rounds)?;
            Ok(EvaluationTiming {
                path,
                evaluations_per_second_1_thread: one,
                evaluations_per_second_2_threads: two,
                speedup_2_threads: two / one,
                ns_per_network_step_1_thread: 1e9 / (one * steps_per_evaluation),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let lockstep = super::bench_ode::lockstep_by_world_size(&networks, args.rounds)?;
    let best_batched = evaluations
        .iter()
        .filter(|e| matches!(e.path.path, EvalPath::Simd(_)) && !e.path.input_noise)
        .map(|e| e.ns_per_network_step_1_thread)
        .next_back();
    let logistic_ns = logistic_ns_per_value(args.rounds);
    let per_network_step = HIDDEN + THRUSTER_COUNT;
    let logistic = LogisticTiming {
        ns_per_value: logistic_ns,
        per_network_step,
        percent_of_batched_network_step: best_batched
            .map_or(f64::NAN, |ns| 100.0 * per_network_step as f64 * logistic_ns / ns),
    };
    let generations = args.generations as usize;
    let evolve = evolve_workload(generations)?.scaling(args.rounds)?;
    let replicate = replicate_workload(generations)?.scaling(args.rounds)?;
    // Long enough that the set-up before the first generation does not count.
    let overhead = algorithm_overhead(5 * generations, args.rounds)?;
    let kernel = kernel_rows(&args.kernel_networks, args.rounds, args.kernel_host)?;
    let machine = machine();
    if args.json {
        let out = serde_json::json!({
            "machine": machine,
            "steps_per_round": args.steps,
            "rounds": args.rounds,
            "physics_step": timings,
            "ode_path": ode_path,
            "networks_per_round": args.networks,
            "psa_evaluation": evaluations,
            "ode_lockstep_by_world_size": lockstep,
            "simd_level_in_use": SimdLevel::detect(),
            "logistic_function": logistic,
            "evolve": evolve,
            "replicate": replicate,
            "algorithm_overhead": overhead,
            "cuda_kernel": kernel,
        });
        say!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        say!("machine: {machine}; batched path runs on {}", SimdLevel::detect());
        say!(
            "physics step, PSA body, dt {} s ({} rounds x {} steps, median):",
            settings.dt,
            args.rounds,
            args.steps
        );
        say!("{:<8} {:>10} {:>10} {:>8}", "backend", "ns/step", "min", "vs ode");
        for t in &timings {
            say!(
                "{:<8} {:>10.1} {:>10.1} {:>7.3}x",
                t.backend.name(),
                t.median_ns_per_step,
                t.min_ns_per_step,
                t.relative_to_ode
            );
        }
        say!(
            "ode path: {:.1} ns/step ours (step + state through the trait) vs {:.1} bare ODE calls: overhead {:.1} % (fastest of {} rounds each)",
            ode_path.ours_ns_per_step,
            ode_path.bare_ns_per_step,
            ode_path.overhead_percent,
            3 * args.rounds
        );
        say!(
            "PSA network evaluations (7-5-4 random networks, task 1, {} steps each, {} networks per round, median):",
            steps_per_evaluation,
            args.networks
        );
        say!(
            "{:<34} {:>14} {:>14} {:>9} {:>16}",
            "path",
            "evals/s 1 thr",
            "evals/s 2 thr",
            "speed-up",
            "ns/network-step"
        );
        for e in &evaluations {
            say!(
                "{:<34} {:>14.0} {:>14.0} {:>8.2}x {:>16.1}",
                e.path.label(),
                e.evaluations_per_second_1_thread,
                e.evaluations_per_second_2_threads,
                e.speedup_2_threads,
                e.ns_per_network_step_1_thread
            );
        }
        let sizes: Vec<String> = lockstep
            .iter()
            .map(|t| format!("{} {:.1}", t.bodies, t.ns_per_network_step))
            .collect();
        say!(
            "ode lockstep, ns/network-step by bodies per world (1 thread, median): {}",
            sizes.join(", ")
        );
        say!(
            "logistic function alone (blocks of {LANES} values, best SIMD level): {:.2} ns per value; the {} of a network-step take {:.1} % of the batched network-step",
            logistic.ns_per_value,
            logistic.per_network_step,
            logistic.percent_of_batched_network_step
        );
        for (what, s) in [("evolve", &evolve), ("replicate", &replicate)] {
            say!(
                "{what}: {}: {:.3} s on 1 thread, {:.3} s on 2 threads (median of {}): speed-up {:.2}x",
                s.description,
                s.seconds_1_thread,
                s.seconds_2_threads,
                s.rounds,
                s.speedup
            );
        }
        say!(
            "algorithm overhead (everything but network evaluation, 1 thread): {:.2} % of generation time ({})",
            overhead.percent,
            overhead.description
        );
        print_kernel_rows(&kernel)?;
    }
    Ok(0)
}

/// The cuda kernel's rows as a table.
fn print_kernel_rows(kernel: &KernelBench) -> Result<()> {
    let Some(why) = &kernel.unavailable else {
        say!(
            "cuda kernel on {} against native batched on 1 thread (task 1, one launch per round, median):",
            kernel.device
        );
        say!(
            "{:>10} {:>22} {:>24} {:>20}",
            "networks",
            "kernel ns/net-step",
            "with copies ns/net-step",
            "native ns/net-step"
        );
        for row in &kernel.rows {
            let kernel_ns = row
                .kernel_ns_per_network_step
                .map_or_else(|| "-".to_string(), |ns| format!("{ns:.4}"));
            say!(
                "{:>10} {:>22} {:>24.4} {:>20.3}",
                row.networks,
                kernel_ns,
                row.end_to_end_ns_per_network_step,
                row.native_ns_per_network_step
            );
        }
        return Ok(());
    };
    say!("cuda kernel: not measured: {why}");
    Ok(())
}
