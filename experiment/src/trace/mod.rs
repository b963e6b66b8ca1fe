//! A traced ESP run: the same run, bit for bit, driven by ask and tell,
//! with a line per generation on its best network: whether it is a
//! first-pass landing (flown once on the scoring fitness) and how ESP's
//! credit ranks its neurons within their sub-populations, after a header
//! that says what run it is ([`TraceHeader`]); [`summary`] reads traces
//! back and summarises them.

use std::path::{Component, Path, PathBuf};

pub mod summary;

use anyhow::{bail, ensure, Context, Result};
use esp_neuroevolution::network::{Network, NetworkSet as _};
use esp_neuroevolution::rng::stream;
use esp_neuroevolution::{best_of, AskPurpose, AskTell, Credit, Esp, GenerationRecord, LesionOutcome, RunResult};
use psa_sim::evaluator::PsaEvaluator;
use psa_sim::io::write_atomic;
use psa_sim::psa::{PsaSettings, Task, TrialRecord, TrialRunner};

use crate::{RunConfig, RunFiles};

/// The key of the stream a traced network's trial is flown with (task 2
/// draws nothing from it: no random start, no noise in evolution).
const TRACE_TRIAL: u64 = 0x0074_7261_6365;

/// The first line of a trace's header: what the file is and the format's
/// version. Traces of builds before the header start with the CSV header.
pub const TRACE_FORMAT_LINE: &str = "# psa-esp evolve --trace, format 1";

/// The keys of a trace's header, in the order written: `# KEY: VALUE`, a
/// line each, after [`TRACE_FORMAT_LINE`].
pub const HEADER_KEYS: [&str; 7] = [
    "task",
    "configuration",
    "config",
    "seed",
    "generations",
    "model",
    "build",
];

/// What run a trace is of: its header (docs/file-formats.md). Traces of
/// one run share every field; `traces` pools only traces that share all
/// but the seed and the build.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct TraceHeader {
    /// The task.
    pub task: Task,
    /// The configuration's name (`evolve --preset`).
    pub configuration: String,
    /// The run's resolved configuration: the FNV-1a 64-bit hash of its
    /// `config.toml` (the preset with `--config` and `--generations` laid
    /// over it), 16 hexadecimal digits.
    pub config: String,
    /// The run's seed.
    pub seed: u64,
    /// The run's generation budget.
    pub generations: usize,
    /// The model: how many rows the build's table of defaults had
    /// (`psa_sim::psa::settings::defaults::rows`).
    pub model: u64,
    /// The build: version, commit and libode version.
    pub build: String,
}

/// The FNV-1a 64-bit hash of `bytes`.
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

impl TraceHeader {
    /// The header of a run of `config` (named `label`) on `task` with
    /// `seed`, by this build.
    pub fn of_run(config: &RunConfig, label: &str, task: Task, seed: u64) -> Result<TraceHeader> {
        let build = crate::build_info();
        Ok(TraceHeader {
            task,
            configuration: label.to_string(),
            config: format!("{:016x}", fnv1a64(config.to_toml()?.as_bytes())),
            seed,
            generations: config.generations(),
            model: build.defaults.unwrap_or(0),
            build: format!(
                "{} commit {} libode {}",
                build.tool_version, build.git_commit, build.libode_version
            ),
        })
    }

    /// The header's lines, each with its line break.
    pub fn text(&self) -> String {
        let values = [
            self.task.to_string(),
            self.configuration.clone(),
            self.config.clone(),
            self.seed.to_string(),
            self.generations.to_string(),
            self.model.to_string(),
            self.build.clone(),
        ];
        let mut text = format!("{TRACE_FORMAT_LINE}\n");
        for (key, value) in HEADER_KEYS.iter().zip(values) {
            text.push_str(&format!("# {key}: {value}\n"));
        }
        text
    }

