//! `psa-esp evolve`: one evolution run of a preset on a task.

use std::path::PathBuf;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};

use super::backend::{BackendArg, EvalPathArg};
use super::choice::choice;
use esp_neuroevolution::GenerationRecord;
use psa_experiment::{run_evolution, run_evolution_traced, Preset};
use psa_sim::named::Named;
use psa_sim::ode::MAX_THREADS;
use psa_sim::psa::Task;

/// Arguments of `evolve`.
#[derive(Debug, clap::Args)]
pub struct EvolveArgs {
    /// Task 1, 2 or 3.
    #[arg(long)]
    pub task: Task,
    /// The paper's configuration to start from.
    #[arg(long, value_parser = choice::<Preset>(), default_value_t = Preset::Baseline)]
    pub preset: Preset,
    /// Seed of the run.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Generations (ESP) or cycles (hill-climber), overriding the configuration.
    #[arg(long)]
    pub generations: Option<usize>,
    /// A TOML file overriding any setting of the preset (see README).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Physics backend, overriding the configuration (`cuda`: native's physics on the GPU).
    #[arg(long, value_parser = BackendArg::parser())]
    pub backend: Option<BackendArg>,
    /// Where the networks are evaluated.
    #[command(flatten)]
    pub eval: EvalPathArg,
    /// Worker threads (0 = one per core; at most 1024). Results do not depend on it.
    #[arg(long, alias = "jobs", default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=MAX_THREADS as u64))]
    pub threads: u64,
    /// Output directory (default: evolve-<preset>-task<T>-seed<S>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write a per-generation trace CSV here (ESP only): a header
    /// naming the run, then each generation's best network flown once on
    /// the scoring fitness (first-pass landing or not) and its neurons'
    /// credit ranks; the run is the same, bit for bit. Checked before the
    /// run: an existing file, a file of the run in --out, a non-UTF-8 name
    /// or a folder that takes no file is refused.
    #[arg(long)]
    pub trace: Option<PathBuf>,
    /// Print the run summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// A progress bar on standard error (drawn only on a terminal).
pub fn progress_bar(len: u64, template: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar
}

/// Runs `evolve`.
pub fn run(args: EvolveArgs) -> Result<i32> {
    let mut config = args.preset.config();
    if let Some(path) = &args.config {
        config = config.with_overrides_from(path)?;
    }
    if let Some(g) = args.generations {
        config.set_generations(g)?;
    }
    if let Some(backend) = args.backend {
        config.problem.backend = backend.physics();
    }
    config.validate()?;
    let path = BackendArg::eval_path(args.backend, args.eval.eval_path.clone())?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("evolve-{}-task{}-seed{}", args.preset, args.task, args.seed)));
    super::require_utf8_folder("--out", &out)?;
    if out.read_dir().is_ok_and(|mut entries| entries.next().is_some()) {
        anyhow::bail!(
            "output directory {} is not empty: results already written are never overwritten; choose another --out",
            out.display()
        );
    }
    let bar = progress_bar(
        config.generations() as u64,
        "{spinner} generation {pos}/{len} [{bar:30}] {msg} elapsed {elapsed} ETA {eta}",
    );
    let pool = psa_sim::ode::thread_pool(args.threads as usize)?;
    let outcome = pool.install(|| {
        let on_generation = |record: &GenerationRecord| {
            bar.set_position(record.generation as u64);
            bar.set_message(format!("champion {:.1} %", record.champion));
        };
        let (label, task, seed) = (args.preset.name(), args.task, args.seed);
        match &args.trace {
            Some(trace) => run_evolution_traced(&config, label, task, seed, &out, &path, trace, on_generation),
            None => run_evolution(&config, label, task, seed, &out, &path, on_generation),
        }
    })?;
    bar.finish_and_clear();
    if args.json {
        say!("{}", serde_json::to_string_pretty(&outcome)?);
    } else {
        say!(
            "{} on task {} (seed {}): champion {:.2} % after {} generations, {} evaluations, {} burst mutations, {} hidden neurons; {:.1} s",
            args.preset,
            args.task,
            args.seed,
            outcome.champion_fitness,
            outcome.generations,
            outcome.evaluations,
            outcome.bursts,
            outcome.champion_hidden,
            outcome.seconds
        );
        say!("wrote {}", out.display());
    }
    Ok(0)
}
