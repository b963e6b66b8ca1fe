//! Batched evaluation of networks on a task: the native batched path over
//! the crate's threads, with the GIL released; every network flown as
//! `psa-esp replay --seed S` flies it, so the same bits.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use esp_neuroevolution::network::Network;
use esp_neuroevolution::rayon::prelude::*;
use esp_neuroevolution::rayon::ThreadPool;
use esp_neuroevolution::rng::{stream, Stream};
use esp_neuroevolution::{evaluate_all, Evaluator};
use numpy::IntoPyArray;
use psa_sim::evaluator::{EvalPath, PsaEvaluator};
use psa_sim::psa::{PsaSettings, Task, INPUT_COUNT, THRUSTER_COUNT};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

use crate::args::{self, SeedArg};
use crate::config::{run_config, type_name};
use crate::errors;
use crate::weights::networks_from;

/// The key of `psa-esp replay`'s random stream (`src/cli/replay.rs`): a
/// network evaluated with seed `S` draws its random starts and noise from
/// `stream(S, [REPLAY_STREAM])`, trial after trial, as `replay --seed S`
/// does. The tests hold the two to the same bits.
pub const REPLAY_STREAM: u64 = 301;

/// The seed `evaluate` flies with when none is given: `psa-esp replay`'s
/// default.
pub const DEFAULT_SEED: u64 = 1;

/// The task numbered `task`, or a `ValueError`.
fn task_of(task: u8) -> PyResult<Task> {
    Task::try_from(task).map_err(PyValueError::new_err)
}

/// The task numbered by the argument `task` (an int or a NumPy integer).
pub fn task_arg(task: &Bound<'_, PyAny>) -> PyResult<Task> {
    let number = args::count(task, "task")?;
    task_of(u8::try_from(number).map_err(|_| PyValueError::new_err(format!("task must be 1, 2 or 3, got {number}")))?)
}

/// The evaluation path named `name`, or a `ValueError` listing the names.
pub fn eval_path(name: &str) -> PyResult<EvalPath> {
    name.parse().map_err(PyValueError::new_err)
}

/// A thread pool of `threads` workers (None or 0: one per core), made once
/// per count, each thread ready for ODE's worlds.
pub fn pool(threads: Option<usize>) -> PyResult<Arc<ThreadPool>> {
    static POOLS: OnceLock<Mutex<HashMap<usize, Arc<ThreadPool>>>> = OnceLock::new();
    let threads = threads.unwrap_or(0);
    let mut pools = POOLS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(pool) = pools.get(&threads) {
        return Ok(pool.clone());
    }
    let pool =
        Arc::new(psa_sim::ode::thread_pool(threads).map_err(|e| PyValueError::new_err(format!("threads: {e}")))?);
    pools.insert(threads, pool.clone());
    Ok(pool)
}

/// One seed for every network, or a seed per network.
fn seeds(seed: &Bound<'_, PyAny>, count: usize) -> PyResult<Vec<u64>> {
    if args::is_integer(seed) || seed.cast::<pyo3::types::PyFloat>().is_ok() {
        return Ok(vec![args::seed(seed, "seed")?; count]);
    }
    if seed.cast::<pyo3::types::PyString>().is_ok() {
        return Err(PyTypeError::new_err(format!(
            "seed must be an int or a sequence of one int per network, got {}",
            type_name(seed)
        )));
    }
    let items: Vec<Bound<'_, PyAny>> = seed.try_iter().and_then(|items| items.collect()).map_err(|_| {
        PyTypeError::new_err(format!(
            "seed must be an int or a sequence of one non-negative int per network, got {}",
            type_name(seed)
        ))
    })?;
    let many = items
        .iter()
        .enumerate()
        .map(|(j, item)| args::seed(item, &format!("seed[{j}]")))
        .collect::<PyResult<Vec<u64>>>()?;
    if many.len() != count {
        return Err(PyValueError::new_err(format!(
            "seed: {} seeds for {count} networks; a seed is an integer in [0, 2**64)",
            many.len()
        )));
    }
    Ok(many)
}

/// How many batches a thread flies between two checks of Python's signals
/// in `evaluate` and `Run.evaluate_psa` (a fraction of a second at the
/// paper's 500 steps).
const PIECE_BATCHES: usize = 64;

