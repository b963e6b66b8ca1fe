//! `psa-esp bench --speedup-floor RATIO`: the batched path's speed-up over
//! the scalar path, both on `native`, 1 thread, timed in one run with their
//! rounds interleaved so that a noisy host slows both alike. A build whose
//! batched path falls back to slow code (the portable level, or the
//! sensor read that once cost 3x) falls below a floor that the AVX2 and
//! AVX-512 paths clear with room: CI runs it (`.ci/run`).

use anyhow::{bail, Result};
use psa_sim::named::Named;
use serde::Serialize;

use super::bench_networks::random_networks;
use super::bench_paths::{evaluation_rate, EvaluationPath};
use super::bench_runs::median;
use super::EXIT_CHECK_FAILED;
use psa_sim::evaluator::{EvalPath, PsaEvaluator};
use psa_sim::numeric::SimdLevel;
use psa_sim::physics::BackendKind;

/// What the check measured.
#[derive(Debug, Serialize)]
pub struct SpeedupCheck {
    /// The batched path's SIMD level.
    pub level: SimdLevel,
    /// Evaluations per second on the scalar path (median round).
    pub scalar_per_second: f64,
    /// Evaluations per second on the batched path (median round).
    pub batched_per_second: f64,
    /// The median of the rounds' ratios, batched over scalar.
    pub speedup: f64,
    /// The floor it was held to.
    pub floor: f64,
    /// Whether the speed-up reached the floor.
    pub passed: bool,
}

/// Times `networks` random networks on task 1 on the scalar path and on
/// the batched path at `level` (the CPU's best where `None`), `rounds`
/// rounds each, interleaved, on 1 thread; the median round's ratio is
/// held to `floor`.
pub fn check(floor: f64, level: Option<SimdLevel>, networks: u64, rounds: u64) -> Result<SpeedupCheck> {
    if !(floor.is_finite() && floor > 0.0) {
        bail!("--speedup-floor {floor}: expected a positive ratio");
    }
    let level = level.unwrap_or_else(SimdLevel::detect);
    if !level.is_supported() {
        bail!("--speedup-level {}: this CPU does not support it", level.name());
    }
    // Fewer networks than one block of the batched path at this level
    // leave nothing to batch: its speed-up could not be told from its padding.
    let block = psa_sim::psa::batch::BatchRunner::widest_block(level) as u64;
    if networks < block {
        bail!(
            "--speedup-floor with --networks {networks}: the batched path flies blocks of {block} networks at the {} level, so fewer leave nothing to batch and its speed-up cannot be measured; give --networks {block} or more",
            level.name()
        );
    }
    let evaluator = |path| {
        EvaluationPath {
            backend: BackendKind::Native,
            path,
            input_noise: false,
        }
        .evaluator()
    };
    let scalar = evaluator(EvalPath::Scalar)?;
    let batched = evaluator(EvalPath::Simd(level))?;
    let networks = random_networks(networks)?;
    let pool = psa_sim::ode::thread_pool(1)?;
    let rate = |evaluator: &PsaEvaluator, round: u64| pool.install(|| evaluation_rate(evaluator, &networks, round));
    let (mut scalar_rates, mut batched_rates, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    for round in 0..rounds {
        let s = rate(&scalar, round)?;
        let b = rate(&batched, round)?;
        scalar_rates.push(s);
        batched_rates.push(b);
        ratios.push(b / s);
    }
    let speedup = median(ratios);
    Ok(SpeedupCheck {
        level,
        scalar_per_second: median(scalar_rates),
        batched_per_second: median(batched_rates),
        speedup,
        floor,
        passed: speedup >= floor,
    })
}

/// Runs the check and reports it: exit 0 when the speed-up reaches the
/// floor, [`EXIT_CHECK_FAILED`] when it does not.
pub fn run(floor: f64, level: Option<SimdLevel>, networks: u64, rounds: u64, json: bool) -> Result<i32> {
    let c = check(floor, level, networks, rounds)?;
    if json {
        say!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        say!(
            "batched path ({}) {:.0} evaluations/s, scalar {:.0} (1 thread, median of {rounds} interleaved rounds of {networks} networks): speed-up {:.2}x, floor {:.2}x: {}",
            c.level.name(),
            c.batched_per_second,
            c.scalar_per_second,
            c.speedup,
            c.floor,
            if c.passed { "passed" } else { "FAILED: the batched path runs slow code" }
        );
    }
    Ok(if c.passed { 0 } else { EXIT_CHECK_FAILED })
}
