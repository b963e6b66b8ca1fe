//! `psa-esp replicate`: the paper's experiment grid.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::Result;

use super::backend::{BackendArg, EvalPathArg};
use super::choice::choice;
use super::evolve::progress_bar;
use esp_neuroevolution::MAX_GENERATIONS;
use psa_experiment::grid::lockstep::Executor;
use psa_experiment::grid::replicate::{describe, replicate, GridProgress, HeldRun, ReplicateOptions};
use psa_experiment::grid::runner::FinishedRun;
use psa_experiment::grid::shard::Shard;
use psa_experiment::grid::{GridPreset, GridSpec, MAX_SEEDS};
use psa_experiment::GridConfig;
use psa_sim::evaluator::EvalPath;
use psa_sim::ode::MAX_THREADS;
use psa_sim::physics::BackendKind;
use psa_sim::psa::settings::limits::MAX_TRIALS;
use psa_sim::psa::Task;

/// Arguments of `replicate`.
#[derive(Debug, clap::Args)]
pub struct ReplicateArgs {
    /// The grid.
    #[command(flatten)]
    pub grid: GridArgs,
    /// The grid's directory; running the same command again resumes it.
    #[arg(long)]
    pub out: PathBuf,
}

/// The options that define a grid (shared by `replicate` and `sweep`).
#[derive(Debug, clap::Args)]
pub struct GridArgs {
    /// quick: a reduced grid (5 seeds, 80 generations, 100-trial robustness,
    /// native backend; about a minute on 2 cores); paper: the full protocol
    /// (30 seeds, 2000 generations, 500-trial robustness, native backend).
    #[arg(long, value_parser = choice::<GridPreset>(), default_value_t = GridPreset::Quick)]
    pub preset: GridPreset,
    /// Configurations, comma-separated (default: the paper's baseline,
    /// systematic, max-credit, lesion-off, erase-best, hill-climb,
    /// input-noise, random-init; also gomez, Gomez's ESP, which the paper
    /// did not run).
    #[arg(long, value_delimiter = ',')]
    pub configs: Option<Vec<GridConfig>>,
    /// Tasks, comma-separated (default: 1,2,3).
    #[arg(long, value_delimiter = ',')]
    pub tasks: Option<Vec<Task>>,
    /// Seeds per configuration and task (seeds F to F+N-1 with F the
    /// --first-seed, at most 10,000).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_SEEDS))]
    pub seeds: Option<u64>,
    /// The first seed (default 1): `--first-seed 31 --seeds 30` runs seeds
    /// 31 to 60, the same runs as seeds 31 to 60 of a larger grid. On an
    /// existing grid whose seeds end at F-1 it adds these seeds to it.
    #[arg(long, value_name = "F", value_parser = clap::value_parser!(u64).range(1..))]
    pub first_seed: Option<u64>,
    /// Generations (ESP) or cycles (hill-climber) per run (at most 1,000,000).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_GENERATIONS as u64))]
    pub generations: Option<u64>,
    /// Physics backend (`cuda`: native's physics on the GPU, the runs in lockstep).
    #[arg(long, value_parser = BackendArg::parser())]
    pub backend: Option<BackendArg>,
    /// Fly every champion again on ode after its run on native: its fitness
    /// and robustness results must be bit-identical, recorded in run.json
    /// (default: on for --preset paper on native).
    #[arg(long, overrides_with = "no_ode_check")]
    pub ode_check: bool,
    /// Skip the ODE check of --ode-check.
    #[arg(long, overrides_with = "ode_check")]
    pub no_ode_check: bool,
    /// Trials of each robustness test (at most 1,000,000).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_TRIALS))]
    pub robustness_trials: Option<u64>,
    /// A TOML file of settings laid over every configuration of the grid
    /// (before each configuration's own change); recorded in grid.json.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Worker threads (0 = one per core; at most 1024). Results do not depend on it.
    #[arg(long, alias = "jobs", default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=MAX_THREADS as u64))]
    pub threads: u64,
    /// Run only shard I of N (I from 0): runs I, I+N, I+2N, ... of the
    /// grid's run order, into the same --out (e.g. one per task of a SLURM
    /// job array). Results do not depend on it.
    #[arg(long, value_name = "I/N", default_value_t = Shard::ALL)]
    pub shard: Shard,
    /// How long another process's claim on a run (its claim.json) holds
    /// before this process takes the run over, e.g. 48h or 90m; a claim of a
    /// process of this host that is gone is taken over at once.
    #[arg(long, value_name = "DURATION", default_value = "48h", value_parser = parse_duration)]
    pub claim_timeout: Duration,
    /// Print nothing while the grid runs (no bars, no lines per run).
    #[arg(long)]
    pub quiet: bool,
    /// Advance all runs together, a generation per round, each round's
    /// networks of every run evaluated as one batch (for evaluators that
    /// gain from large batches). Results do not depend on it.
    #[arg(long)]
    pub lockstep: bool,
    /// Where the networks are evaluated.
    #[command(flatten)]
    pub eval: EvalPathArg,
}

