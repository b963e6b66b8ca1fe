//! `psa-esp replay`: fly a saved network on a task and show what it does.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use serde::Serialize;

use super::choice::choice;
use psa_experiment::champion::robustness::TrialSummary;
use psa_experiment::plots::{write_trial_pictures, TrialPicture};
use psa_sim::physics::BackendKind;
use psa_sim::psa::settings::limits::{check_as, MAX_TRIALS};
use psa_sim::psa::{NetworkFile, NoiseSettings, PsaSettings, Task, TrialRecord, TrialRunner};

/// Key of the random stream of replays.
const REPLAY_STREAM: u64 = 301;

/// Arguments of `replay`.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
    /// The network file (JSON) to fly.
    pub network: PathBuf,
    /// Task 1, 2 or 3 (default: the task the network was evolved for).
    #[arg(long)]
    pub task: Option<Task>,
    /// Physics backend.
    #[arg(long, value_parser = choice::<BackendKind>(), default_value_t = BackendKind::Ode)]
    pub backend: BackendKind,
    /// Standard deviation of Gaussian noise on every input but the bias.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub input_noise: f64,
    /// Standard deviation of Gaussian noise on every output (before clamping).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub output_noise: f64,
    /// Random initial conditions (tasks 1 and 3).
    #[arg(long)]
    pub random_init: bool,
    /// Number of trials (at most 1,000,000); the fitness is their mean.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=MAX_TRIALS))]
    pub trials: u64,
    /// Seed of the noise and random initial conditions.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A TOML file of settings (as for `evolve --config`) laid over the
    /// model the network was evolved under; its `problem` table applies.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Fly the network on this build's default model instead of the one
    /// recorded in the network file.
    #[arg(long)]
    pub default_model: bool,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
    /// Where to write the first trial's trajectory, pictures and animation
    /// (default: replay-<network name>-task<N> in the current directory).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// What `replay --json` prints.
#[derive(Debug, Serialize)]
struct ReplaySummary {
    network: PathBuf,
    task: Task,
    backend: BackendKind,
    trials: u64,
    #[serde(serialize_with = "psa_sim::io::u64_string::serialize")]
    seed: u64,
    input_noise: f64,
    output_noise: f64,
    random_init: bool,
    fitness_percent_mean: f64,
    fitness_percent_sd: f64,
    fitness_percent_per_trial: Vec<f64>,
    files: Vec<PathBuf>,
}

fn write_outputs(dir: &Path, record: &TrialRecord, settings: &PsaSettings, title: String) -> Result<Vec<PathBuf>> {
    psa_sim::io::create_output_dir(dir)?;
    let csv = super::trajectory_csv(&record.states, settings.physics.dt, ",u0,u1,u2,u3,points", |i| {
        match (
            i.checked_sub(1).and_then(|k| record.outputs.get(k)),
            i.checked_sub(1).and_then(|k| record.points.get(k)),
        ) {
            (Some(u), Some(p)) => format!(",{},{},{},{},{p}", u[0], u[1], u[2], u[3]),
            _ => ",,,,,".into(),
        }
    });
    let csv_path = dir.join("trajectory.csv");
    psa_sim::io::write_atomic(&csv_path, csv.as_bytes())?;
    let picture = TrialPicture {
        title,
        dt: settings.physics.dt,
        states: &record.states,
        outputs: &record.outputs,
        target: [record.target.x, record.target.y, record.target.heading],
        box_half_width: settings.fitness.box_half_width,
        heading_window: settings.fitness.heading_window,
        hull_radius: settings.body.hull_radius,
    };
    let mut files = vec![csv_path];
    files.extend(write_trial_pictures(&picture, dir, "trial")?);
    Ok(files)
}

/// The model to fly on: the one the file records (for files of older
/// builds, the default model with the file's input scaling), or the
/// default with `--default-model`; then `--config` laid over it.
fn model(args: &ReplayArgs, file: &NetworkFile) -> Result<PsaSettings> {
    let recorded = match (&file.problem, args.default_model) {
        (_, true) => PsaSettings::default(),
        (Some(problem), false) => problem.clone(),
        (None, false) => PsaSettings {
            sensors: file.input_scaling,
            ..PsaSettings::default()
        },
    };
    match &args.config {
        None => Ok(recorded),
        Some(path) => {
            let base = psa_experiment::RunConfig {
                problem: recorded,
                ..psa_experiment::RunConfig::default()
            };
            Ok(base.with_overrides_from(path)?.problem)
        }
    }
}

/// Runs `replay`.
pub fn run(args: ReplayArgs) -> Result<i32> {
    check_as("noise.input_sd", "--input-noise", args.input_noise).map_err(anyhow::Error::msg)?;
    check_as("noise.output_sd", "--output-noise", args.output_noise).map_err(anyhow::Error::msg)?;
    let (file, network) = NetworkFile::load(&args.network)?;
    let task = args.task.unwrap_or(file.task);
    if args.random_init && !task.has_random_init() {
        bail!("--random-init: task {task} has no random-initialisation variant (tasks 1 and 3 have)");
    }
    let model = model(&args, &file)?;
    let settings = PsaSettings {
        backend: args.backend,
        trials: args.trials as usize,
        random_init: args.random_init,
        noise: NoiseSettings {
            input_sd: args.input_noise,
            output_sd: args.output_noise,
            ..model.noise
        },
        ..model
    };
    let mut runner = TrialRunner::new(&settings, task)?;
    let mut rng = esp_neuroevolution::rng::stream(args.seed, &[REPLAY_STREAM]);
    let maximum = runner.maximum_points();
    let mut first = TrialRecord::default();
    let mut per_trial = Vec::with_capacity(settings.trials);
    for trial in 0..settings.trials {
        let record = (trial == 0).then_some(&mut first);
        per_trial.push(100.0 * runner.run_trial(&network, &mut rng, record)? / maximum);
    }
    let TrialSummary { mean, sd } = TrialSummary::of(&per_trial);
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .network
            .file_stem()
            .map_or("network".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from(format!("replay-{stem}-task{task}"))
    });
    let title = format!(
        "{} on task {task} ({} backend): trial 1 scores {:.1} %",
        args.network
            .file_name()
            .map_or("network".into(), |s| s.to_string_lossy()),
        args.backend,
        per_trial[0]
    );
    let files = write_outputs(&out, &first, &settings, title)?;
    if args.json {
        let summary = ReplaySummary {
            network: args.network,
            task,
            backend: args.backend,
            trials: args.trials,
            seed: args.seed,
            input_noise: args.input_noise,
            output_noise: args.output_noise,
            random_init: args.random_init,
            fitness_percent_mean: mean,
            fitness_percent_sd: sd,
            fitness_percent_per_trial: per_trial,
            files,
        };
        say!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        say!(
            "task {task}, {} backend, {} trial(s): fitness {mean:.2} % (sd {sd:.2}) of the theoretical maximum",
            args.backend,
            args.trials
        );
        for f in &files {
            say!("wrote {}", f.display());
        }
    }
    Ok(0)
}
