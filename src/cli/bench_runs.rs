//! The whole-run part of `psa-esp bench`: `evolve` and `replicate` on 1 and
//! 2 threads, and the share of a generation's time that is not network
//! evaluation (sorting, recombination, mutation, bookkeeping, records).

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::Result;
use serde::Serialize;

use esp_neuroevolution::network::{Network, NetworkSet};
use esp_neuroevolution::rng::{Stream, StreamFamily};
use esp_neuroevolution::{Esp, Evaluator};
use psa_experiment::grid::replicate::{replicate, GridProgress, ReplicateOptions};
use psa_experiment::grid::runner::FinishedRun;
use psa_experiment::grid::{GridPreset, GridSpec};
use psa_experiment::{GridConfig, Preset, RunConfig};
use psa_sim::evaluator::{EvalPath, PsaEvaluator};
use psa_sim::physics::BackendKind;
use psa_sim::psa::Task;

/// A whole-run workload timed on 1 and on 2 threads.
#[derive(Debug, Serialize)]
pub struct RunScaling {
    /// What was run.
    pub description: String,
    /// Median seconds on 1 thread.
    pub seconds_1_thread: f64,
    /// Median seconds on 2 threads.
    pub seconds_2_threads: f64,
    /// seconds_1_thread / seconds_2_threads.
    pub speedup: f64,
    /// Rounds per thread count.
    pub rounds: u64,
}

/// The share of generation time spent outside network evaluation.
#[derive(Debug, Serialize)]
pub struct AlgorithmOverhead {
    /// What was run.
    pub description: String,
    /// Median over rounds, in % of the run's time.
    pub percent: f64,
}

/// The median of the bench's samples (the upper one of an even count).
pub(super) fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// A whole-run workload that runs on any number of threads.
pub struct Workload {
    /// Its short name: the command it stands for.
    pub name: &'static str,
    /// What is run.
    pub description: String,
    work: Box<dyn Fn(usize) -> Result<()>>,
}

impl Workload {
    /// Runs it once on `threads` threads.
    pub fn run(&self, threads: usize) -> Result<()> {
        (self.work)(threads)
    }

    /// Times it on 1 and 2 threads, interleaved, `rounds` times each.
    pub fn scaling(&self, rounds: u64) -> Result<RunScaling> {
        let (mut one, mut two) = (Vec::new(), Vec::new());
        for _ in 0..rounds {
            for (threads, samples) in [(1, &mut one), (2, &mut two)] {
                let clock = Instant::now();
                self.run(threads)?;
                samples.push(clock.elapsed().as_secs_f64());
            }
        }
        let (seconds_1_thread, seconds_2_threads) = (median(one), median(two));
        Ok(RunScaling {
            description: self.description.clone(),
            seconds_1_thread,
            seconds_2_threads,
            speedup: seconds_1_thread / seconds_2_threads,
            rounds,
        })
    }
}

/// The baseline ESP configuration on `native`, cut to `generations`.
fn baseline(generations: usize) -> Result<RunConfig> {
    let mut config = Preset::Baseline.config();
    config.problem.backend = BackendKind::Native;
    config.set_generations(generations)?;
    Ok(config)
}

/// One baseline ESP run of task 3 on the default (batched) native path.
pub fn evolve_workload(generations: usize) -> Result<Workload> {
    let config = baseline(generations)?;
    let evaluator = PsaEvaluator::new(config.problem.clone(), Task::StopAtPosition, &EvalPath::Fastest)?;
    let esp = Esp::new(config.esp.clone(), 1).map_err(anyhow::Error::msg)?;
    Ok(Workload {
        name: "evolve",
        description: format!("one baseline ESP run, task 3, native, {generations} generations"),
        work: Box::new(move |threads| {
            psa_sim::ode::thread_pool(threads)?.install(|| esp.run(&evaluator, |_| {}))?;
            Ok(())
        }),
    })
}