/// A duration such as `48h`, `90m` or `1h 30m`, above zero.
fn parse_duration(text: &str) -> Result<Duration, String> {
    match humantime::parse_duration(text) {
        Ok(d) if !d.is_zero() => Ok(d),
        Ok(_) => Err("the duration must be above zero".into()),
        Err(e) => Err(format!("{e} (write e.g. 48h, 90m or 1h 30m)")),
    }
}

impl GridArgs {
    /// The executor these options ask for.
    pub fn executor(&self) -> Executor {
        if self.lockstep || self.backend == Some(BackendArg::Cuda) {
            Executor::Lockstep
        } else {
            Executor::RunByRun
        }
    }

    /// The grid these options describe.
    pub fn spec(&self) -> Result<GridSpec> {
        let mut spec = GridSpec::from_preset(self.preset);
        if let Some(path) = &self.config {
            spec.overrides = Some(read_overrides(path)?);
        }
        if let Some(c) = &self.configs {
            spec.configs = c.clone();
        }
        if let Some(t) = &self.tasks {
            spec.tasks = t.clone();
        }
        spec.seeds = self.seeds.unwrap_or(spec.seeds);
        spec.first_seed = self.first_seed.unwrap_or(spec.first_seed);
        spec.generations = self.generations.map_or(spec.generations, |g| g as usize);
        spec.backend = self.backend.map_or(spec.backend, BackendArg::physics);
        spec.robustness_trials = self.robustness_trials.map_or(spec.robustness_trials, |t| t as usize);
        spec.ode_check = match (self.ode_check, self.no_ode_check) {
            (true, _) => true,
            (_, true) => false,
            _ => self.preset == GridPreset::Paper && spec.backend == BackendKind::Native,
        };
        Ok(spec)
    }

    /// How the grid runs: threads, shard, claim timeout, executor and
    /// evaluation path (for `--backend cuda` the GPU, opened here: see
    /// [`BackendArg::eval_path`]).
    pub fn options(&self) -> Result<ReplicateOptions> {
        Ok(ReplicateOptions {
            threads: self.threads as usize,
            shard: self.shard,
            claim_timeout: self.claim_timeout,
            executor: self.executor(),
            eval_path: BackendArg::eval_path(self.backend, self.eval.eval_path.clone())?,
        })
    }
}

/// The text of a `--config` file, checked to be a valid overlay of the baseline.
pub fn read_overrides(path: &std::path::Path) -> Result<String> {
    use anyhow::Context;
    let text = psa_sim::io::read_input(path, "configuration")?;
    psa_experiment::RunConfig::baseline_with(&text).with_context(|| format!("configuration {}", path.display()))?;
    Ok(text)
}

/// What the user sees while a grid runs: on a terminal, a bar over the
/// grid and a line per finished run above it; otherwise (a pipe, a file, a
/// batch job) a plain line per finished run with the count and an ETA;
/// nothing with `--quiet`.
pub struct Progress {
    /// The bar (hidden unless standard error is a terminal).
    pub bar: indicatif::ProgressBar,
    lines: bool,
    /// Whether a finished run's line names its grid's folder (a sweep's variant).
    name_grids: bool,
    state: Mutex<ProgressState>,
}

/// The counts behind [`Progress`].
struct ProgressState {
    total: usize,
    done: usize,
    ran: usize,
    best: f64,
    clock: Instant,
}