    /// Reads a header from `lines` (each without its `#`-less rest
    /// checked: every line must be `# KEY: VALUE`), the first of which is
    /// line `first` of the file; errors name `path` and the line.
    pub fn parse(lines: &[&str], first: usize, path: &Path) -> Result<TraceHeader> {
        let at = |n: usize| format!("{} line {}", path.display(), first + n);
        let Some(format) = lines.first() else {
            bail!("{}: no header", path.display());
        };
        if *format != TRACE_FORMAT_LINE {
            match format.strip_prefix("# psa-esp evolve --trace, format ") {
                Some(version) => bail!(
                    "{}: a trace of format {version}, which this build does not read (it reads format 1: \\
                     written by a later build?)",
                    at(0)
                ),
                None => bail!(
                    "{}: {format:?} is not a trace's header (its first line is {TRACE_FORMAT_LINE:?})",
                    at(0)
                ),
            }
        }
        let mut values: [Option<&str>; HEADER_KEYS.len()] = [None; HEADER_KEYS.len()];
        for (n, line) in lines.iter().enumerate().skip(1) {
            let Some((key, value)) = line.strip_prefix("# ").and_then(|l| l.split_once(": ")) else {
                bail!("{}: {line:?} is not a header line `# KEY: VALUE`", at(n));
            };
            let Some(k) = HEADER_KEYS.iter().position(|h| *h == key) else {
                bail!(
                    "{}: unknown header key {key:?} (the keys are {})",
                    at(n),
                    HEADER_KEYS.join(", ")
                );
            };
            ensure!(values[k].is_none(), "{}: header key {key:?} given twice", at(n));
            values[k] = Some(value);
        }
        let mut value = |k: usize| {
            values[k].take().with_context(|| {
                format!(
                    "{}: the header lacks {:?} (it needs {})",
                    path.display(),
                    HEADER_KEYS[k],
                    HEADER_KEYS.join(", ")
                )
            })
        };
        let bad =
            |key: &str, value: &str, why: &str| anyhow::anyhow!("{}: header {key} {value:?}: {why}", path.display());
        let task = value(0)?;
        let task: Task = task.parse().map_err(|e: String| bad("task", task, &e))?;
        let configuration = value(1)?.to_string();
        ensure!(
            !configuration.trim().is_empty(),
            bad("configuration", &configuration, "empty")
        );
        let config = value(2)?.to_string();
        ensure!(
            config.len() == 16 && config.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)),
            bad(
                "config",
                &config,
                "not 16 lowercase hexadecimal digits (the hash of config.toml)"
            )
        );
        let seed = value(3)?;
        let seed: u64 = seed
            .parse()
            .map_err(|_| bad("seed", seed, "not a whole number in [0, 2^64)"))?;
        let generations = value(4)?;
        let max = esp_neuroevolution::MAX_GENERATIONS;
        let generations: usize = generations
            .parse()
            .ok()
            .filter(|g| (1..=max).contains(g))
            .ok_or_else(|| bad("generations", generations, &format!("not a whole number in [1, {max}]")))?;
        let model = value(5)?;
        let model: u64 = model.parse().ok().filter(|&m| m > 0).ok_or_else(|| {
            bad(
                "model",
                model,
                "not a positive whole number (rows of the table of defaults)",
            )
        })?;
        let build = value(6)?.to_string();
        ensure!(!build.trim().is_empty(), bad("build", &build, "empty"));
        Ok(TraceHeader {
            task,
            configuration,
            config,
            seed,
            generations,
            model,
            build,
        })
    }
}

/// `path` made absolute, with links resolved as far as it exists and `.`
/// and `..` applied to the rest: two names of one file compare equal.
fn resolved(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let parts: Vec<Component> = absolute.components().collect();
    for k in (1..=parts.len()).rev() {
        let Ok(mut out) = parts[..k].iter().collect::<PathBuf>().canonicalize() else {
            continue;
        };
        for part in &parts[k..] {
            match part {
                Component::ParentDir => {
                    out.pop();
                }
                Component::CurDir => {}
                other => out.push(other),
            }
        }
        return out;
    }
    absolute
}

