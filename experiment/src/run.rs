//! One evolution run, written to its own directory.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::results::columns::{header, row, Column};
use crate::results::EvolveOutcome;
use crate::{Algorithm, RunConfig};
use anyhow::{Context, Result};
use esp_neuroevolution::{Esp, GenerationRecord, HillClimb, LesionOutcome, RunResult};
use psa_sim::evaluator::{EvalPath, PsaEvaluator};
use psa_sim::io::write_atomic;
use psa_sim::named::Named;
use psa_sim::psa::{NetworkFile, Task};

/// The files of a run directory.
#[derive(Debug, Clone)]
pub struct RunFiles {
    /// The resolved configuration (`config.toml`).
    pub config: PathBuf,
    /// One row per generation (`records.csv`).
    pub records: PathBuf,
    /// The champion network (`champion.json`).
    pub champion: PathBuf,
    /// Task, seed, results, build and times (`run.json`).
    pub summary: PathBuf,
}

impl RunFiles {
    /// The name of [`RunFiles::config`].
    pub const CONFIG: &'static str = "config.toml";
    /// The name of [`RunFiles::records`].
    pub const RECORDS: &'static str = "records.csv";
    /// The name of [`RunFiles::champion`].
    pub const CHAMPION: &'static str = "champion.json";
    /// The name of [`RunFiles::summary`].
    pub const SUMMARY: &'static str = "run.json";
    /// Every file's name, in the order above.
    pub const NAMES: [&'static str; 4] = [Self::CONFIG, Self::RECORDS, Self::CHAMPION, Self::SUMMARY];

    /// The files of the run directory `dir`.
    pub fn in_dir(dir: &Path) -> RunFiles {
        RunFiles {
            config: dir.join(Self::CONFIG),
            records: dir.join(Self::RECORDS),
            champion: dir.join(Self::CHAMPION),
            summary: dir.join(Self::SUMMARY),
        }
    }
}

/// The columns of `records.csv`, one row per generation (hill-climber: per
/// cycle); fitness in % of the task's theoretical maximum.
pub const RECORD_COLUMNS: [Column<GenerationRecord>; 11] = [
    Column {
        name: "generation",
        doc: "the generation (hill-climber: the cycle), from 1",
        value: |r| r.generation.to_string(),
    },
    Column {
        name: "min",
        doc: "the lowest network fitness of the generation",
        value: |r| r.min.to_string(),
    },
    Column {
        name: "mean",
        doc: "the mean network fitness of the generation",
        value: |r| r.mean.to_string(),
    },
    Column {
        name: "max",
        doc: "the highest network fitness of the generation",
        value: |r| r.max.to_string(),
    },
    Column {
        name: "best",
        doc: "the search's best network fitness so far (empty right after `erase_best` forgot it)",
        value: |r| r.best.map_or(String::new(), |b| b.to_string()),
    },
    Column {
        name: "champion",
        doc: "the champion's fitness: the best network ever evaluated",
        value: |r| r.champion.to_string(),
    },
    Column {
        name: "evaluations",
        doc: "network evaluations so far, lesion tests included",
        value: |r| r.evaluations.to_string(),
    },
    Column {
        name: "subpops",
        doc: "sub-populations after the generation",
        value: |r| r.subpops.to_string(),
    },
    Column {
        name: "burst",
        doc: "whether the generation ended in a burst mutation (`true` or `false`)",
        value: |r| r.burst.to_string(),
    },
    Column {
        name: "bursts",
        doc: "burst mutations so far",
        value: |r| r.bursts.to_string(),
    },
    Column {
        name: "lesion",
        doc: "the lesion test's outcome: `add`, `remove K` or empty",
        value: |r| match r.lesion {
            None => String::new(),
            Some(LesionOutcome::Add) => "add".into(),
            Some(LesionOutcome::Remove { neuron }) => format!("remove {neuron}"),
        },
    },
];

/// One line of `records.csv`, with its line break.
fn record_line(r: &GenerationRecord) -> String {
    row(&RECORD_COLUMNS, r) + "\n"
}

/// The records as CSV, one row per generation.
pub fn records_csv(records: &[GenerationRecord]) -> String {
    let mut csv = header(&RECORD_COLUMNS) + "\n";
    for r in records {
        csv.push_str(&record_line(r));
    }
    csv
}

/// `records.csv` while the run goes: a line written and flushed per
/// generation, so that it can be watched (`tail -f`). The finished run
/// replaces it atomically with the whole file; should a live write fail,
/// live writing stops and the run goes on.
struct LiveRecords {
    file: Option<std::fs::File>,
}

impl LiveRecords {
    fn create(path: &Path) -> LiveRecords {
        // Never through a link or into a FIFO or device (docs/limits.md).
        if psa_sim::io::check_output_file(path).is_err() {
            return LiveRecords { file: None };
        }
        let file = std::fs::File::create(path).and_then(|mut f| {
            f.write_all((header(&RECORD_COLUMNS) + "\n").as_bytes())?;
            Ok(f)
        });
        LiveRecords { file: file.ok() }
    }