impl Progress {
    /// A bar on a terminal, lines elsewhere, nothing when `quiet`; with
    /// `name_grids`, each finished run's line names its grid's folder.
    pub fn new(quiet: bool, name_grids: bool) -> Progress {
        let bar = progress_bar(
            0,
            "{spinner} runs {pos}/{len} [{bar:30}] {msg} elapsed {elapsed} ETA {eta}",
        );
        let terminal = std::io::stderr().is_terminal();
        if quiet || !terminal {
            bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
        }
        Progress {
            bar,
            lines: !quiet && !terminal,
            name_grids,
            state: Mutex::new(ProgressState {
                total: 0,
                done: 0,
                ran: 0,
                best: f64::NEG_INFINITY,
                clock: Instant::now(),
            }),
        }
    }
}

impl GridProgress for Progress {
    fn start(&self, total: usize, done: usize) {
        let mut state = self.state.lock().expect("no panics while holding the lock");
        *state = ProgressState {
            total,
            done,
            ran: 0,
            best: state.best,
            clock: Instant::now(),
        };
        self.bar.set_length(total as u64);
        self.bar.set_position(done as u64);
        self.bar.reset_eta();
    }

    fn finished(&self, grid: &Path, run: &FinishedRun) {
        let mut state = self.state.lock().expect("no panics while holding the lock");
        state.best = state.best.max(run.outcome.champion_fitness);
        state.done += 1;
        state.ran += 1;
        let variant = match grid.file_name() {
            Some(name) if self.name_grids => format!("{}: ", name.to_string_lossy()),
            _ => String::new(),
        };
        let what = format!(
            "{variant}finished {} task {} seed {}: champion {:.1} % ({:.0} s)",
            run.key.config, run.key.task, run.key.seed, run.outcome.champion_fitness, run.outcome.seconds
        );
        if self.lines {
            // Runs still to do at this process's pace so far.
            let left = state.total.saturating_sub(state.done);
            let eta = state.clock.elapsed().as_secs_f64() / state.ran as f64 * left as f64;
            let eta = humantime::format_duration(Duration::from_secs(eta.round() as u64));
            eprintln!("{what}; {}/{} runs done, ETA {eta}", state.done, state.total);
        } else {
            self.bar.println(what);
        }
        self.bar.set_message(format!("best champion {:.1} %", state.best));
        self.bar.inc(1);
    }
}

/// Prints the runs other processes held, left to them.
pub fn report_held<'a>(held: impl Iterator<Item = (String, &'a HeldRun)>) {
    for (prefix, h) in held {
        eprintln!(
            "left to another process: {prefix}{} task {} seed {} (claimed by {})",
            h.key.config, h.key.task, h.key.seed, h.claim
        );
    }
}

/// Runs `replicate`.
pub fn run(args: ReplicateArgs) -> Result<i32> {
    let spec = args.grid.spec()?;
    let progress = Progress::new(args.grid.quiet, false);
    let options = args.grid.options()?;
    let clock = Instant::now();
    super::require_utf8_folder("--out", &args.out)?;
    let summary = replicate(&args.out, &spec, &options, &progress);
    progress.bar.finish_and_clear();
    report_gpu_share(&options.eval_path, clock.elapsed().as_secs_f64())?;
    let summary = summary?;
    report_held(summary.held.iter().map(|h| (String::new(), h)));
    let shard = if options.shard == Shard::ALL {
        String::new()
    } else {
        format!(", shard {}", options.shard)
    };
    say!(
        "grid {} ({}{shard}): {} runs, {} already finished, {} run now, {} left to other processes, in {:.0} s",
        args.out.display(),
        describe(&spec),
        summary.total,
        summary.skipped,
        summary.ran,
        summary.held.len(),
        summary.seconds
    );
    say!("next: psa-esp report {}", args.out.display());
    Ok(0)
}

/// With `--backend cuda`, the wall time the GPU evaluated (a launch in
/// flight, its copies included) of the command's `seconds` (printed
/// whether or not its runs all succeeded).
pub fn report_gpu_share(path: &EvalPath, seconds: f64) -> Result<()> {
    if let EvalPath::Kernel(flier) = path {
        if let Some(busy) = flier.busy() {
            let busy = busy.as_secs_f64();
            say!(
                "GPU evaluation (a launch in flight, copies included): {busy:.1} s of the {seconds:.1} s ({:.0} %)",
                100.0 * busy / seconds.max(f64::MIN_POSITIVE)
            );
        }
    }
    Ok(())
}