/// Checks, before a traced run writes anything, that its trace can be
/// written to `trace` beside the run folder `out`: a UTF-8 name (`traces`
/// labels runs by it) that is new, not `out` itself nor a file of the run
/// (`config.toml`, ...) nor a folder above `out`, in a folder that exists
/// (or is `out`) and takes a new file. The error names the path.
pub fn check_trace_path(trace: &Path, out: &Path) -> Result<()> {
    if trace.to_str().is_none() {
        bail!(
            "--trace {}: the file name is not UTF-8, so `traces` could not read or label it; choose a UTF-8 name",
            trace.display()
        );
    }
    let (at, run) = (resolved(trace), resolved(out));
    if at == run {
        bail!(
            "--trace {} is the --out folder itself: the trace is a file; choose a name beside or inside the run folder",
            trace.display()
        );
    }
    if run.starts_with(&at) {
        bail!(
            "--out {} lies inside --trace {}: the trace is a file; choose another --trace",
            out.display(),
            trace.display()
        );
    }
    if trace.symlink_metadata().is_ok() {
        bail!(
            "trace file {} exists: results already written are never overwritten; choose another --trace",
            trace.display()
        );
    }
    let Some(name) = at.file_name().and_then(|n| n.to_str()) else {
        bail!("--trace {} names no file", trace.display());
    };
    let folder = at.parent().unwrap_or(Path::new("/"));
    if folder == run {
        if RunFiles::NAMES.contains(&name) {
            bail!(
                "--trace {} would be the run's own {name} in --out {}: the run writes {}; choose another name",
                trace.display(),
                out.display(),
                RunFiles::NAMES.join(", ")
            );
        }
        // The run makes `out`, and writes its files there first.
        return Ok(());
    }
    if folder.starts_with(&run) {
        bail!(
            "cannot write --trace {}: its folder {} would be inside the new run folder {}, which holds only the run's files; \
             put the trace in --out itself or beside it",
            trace.display(),
            folder.display(),
            out.display()
        );
    }
    match std::fs::metadata(folder) {
        Ok(meta) if meta.is_dir() => {}
        Ok(_) => bail!(
            "cannot write --trace {}: {} is not a folder",
            trace.display(),
            folder.display()
        ),
        Err(e) => bail!(
            "cannot write --trace {}: its folder {} cannot be used ({e}); `evolve` makes only --out",
            trace.display(),
            folder.display()
        ),
    }
    // A file made and removed proves the folder takes one (a read-only
    // folder, /proc, a full quota are refused now, not after the run).
    let probe = folder.join(psa_sim::io::temporary_name(name));
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(file) => {
            drop(file);
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => bail!(
            "cannot write --trace {}: no file can be made in {} ({e})",
            trace.display(),
            folder.display()
        ),
    }
}

/// How a network's trial passes the scoring window (the steps that earn
/// points on the scoring fitness: for task 2's original fitness, in the
/// box and within the heading window).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Landing {
    /// Entries into the window (an entry: a step that earns points after
    /// one that did not, or the first step).
    pub entries: usize,
    /// Steps that earn points.
    pub steps_in: usize,
    /// The first step that earns points, if any.
    pub first_in: Option<usize>,
    /// The trial's steps.
    pub steps: usize,
}

impl Landing {
    /// The window's passes in `points`, the points of each step.
    pub fn of_points(points: &[f64]) -> Landing {
        let mut entries = 0;
        let mut was_in = false;
        for &p in points {
            let is_in = p > 0.0;
            entries += usize::from(is_in && !was_in);
            was_in = is_in;
        }
        Landing {
            entries,
            steps_in: points.iter().filter(|&&p| p > 0.0).count(),
            first_in: points.iter().position(|&p| p > 0.0),
            steps: points.len(),
        }
    }

    /// A first-pass landing: the robot enters the window once and stays in
    /// it from then to the trial's last step.
    pub fn is_first_pass(&self) -> bool {
        self.entries == 1 && self.first_in.is_some_and(|first| self.steps - first == self.steps_in)
    }
}

/// One generation of a traced run.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceLine {
    /// The generation's record, as the run keeps it.
    pub record: GenerationRecord,
    /// How the generation's best network passes the window.
    pub top: Landing,
    /// Whether the best network so far (the champion) is a first-pass landing.
    pub champion_first_pass: bool,
    /// The mean over sub-populations of the rank (0 the best, 1 the worst)
    /// of the best network's neuron under mean credit.
    pub mean_credit_rank: f64,
    /// The same under max credit.
    pub max_credit_rank: f64,
    /// The mean over sub-populations of the best network's neuron's mean
    /// credit less the sub-population's mean of mean credits.
    pub mean_credit_gap: f64,
}

/// The ranks (0 best, 1 worst; ties share the best rank) of neuron
/// `picks[i]` in sub-population i by `credit` (as
/// [`Credit::neuron_credits`] gives it), averaged over sub-populations;
/// and the neuron's credit less its sub-population's mean, averaged.
fn rank_and_gap(credit: &[Option<f64>], picks: &[usize], subpop_size: usize) -> (f64, f64) {
    let (mut rank, mut gap) = (0.0, 0.0);
    for (i, &k) in picks.iter().enumerate() {
        let subpop = &credit[i * subpop_size..(i + 1) * subpop_size];
        let own = subpop[k].expect("a network's neurons joined it");
        let scored: Vec<f64> = subpop.iter().flatten().copied().collect();
        let above = scored.iter().filter(|&&c| c > own).count();
        rank += above as f64 / (subpop_size - 1).max(1) as f64;
        gap += own - scored.iter().sum::<f64>() / scored.len() as f64;
    }
    let n = picks.len() as f64;
    (rank / n, gap / n)
}

