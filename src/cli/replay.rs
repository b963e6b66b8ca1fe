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
    /// Physics backend [default: the `--config` file's `problem.backend`, else ode].
    #[arg(long, value_parser = choice::<BackendKind>())]
    pub backend: Option<BackendKind>,
    /// Standard deviation of Gaussian noise on every input (the bias too,
    /// unless the model sets `noise.on_bias = false`) [default: the
    /// `--config` file's `problem.noise.input_sd`, else 0].
    #[arg(long, allow_negative_numbers = true)]
    pub input_noise: Option<f64>,
    /// Standard deviation of Gaussian noise on every output (before
    /// clamping) [default: the `--config` file's `problem.noise.output_sd`, else 0].
    #[arg(long, allow_negative_numbers = true)]
    pub output_noise: Option<f64>,
    /// Random initial conditions (tasks 1 and 3); also where the `--config`
    /// file sets `problem.random_init = true`.
    #[arg(long)]
    pub random_init: bool,
    /// Number of trials (at most 1,000,000); the fitness is their mean
    /// [default: the `--config` file's `problem.trials`, else 1].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_TRIALS))]
    pub trials: Option<u64>,
    /// Seed of the noise and random initial conditions.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A TOML file of settings (as for `evolve --config`) laid over the
    /// model the network was evolved under; its `problem` table applies,
    /// noise, trials, random starts and backend included; an option given
    /// on the command line wins over the file.
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

/// The settings of the `--config` file's `problem` table that replay has
/// options for, as the file sets them (after the model it lays them on).
#[derive(Debug, Default, PartialEq)]
struct FileSets {
    input_sd: bool,
    output_sd: bool,
    trials: bool,
    random_init: bool,
    backend: bool,
}

impl FileSets {
    /// What `path` (a `--config` file that already loaded) sets.
    fn of(path: Option<&Path>) -> Result<FileSets> {
        let Some(path) = path else {
            return Ok(FileSets::default());
        };
        let keys = psa_experiment::RunConfig::keys_set_by(path)?;
        let sets = |key: &str| keys.iter().any(|k| k == key);
        Ok(FileSets {
            input_sd: sets("problem.noise.input_sd"),
            output_sd: sets("problem.noise.output_sd"),
            trials: sets("problem.trials"),
            random_init: sets("problem.random_init"),
            backend: sets("problem.backend"),
        })
    }
}

/// The settings a replay flies: the model, then for noise, trials, random
/// starts and backend the option where given, else the `--config` file's
/// value where it sets one, else replay's own default (no noise, one trial
/// from the paper's start, on `ode`).
fn flown(args: &ReplayArgs, model: PsaSettings, sets: &FileSets) -> Result<PsaSettings> {
    let pick = |option: Option<f64>, file_sets: bool, from_file: f64| {
        option.unwrap_or(if file_sets { from_file } else { 0.0 })
    };
    let input_sd = pick(args.input_noise, sets.input_sd, model.noise.input_sd);
    let output_sd = pick(args.output_noise, sets.output_sd, model.noise.output_sd);
    check_as("noise.input_sd", "--input-noise", input_sd).map_err(anyhow::Error::msg)?;
    check_as("noise.output_sd", "--output-noise", output_sd).map_err(anyhow::Error::msg)?;
    let trials = match args.trials {
        Some(n) => n as usize,
        None if sets.trials => model.trials,
        None => 1,
    };
    Ok(PsaSettings {
        backend: args
            .backend
            .unwrap_or(if sets.backend { model.backend } else { BackendKind::Ode }),
        trials,
        random_init: args.random_init || (sets.random_init && model.random_init),
        noise: NoiseSettings {
            input_sd,
            output_sd,
            ..model.noise
        },
        ..model
    })
}

/// Runs `replay`.
pub fn run(args: ReplayArgs) -> Result<i32> {
    for (option, key, value) in [
        ("--input-noise", "noise.input_sd", args.input_noise),
        ("--output-noise", "noise.output_sd", args.output_noise),
    ] {
        if let Some(value) = value {
            check_as(key, option, value).map_err(anyhow::Error::msg)?;
        }
    }
    if let Some(out) = &args.out {
        super::require_utf8_folder("--out", out)?;
    }
    if args.json && args.network.to_str().is_none() {
        bail!(
            "{}: --json names the network file, and its name is not UTF-8; rename it",
            args.network.display()
        );
    }
    let (file, network) = NetworkFile::load(&args.network)?;
    let task = args.task.unwrap_or(file.task);
    let model = model(&args, &file)?;
    let settings = flown(&args, model, &FileSets::of(args.config.as_deref())?)?;
    if settings.random_init && !task.has_random_init() {
        let source = if args.random_init {
            "--random-init"
        } else {
            "the --config file's problem.random_init"
        };
        bail!("{source}: task {task} has no random-initialisation variant (tasks 1 and 3 have)");
    }
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
        settings.backend,
        per_trial[0]
    );
    let files = write_outputs(&out, &first, &settings, title)?;
    if args.json {
        let summary = ReplaySummary {
            network: args.network,
            task,
            backend: settings.backend,
            trials: settings.trials as u64,
            seed: args.seed,
            input_noise: settings.noise.input_sd,
            output_noise: settings.noise.output_sd,
            random_init: settings.random_init,
            fitness_percent_mean: mean,
            fitness_percent_sd: sd,
            fitness_percent_per_trial: per_trial,
            files,
        };
        say!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        say!(
            "task {task}, {} backend, {} trial(s): fitness {mean:.2} % (sd {sd:.2}) of the theoretical maximum",
            settings.backend,
            settings.trials
        );
        for f in &files {
            say!("wrote {}", f.display());
        }
    }
    Ok(0)
}