struct Silent;
impl GridProgress for Silent {
    fn start(&self, _: usize, _: usize) {}
    fn finished(&self, _: &std::path::Path, _: &FinishedRun) {}
}

/// A small grid (baseline and max-credit, 3 tasks, 2 seeds, 50-trial
/// robustness tests) replicated into a fresh temporary folder.
pub fn replicate_workload(generations: usize) -> Result<Workload> {
    let spec = GridSpec {
        configs: vec![
            GridConfig::Preset(Preset::Baseline),
            GridConfig::Preset(Preset::MaxCredit),
        ],
        seeds: 2,
        first_seed: 1,
        generations,
        backend: BackendKind::Native,
        robustness_trials: 50,
        ..GridSpec::from_preset(GridPreset::Quick)
    };
    let runs = spec.runs().len();
    Ok(Workload {
        name: "replicate",
        description: format!(
            "replicate of {runs} runs (2 configurations x 3 tasks x 2 seeds), native, {generations} generations"
        ),
        work: Box::new(move |threads| {
            let dir = tempfile::Builder::new().prefix("psa-esp-bench-").tempdir()?;
            let options = ReplicateOptions {
                threads,
                ..ReplicateOptions::default()
            };
            replicate(dir.path(), &spec, &options, &Silent)?;
            Ok(())
        }),
    })
}

/// An evaluator that adds the wall time spent evaluating to a counter.
struct Timed<'a> {
    inner: &'a PsaEvaluator,
    nanos: &'a AtomicU64,
}

impl Timed<'_> {
    fn time<T>(&self, f: impl FnOnce() -> T) -> T {
        let clock = Instant::now();
        let out = f();
        self.nanos
            .fetch_add(clock.elapsed().as_nanos() as u64, Ordering::Relaxed);
        out
    }
}

impl Evaluator for Timed<'_> {
    type Worker = <PsaEvaluator as Evaluator>::Worker;
    fn inputs(&self) -> usize {
        self.inner.inputs()
    }
    fn outputs(&self) -> usize {
        self.inner.outputs()
    }
    fn worker(&self) -> Result<Self::Worker> {
        self.inner.worker()
    }
    fn evaluate(&self, worker: &mut Self::Worker, network: &Network, rng: &mut Stream) -> Result<f64> {
        self.time(|| self.inner.evaluate(worker, network, rng))
    }
    fn batch_size(&self) -> usize {
        self.inner.batch_size()
    }
    fn narrowest_batch(&self) -> usize {
        self.inner.narrowest_batch()
    }
    fn evaluate_batch<S: NetworkSet + ?Sized>(
        &self,
        worker: &mut Self::Worker,
        networks: &S,
        range: Range<usize>,
        streams: &StreamFamily,
    ) -> Result<Vec<f64>> {
        self.time(|| self.inner.evaluate_batch(worker, networks, range, streams))
    }
}

/// The share of a baseline ESP run's time (1 thread, task 3, native
/// batched) spent outside the evaluator.
pub fn algorithm_overhead(generations: usize, rounds: u64) -> Result<AlgorithmOverhead> {
    let config = baseline(generations)?;
    let evaluator = PsaEvaluator::new(config.problem.clone(), Task::StopAtPosition, &EvalPath::Fastest)?;
    let esp = Esp::new(config.esp.clone(), 1).map_err(anyhow::Error::msg)?;
    let pool = psa_sim::ode::thread_pool(1)?;
    let mut shares = Vec::new();
    for _ in 0..rounds {
        let nanos = AtomicU64::new(0);
        let timed = Timed {
            inner: &evaluator,
            nanos: &nanos,
        };
        let clock = Instant::now();
        pool.install(|| esp.run(&timed, |_| {}))?;
        let total = clock.elapsed().as_nanos() as f64;
        shares.push(100.0 * (1.0 - nanos.load(Ordering::Relaxed) as f64 / total));
    }
    Ok(AlgorithmOverhead {
        description: format!("baseline ESP, task 3, native batched, {generations} generations"),
        percent: median(shares),
    })
}