/// The fitness of networks `0..count`, flown by `fly(range)` on `pool`
/// in pieces of many of `evaluator`'s batches a thread, the GIL released
/// inside each and Python's signals checked between them: Ctrl-C stops a
/// long call. Each network's bits do not depend on the piece it is flown
/// in; `error` turns a piece's error into Python's.
pub(crate) fn in_pieces<E>(
    py: Python<'_>,
    pool: &ThreadPool,
    evaluator: &PsaEvaluator,
    count: usize,
    fly: impl Fn(Range<usize>) -> Result<Vec<f64>, E> + Sync,
    error: impl Fn(E) -> PyErr,
) -> PyResult<Vec<f64>>
where
    E: Send,
{
    let piece = pool.current_num_threads().max(1) * evaluator.batch_size().max(1) * PIECE_BATCHES;
    let mut fitness = Vec::with_capacity(count);
    for start in (0..count).step_by(piece) {
        py.check_signals()?;
        let range = start..(start + piece).min(count);
        fitness.extend(py.detach(|| pool.install(|| fly(range))).map_err(&error)?);
    }
    Ok(fitness)
}

/// Where a batch of networks goes: full batches of the evaluator's batch
/// size, then what is left, each taken by whichever thread is free.
fn batches(count: usize, size: usize) -> Vec<Range<usize>> {
    let size = size.max(1);
    (0..count)
        .step_by(size)
        .map(|start| start..(start + size).min(count))
        .collect()
}

/// Each network's fitness, network `j` with `stream(seeds[j], [REPLAY_STREAM])`,
/// on the current rayon pool.
pub fn evaluate_networks(evaluator: &PsaEvaluator, networks: &[Network], seeds: &[u64]) -> anyhow::Result<Vec<f64>> {
    let pieces: Vec<anyhow::Result<Vec<f64>>> = batches(networks.len(), evaluator.batch_size())
        .into_par_iter()
        .with_max_len(1)
        .map_init(
            || None,
            |worker, range| {
                let worker = match worker {
                    Some(worker) => worker,
                    None => worker.insert(evaluator.worker()?),
                };
                let mut rngs: Vec<Stream> = range.clone().map(|j| stream(seeds[j], &[REPLAY_STREAM])).collect();
                evaluator.evaluate_with_streams(worker, networks, range, &mut rngs)
            },
        )
        .collect();
    let mut fitness = Vec::with_capacity(networks.len());
    for piece in pieces {
        fitness.extend(piece?);
    }
    Ok(fitness)
}

/// The problem `config` resolves to, with `trials` in place of its own.
fn problem(
    config: Option<&Bound<'_, PyAny>>,
    preset: &str,
    backend: Option<&str>,
    trials: Option<usize>,
) -> PyResult<PsaSettings> {
    let mut problem = run_config(config, preset, backend)?.problem;
    if let Some(trials) = trials {
        problem.trials = trials;
    }
    Ok(problem)
}