/// Flies `network` once on `scoring` and returns its passes of the window.
fn landing(runner: &mut TrialRunner, network: &Network, seed: u64) -> Result<Landing> {
    let mut record = TrialRecord::default();
    runner.run_trial(network, &mut stream(seed, &[TRACE_TRIAL]), Some(&mut record))?;
    Ok(Landing::of_points(&record.points))
}

/// Runs `esp` on `evaluator` by ask and tell, calling `on_generation`
/// after each generation as [`Esp::run`] would, and returns the run's
/// result with one [`TraceLine`] a generation; `scoring` (the settings a
/// champion of `task` is scored with) flies each generation's best network.
pub fn traced_run(
    esp: &Esp,
    evaluator: &PsaEvaluator,
    scoring: &PsaSettings,
    task: Task,
    mut on_generation: impl FnMut(&GenerationRecord),
) -> Result<(RunResult, Vec<TraceLine>)> {
    use esp_neuroevolution::Evaluator as _;
    let mut run = esp.start(evaluator.inputs(), evaluator.outputs())?;
    let mut runner = TrialRunner::new(scoring, task)?;
    let subpop_size = esp.settings().subpop_size;
    let mut lines = Vec::new();
    let mut champion: Option<(f64, bool)> = None;
    let mut pending = None;
    loop {
        let Some(asked) = run.ask()? else { break };
        let ticket = asked.ticket();
        let fitness = asked.evaluate(evaluator)?;
        let observed = match asked.purpose() {
            AskPurpose::Generation(_) => {
                let picks: Vec<&[usize]> = (0..fitness.len()).filter_map(|j| asked.picks(j)).collect();
                let subpops = picks.first().map_or(0, |p| p.len());
                let (top, top_fitness) = best_of(&fitness);
                let network = asked.network(top).into_owned();
                let top_landing = landing(&mut runner, &network, esp.seed())?;
                let mean = Credit::Mean.neuron_credits(subpops, subpop_size, picks.iter().copied(), &fitness);
                let max = Credit::Max.neuron_credits(subpops, subpop_size, picks.iter().copied(), &fitness);
                let (mean_rank, mean_gap) = rank_and_gap(&mean, picks[top], subpop_size);
                let (max_rank, _) = rank_and_gap(&max, picks[top], subpop_size);
                if champion.is_none_or(|(f, _)| top_fitness > f) {
                    champion = Some((top_fitness, top_landing.is_first_pass()));
                }
                Some((top_landing, mean_rank, max_rank, mean_gap))
            }
            AskPurpose::LesionTest(_) | AskPurpose::Base => None,
        };
        if let Some(observed) = observed {
            pending = Some(observed);
        }
        if let Some(record) = run.tell(ticket, &fitness)? {
            let Some((top, mean_credit_rank, max_credit_rank, mean_credit_gap)) = pending.take() else {
                bail!("generation {} told without its networks", record.generation);
            };
            lines.push(TraceLine {
                record: record.clone(),
                top,
                champion_first_pass: champion.is_some_and(|(_, first)| first),
                mean_credit_rank,
                max_credit_rank,
                mean_credit_gap,
            });
            on_generation(record);
        }
    }
    Ok((run.into_result()?, lines))
}

/// The trace: its header, then CSV, a line per generation.
pub fn trace_csv(header: &TraceHeader, lines: &[TraceLine]) -> String {
    let mut out = header.text();
    out.push_str(
        "generation,max,champion,subpops,burst,topology,top_first_pass,top_entries,top_steps_in,top_first_in,\
         champion_first_pass,mean_credit_rank,max_credit_rank,mean_credit_gap\n",
    );
    for l in lines {
        let r = &l.record;
        let topology = match r.lesion {
            None => "",
            Some(LesionOutcome::Add) => "add",
            Some(LesionOutcome::Remove { .. }) => "remove",
        };
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{:.4},{:.4},{:.4}\n",
            r.generation,
            r.max,
            r.champion,
            r.subpops,
            u8::from(r.burst),
            topology,
            u8::from(l.top.is_first_pass()),
            l.top.entries,
            l.top.steps_in,
            l.top.first_in.map_or(String::new(), |s| s.to_string()),
            u8::from(l.champion_first_pass),
            l.mean_credit_rank,
            l.max_credit_rank,
            l.mean_credit_gap,
        ));
    }
    out
}