    fn push(&mut self, record: &GenerationRecord) {
        if let Some(file) = &mut self.file {
            if file
                .write_all(record_line(record).as_bytes())
                .and_then(|_| file.flush())
                .is_err()
            {
                self.file = None;
            }
        }
    }
}

/// Runs `config` on `task` with `seed` on the current rayon pool and writes
/// `config.toml`, `records.csv`, `champion.json` and `run.json` (each
/// atomically) into `dir`; `records.csv` also grows a line per generation
/// while the run goes; its networks are evaluated on `path`. `on_generation`
/// sees every record as it comes.
pub fn run_evolution(
    config: &RunConfig,
    label: &str,
    task: Task,
    seed: u64,
    dir: &Path,
    path: &EvalPath,
    on_generation: impl FnMut(&GenerationRecord),
) -> Result<EvolveOutcome> {
    evolve(config, label, task, seed, dir, path, None, on_generation)
}

/// [`run_evolution`] with a trace ([`crate::trace`]) written to `trace`
/// (atomically, after the run's own files): the same run, bit for bit.
/// ESP only (the hill-climber has no sub-populations to trace): refused
/// otherwise, as is a `trace` that could not be written
/// ([`crate::trace::check_trace_path`]), before anything is written.
#[allow(clippy::too_many_arguments)]
pub fn run_evolution_traced(
    config: &RunConfig,
    label: &str,
    task: Task,
    seed: u64,
    dir: &Path,
    path: &EvalPath,
    trace: &Path,
    on_generation: impl FnMut(&GenerationRecord),
) -> Result<EvolveOutcome> {
    if config.algorithm != Algorithm::Esp {
        anyhow::bail!("--trace follows ESP's sub-populations; the hill-climber has none to trace");
    }
    crate::trace::check_trace_path(trace, dir)?;
    evolve(config, label, task, seed, dir, path, Some(trace), on_generation)
}

#[allow(clippy::too_many_arguments)]
fn evolve(
    config: &RunConfig,
    label: &str,
    task: Task,
    seed: u64,
    dir: &Path,
    path: &EvalPath,
    trace: Option<&Path>,
    mut on_generation: impl FnMut(&GenerationRecord),
) -> Result<EvolveOutcome> {
    let mut started = RunStart::new(config, dir)?;
    let evaluator = PsaEvaluator::new(config.problem.clone(), task, path)?;
    let on_generation = |record: &GenerationRecord| {
        started.record(record);
        on_generation(record);
    };
    let mut traced = None;
    let result: RunResult = match (config.algorithm, trace) {
        (Algorithm::Esp, Some(_)) => {
            let esp = Esp::new(config.esp.clone(), seed).map_err(anyhow::Error::msg)?;
            let scoring = config.problem.scoring_for(task)?;
            let (result, lines) = crate::trace::traced_run(&esp, &evaluator, &scoring, task, on_generation)?;
            traced = Some(lines);
            result
        }
        (Algorithm::Esp, _) => Esp::new(config.esp.clone(), seed)
            .map_err(anyhow::Error::msg)?
            .run(&evaluator, on_generation)?,
        (Algorithm::HillClimb, _) => HillClimb::new(config.hill_climb.clone(), seed)
            .map_err(anyhow::Error::msg)?
            .run(&evaluator, on_generation)?,
    };
    let outcome = started.finish(config, label, task, seed, &result)?;
    if let (Some(path), Some(lines)) = (trace, traced) {
        let header = crate::trace::TraceHeader::of_run(config, label, task, seed)?;
        crate::trace::write_trace(path, &header, &lines)
            .with_context(|| format!("the run is written whole in {}, but not its trace", dir.display()))?;
    }
    Ok(outcome)
}

/// A run begun on disk: its folder made, `config.toml` written and
/// `records.csv` growing a line per generation; its start time and clock.
pub struct RunStart {
    files: RunFiles,
    live: LiveRecords,
    started: String,
    clock: Instant,
}

impl RunStart {
    /// Checks `config`, makes `dir` and writes `config.toml` into it.
    pub fn new(config: &RunConfig, dir: &Path) -> Result<RunStart> {
        config.validate()?;
        psa_sim::io::create_output_dir(dir)?;
        let files = RunFiles::in_dir(dir);
        write_atomic(&files.config, config.to_toml()?.as_bytes())?;
        let live = LiveRecords::create(&files.records);
        Ok(RunStart {
            files,
            live,
            started: psa_sim::provenance::now_rfc3339(),
            clock: Instant::now(),
        })
    }

    /// Appends one generation's line to the live `records.csv`.
    pub fn record(&mut self, record: &GenerationRecord) {
        self.live.push(record);
    }

    /// Writes the run's `result` (`records.csv` whole and atomically,
    /// `champion.json`, `run.json`).
    pub fn finish(
        self,
        config: &RunConfig,
        label: &str,
        task: Task,
        seed: u64,
        result: &RunResult,
    ) -> Result<EvolveOutcome> {
        let files = self.files;
        let seconds = self.clock.elapsed().as_secs_f64();
        write_atomic(&files.records, records_csv(&result.records).as_bytes())?;
        let champion = &result.champion;
        let mut extra = serde_json::Map::new();
        extra.insert("configuration".into(), label.into());
        extra.insert("seed".into(), seed.to_string().into());
        extra.insert("fitness_percent".into(), champion.fitness.into());
        extra.insert("generation".into(), champion.generation.into());
        extra.insert("backend".into(), config.problem.backend.name().into());
        let build = crate::build_info();
        NetworkFile::new(&champion.network, task, &config.problem, &build, extra).save(&files.champion)?;
        let last = result.records.last().context("a run has at least one generation")?;
        let outcome = EvolveOutcome {
            task,
            seed,
            label: label.to_string(),
            backend: config.problem.backend,
            champion_fitness: champion.fitness,
            champion_generation: champion.generation,
            generations: result.records.len(),
            evaluations: last.evaluations,
            bursts: last.bursts,
            champion_hidden: champion.network.hidden(),
            build,
            started: self.started,
            finished: psa_sim::provenance::now_rfc3339(),
            seconds,
            ode_check: None,
        };
        outcome.save(&files.summary)?;
        Ok(outcome)
    }
}