/// The fitness of every network in `weights` on `task` (in % of the task's
/// theoretical maximum, the mean over the configuration's trials), as a
/// float64 array.
///
/// `weights` is a float64 array of shape (networks, hidden, 11) or
/// (networks, hidden * 11): each hidden neuron's 7 input weights (bias
/// last), then its 4 output weights, as in a network file. `lesioned`, a
/// bool array (networks, hidden), switches neurons off.
///
/// `config` is a dict of settings (`{"problem": {"noise": {"input_sd":
/// 0.05}}}`) or the path of a TOML file (a run's `config.toml`), laid over
/// `preset` on the `native` backend; `trials` and `backend` replace the
/// configuration's. Network `j` is flown with the seed `seed` (an int,
/// 1 if left out) or `seed[j]` (one per network), exactly as `psa-esp
/// replay NETWORK.json --seed S --trials K` flies it: the same bits.
/// `seed=None` draws a fresh seed from the system's entropy; with
/// `return_seed=True` the result is `(fitness, seed)`, the seed as used,
/// to fly the same noise again. The networks are flown
/// on `eval_path` (`"fastest"`: native's batched SIMD path) on `threads`
/// threads (None: one per core), with the GIL released; Ctrl-C stops it
/// between pieces of a few thousand networks (`KeyboardInterrupt`).
///
/// Raises `TypeError` for an array of another dtype, `ValueError` for a
/// wrong shape, a non-finite weight (naming the network and the neuron)
/// or a bad task, seed or path, `ConfigError` for an unknown or
/// out-of-range setting, `SimulationError` if the simulator fails.
#[pyfunction]
#[pyo3(signature = (weights, task, config=None, *, seed=SeedArg::Default, trials=None, lesioned=None, preset="baseline", backend=None, eval_path="fastest", threads=None, return_seed=false))]
#[allow(clippy::too_many_arguments)]
pub fn evaluate<'py>(
    py: Python<'py>,
    weights: &Bound<'py, PyAny>,
    task: &Bound<'py, PyAny>,
    config: Option<&Bound<'py, PyAny>>,
    seed: SeedArg<'py>,
    trials: Option<&Bound<'py, PyAny>>,
    lesioned: Option<&Bound<'py, PyAny>>,
    preset: &str,
    backend: Option<&str>,
    eval_path: &str,
    threads: Option<&Bound<'py, PyAny>>,
    return_seed: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let task = task_arg(task)?;
    let path = self::eval_path(eval_path)?;
    let networks = networks_from(weights, INPUT_COUNT, THRUSTER_COUNT, lesioned, false)?;
    let seed = match seed {
        SeedArg::Default => DEFAULT_SEED.into_pyobject(py)?.into_any(),
        SeedArg::Given(seed) if seed.is_none() => args::fresh_seed(py)?.into_pyobject(py)?.into_any(),
        SeedArg::Given(seed) => seed,
    };
    let seeds = seeds(&seed, networks.len())?;
    let trials = args::optional_count(trials, "trials")?;
    let threads = args::optional_count(threads, "threads")?;
    let problem = problem(config, preset, backend, trials)?;
    let evaluator = PsaEvaluator::new(problem, task, &path).map_err(errors::config_chain)?;
    let pool = pool(threads)?;
    let fitness = in_pieces(
        py,
        &pool,
        &evaluator,
        networks.len(),
        |range| evaluate_networks(&evaluator, &networks[range.clone()], &seeds[range]),
        errors::simulation,
    )?;
    let fitness = fitness.into_pyarray(py).into_any();
    if return_seed {
        Ok((fitness, seed).into_pyobject(py)?.into_any())
    } else {
        Ok(fitness)
    }
}

/// The reference of the benchmark of `evaluate`: networks evaluated per
/// second by `esp_neuroevolution::evaluate_all` over `psa-sim`'s evaluator
/// on `eval_path` (what `psa-esp bench` times for its rows of evaluations
/// per second), for `rounds` rounds of the same `weights`; returns each
/// round's rate. No Python runs inside a round.
#[pyfunction]
#[pyo3(signature = (weights, task, *, rounds=3, config=None, preset="baseline", eval_path="fastest", threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn reference_evaluations_per_second(
    py: Python<'_>,
    weights: &Bound<'_, PyAny>,
    task: &Bound<'_, PyAny>,
    rounds: usize,
    config: Option<&Bound<'_, PyAny>>,
    preset: &str,
    eval_path: &str,
    threads: Option<usize>,
) -> PyResult<Vec<f64>> {
    let task = task_arg(task)?;
    let path = self::eval_path(eval_path)?;
    let networks = networks_from(weights, INPUT_COUNT, THRUSTER_COUNT, None, false)?;
    let problem = problem(config, preset, None, None)?;
    let evaluator = PsaEvaluator::new(problem, task, &path).map_err(errors::config_chain)?;
    let pool = pool(threads)?;
    py.detach(|| {
        (0..rounds)
            .map(|round| {
                let start = Instant::now();
                pool.install(|| evaluate_all(&evaluator, &networks[..], round as u64, &[]))?;
                Ok(networks.len() as f64 / start.elapsed().as_secs_f64())
            })
            .collect::<Result<Vec<f64>, esp_neuroevolution::RunError>>()
    })
    .map_err(errors::run)
}