/// Writes the trace to `path` atomically.
pub fn write_trace(path: &Path, header: &TraceHeader, lines: &[TraceLine]) -> Result<()> {
    write_atomic(path, trace_csv(header, lines).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_first_pass_landing_enters_the_window_once_and_stays() {
        let landed = Landing::of_points(&[0.0, 0.0, 1.0, 1.0, 1.0]);
        assert_eq!((landed.entries, landed.steps_in, landed.first_in), (1, 3, Some(2)));
        assert!(landed.is_first_pass());
        // The plateau: a pass through the window, then rest on a later pass.
        let plateau = Landing::of_points(&[0.0, 1.0, 0.0, 0.0, 1.0, 1.0]);
        assert_eq!(plateau.entries, 2);
        assert!(!plateau.is_first_pass());
        // In from the first step and leaving before the end.
        assert!(!Landing::of_points(&[1.0, 1.0, 0.0]).is_first_pass());
        assert!(Landing::of_points(&[1.0, 1.0, 1.0]).is_first_pass());
        assert!(!Landing::of_points(&[0.0, 0.0]).is_first_pass());
    }

    fn header() -> TraceHeader {
        TraceHeader {
            task: Task::Turn,
            configuration: "baseline".into(),
            config: "0123456789abcdef".into(),
            seed: u64::MAX,
            generations: 80,
            model: 12,
            build: "0.1.0 commit abc libode 0.16.2".into(),
        }
    }

    #[test]
    fn a_header_reads_back_as_written_and_a_bad_one_is_named() {
        let path = Path::new("t.trace.csv");
        let text = header().text();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], TRACE_FORMAT_LINE);
        assert_eq!(TraceHeader::parse(&lines, 1, path).unwrap(), header());
        let refused = |text: String, needle: &str| {
            let lines: Vec<&str> = text.lines().collect();
            let e = format!("{:#}", TraceHeader::parse(&lines, 1, path).unwrap_err());
            assert!(e.contains(needle), "{needle:?} not in {e}");
        };
        refused(text.replace("format 1", "format 2"), "format 2");
        refused(text.replace("# task: 2", "# task: 4"), "header task \"4\"");
        refused(
            text.replace("# seed: 18446744073709551615", "# seed: -1"),
            "header seed",
        );
        refused(
            text.replace("# generations: 80", "# generations: 0"),
            "header generations",
        );
        refused(text.replace("# model: 12\n", ""), "lacks \"model\"");
        refused(text.replace("# model: 12", "# model: 12\n# model: 12"), "given twice");
        refused(text.replace("# model: 12", "# colour: red"), "unknown header key");
        refused(
            text.replace("# config: 0123456789abcdef", "# config: xyz"),
            "header config",
        );
        refused(format!("# a comment\n{text}"), "is not a trace's header");
    }

    #[test]
    fn names_of_one_path_resolve_alike() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir(d.join("o")).unwrap();
        assert_eq!(
            resolved(&d.join("o/./x/../config.toml")),
            resolved(&d.join("o/config.toml"))
        );
        assert_eq!(resolved(&d.join("new/a/..")), resolved(&d.join("new")));
    }

    #[test]
    fn ranks_count_the_neurons_credited_above() {
        // Two sub-populations of 3; the network takes neuron 1 of the
        // first (the best: rank 0) and neuron 0 of the second (below two: rank 1).
        let credit = [Some(1.0), Some(5.0), Some(3.0), Some(0.0), Some(2.0), Some(4.0)];
        let (rank, gap) = rank_and_gap(&credit, &[1, 0], 3);
        assert!((rank - 0.5).abs() < 1e-12, "{rank}");
        assert!((gap - ((5.0 - 3.0) + (0.0 - 2.0)) / 2.0).abs() < 1e-12, "{gap}");
        // A neuron that joined no network is not counted.
        let (rank, _) = rank_and_gap(&[Some(1.0), None, Some(0.0)], &[2], 3);
        assert!((rank - 0.5).abs() < 1e-12, "{rank}");
    }
}
