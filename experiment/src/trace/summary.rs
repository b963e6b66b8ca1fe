//! Traces read back and summarised: per run, when the generation's best
//! network is first a first-pass landing, how often a landing drops out of
//! a generation's best (after a burst, a topology change or neither), and
//! how mean credit ranks a landing network's neurons against other best
//! networks'; per group of runs (a folder of `*.trace.csv`, all of one
//! task, configuration, generation budget and model unless pooled), the
//! same summed, a Markdown table and a figure of the share of runs that
//! have found a landing by each generation.

use std::collections::{BTreeSet, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context, Result};

use super::TraceHeader;
use crate::plots::curves::{write_curve_figure, CurveFigure, Series};
use crate::results::stats::mean_sd;
use psa_sim::io::write_atomic;

/// The file name ending that marks a trace in a group's folder.
pub const TRACE_SUFFIX: &str = ".trace.csv";

/// The columns a summary reads, by their names in the trace's header.
const COLUMNS: [&str; 6] = [
    "generation",
    "burst",
    "topology",
    "top_first_pass",
    "champion_first_pass",
    "mean_credit_rank",
];

/// One generation as the summary reads it.
#[derive(Debug, Clone, PartialEq)]
struct Generation {
    generation: usize,
    burst: bool,
    topology: bool,
    lands: bool,
    champion_lands: bool,
    mean_credit_rank: f64,
}

/// A trace as read back: what run it is of (`None` for a trace of a
/// build before the header) and its generations.
#[derive(Debug, Clone, PartialEq)]
struct Trace {
    header: Option<TraceHeader>,
    generations: Vec<Generation>,
}

/// Reads a trace written by `psa-esp evolve --trace` (of this build, with
/// its header, or of an earlier one, without) under the rules of every
/// input file (a regular file of at most 64 MiB): generations 1, 2, 3, ...
/// a line each (at most the header's budget), flags 0 or 1, ranks finite
/// and in [0, 1], as many fields as the CSV header. Every error names the
/// file and line.
fn read_trace(path: &Path) -> Result<Trace> {
    let text = psa_sim::io::read_input(path, "trace")?;
    let all: Vec<&str> = text.lines().collect();
    let comments = all.iter().take_while(|l| l.starts_with('#')).count();
    let header = (comments > 0)
        .then(|| TraceHeader::parse(&all[..comments], 1, path))
        .transpose()?;
    let line_of = |n: usize| format!("{} line {}", path.display(), comments + n + 1);
    let mut lines = all[comments..].iter().enumerate();
    let columns: Vec<&str> = lines.next().map(|(_, l)| *l).unwrap_or_default().split(',').collect();
    let at = COLUMNS.map(|name| columns.iter().position(|h| *h == name));
    let Some(at) = at.iter().copied().collect::<Option<Vec<usize>>>() else {
        bail!(
            "{} is not a trace of `psa-esp evolve --trace`: its header lacks one of {}",
            path.display(),
            COLUMNS.join(", ")
        );
    };
    let max_rank_at = columns.iter().position(|h| *h == "max_credit_rank");
    let mut out: Vec<Generation> = Vec::new();
    for (n, line) in lines {
        let fields: Vec<&str> = line.split(',').collect();
        ensure!(
            fields.len() == columns.len(),
            "{}: {} fields, where the header has {}",
            line_of(n),
            fields.len(),
            columns.len()
        );
        let field = |i: usize| fields[at[i]];
        let flag = |i: usize| match field(i) {
            "0" => Ok(false),
            "1" => Ok(true),
            other => bail!("{}: {} is {other:?}, not 0 or 1", line_of(n), COLUMNS[i]),
        };
        let rank = |name: &str, text: &str| -> Result<f64> {
            match text.parse::<f64>() {
                Ok(r) if (0.0..=1.0).contains(&r) => Ok(r),
                _ => bail!("{}: {name} {text:?} is not a number in [0, 1]", line_of(n)),
            }
        };
        let expected = out.len() + 1;
        let generation: usize = field(0).parse().ok().filter(|&g| g == expected).with_context(|| {
            format!(
                "{}: generation {:?} where {expected} is due: a trace holds generations 1, 2, 3, ... a line each",
                line_of(n),
                field(0)
            )
        })?;
        if let Some(h) = &header {
            ensure!(
                generation <= h.generations,
                "{}: generation {generation} of a run of {} generations (its header's)",
                line_of(n),
                h.generations
            );
        }
        let mean_credit_rank = rank("mean_credit_rank", field(5))?;
        if let Some(i) = max_rank_at {
            rank("max_credit_rank", fields[i])?;
        }
        out.push(Generation {
            generation,
            burst: flag(1)?,
            topology: !field(2).is_empty(),
            lands: flag(3)?,
            champion_lands: flag(4)?,
            mean_credit_rank,
        });
    }
    ensure!(!out.is_empty(), "{} holds no generation", path.display());
    Ok(Trace {
        header,
        generations: out,
    })
}

/// What one traced run shows.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// The trace's file name without [`TRACE_SUFFIX`].
    pub name: String,
    /// Generations traced.
    pub generations: usize,
    /// The first generation whose best network is a first-pass landing.
    pub first_landing: Option<usize>,
    /// Generations whose best network is a first-pass landing.
    pub landing_generations: usize,
    /// Landings lost: a generation whose best lands, the next one's not,
    /// by what ended the first: a burst mutation, a topology change, or
    /// neither (recombination).
    pub lost_after_burst: usize,
    /// As above, after a topology change without a burst.
    pub lost_after_topology: usize,
    /// As above, after neither.
    pub lost_otherwise: usize,
    /// Whether the run's final champion is a first-pass landing.
    pub champion_lands: bool,
    /// The mean over generations whose best lands of its neurons' rank
    /// under mean credit (0 the best, 1 the worst).
    pub landing_rank: Option<f64>,
    /// The same over the other generations.
    pub other_rank: Option<f64>,
    /// What run the trace is of (`None`: a trace of an earlier build,
    /// without a header).
    pub header: Option<TraceHeader>,
}

/// The mean of `values` ([`mean_sd`]'s), if there is any.
fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let values: Vec<f64> = values.collect();
    (!values.is_empty()).then(|| mean_sd(&values).0)
}

impl RunSummary {
    fn of(name: String, header: Option<TraceHeader>, trace: &[Generation]) -> RunSummary {
        let (mut after_burst, mut after_topology, mut otherwise) = (0, 0, 0);
        for pair in trace.windows(2) {
            if pair[0].lands && !pair[1].lands {
                match (pair[0].burst, pair[0].topology) {
                    (true, _) => after_burst += 1,
                    (false, true) => after_topology += 1,
                    (false, false) => otherwise += 1,
                }
            }
        }
        RunSummary {
            name,
            generations: trace.len(),
            first_landing: trace.iter().find(|g| g.lands).map(|g| g.generation),
            landing_generations: trace.iter().filter(|g| g.lands).count(),
            lost_after_burst: after_burst,
            lost_after_topology: after_topology,
            lost_otherwise: otherwise,
            champion_lands: trace.last().is_some_and(|g| g.champion_lands),
            landing_rank: mean(trace.iter().filter(|g| g.lands).map(|g| g.mean_credit_rank)),
            other_rank: mean(trace.iter().filter(|g| !g.lands).map(|g| g.mean_credit_rank)),
            header,
        }
    }
}

/// A group of traced runs: a folder's `*.trace.csv`, named by the folder.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// The group's label: the folder's name (its path where two folders
    /// share a name).
    pub name: String,
    /// Its runs, in file name order.
    pub runs: Vec<RunSummary>,
    /// Per generation (from 1), how many runs' best network is a
    /// first-pass landing in that generation.
    pub landing_now: Vec<usize>,
    /// What its runs are of, from their headers, in words.
    pub about: String,
}

/// The fields of a header that traces pooled in one group must share
/// (all but the seed and the build), each named.
fn kind(h: &TraceHeader) -> [(&'static str, String); 4] {
    [
        ("task", h.task.to_string()),
        ("configuration", format!("{} (config {})", h.configuration, h.config)),
        ("generations", h.generations.to_string()),
        ("model", h.model.to_string()),
    ]
}

/// "task 2" or "tasks 1, 2": `name` and the distinct `values`.
fn listed(name: &str, values: &BTreeSet<String>) -> String {
    let plural = if values.len() > 1 { "s" } else { "" };
    let values: Vec<&str> = values.iter().map(String::as_str).collect();
    format!("{name}{plural} {}", values.join(", "))
}

/// What `runs` are of, in words (see [`Group::about`]).
fn about(runs: &[RunSummary], pooled: bool) -> String {
    let headers: Vec<&TraceHeader> = runs.iter().filter_map(|r| r.header.as_ref()).collect();
    let old = runs.len() - headers.len();
    let mut parts = Vec::new();
    if !headers.is_empty() {
        let values = |f: &dyn Fn(&TraceHeader) -> String| headers.iter().map(|h| f(h)).collect::<BTreeSet<String>>();
        let tasks = values(&|h| h.task.to_string());
        let configurations = values(&|h| format!("{} (config {})", h.configuration, h.config));
        let generations = values(&|h| h.generations.to_string());
        let models = values(&|h| h.model.to_string());
        let mut seeds: Vec<u64> = headers.iter().map(|h| h.seed).collect();
        seeds.sort_unstable();
        seeds.dedup();
        let seeds: Vec<String> = seeds.iter().map(u64::to_string).collect();
        let builds = values(&|h| h.build.clone());
        let mixed = [&tasks, &configurations, &generations, &models]
            .iter()
            .any(|v| v.len() > 1);
        if pooled && mixed {
            parts.push("pooled (`--pool`): runs of different kinds summed".to_string());
        }
        parts.push(listed("task", &tasks));
        parts.push(listed("configuration", &configurations));
        parts.push(format!(
            "{} generations",
            generations.into_iter().collect::<Vec<_>>().join(", ")
        ));
        parts.push(listed("model", &models));
        parts.push(format!(
            "seed{} {}",
            if seeds.len() > 1 { "s" } else { "" },
            seeds.join(", ")
        ));
        parts.push(listed("build", &builds));
    }
    if old > 0 {
        parts.push(format!(
            "{old} of {} traces of an earlier build, without a header: what task, configuration, seed and model \
             each is of is unknown, and it is grouped by its folder alone",
            runs.len()
        ));
    }
    parts.join("; ")
}

impl Group {
    /// Reads every `*.trace.csv` of `dir` as the group `name`; a folder
    /// without one is an error, and so is a file so named that is not a
    /// trace, a non-UTF-8 name, two traces of one run, or (unless `pool`)
    /// traces of different tasks, configurations, generation budgets or
    /// models.
    pub fn read(dir: &Path, name: String, pool: bool) -> Result<Group> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .with_context(|| format!("cannot read folder {}", dir.display()))?
            .map(|entry| entry.map(|e| e.path()))
            .collect::<std::io::Result<_>>()
            .with_context(|| format!("cannot read folder {}", dir.display()))?;
        // Every entry so named is read (a FIFO, a folder or a link to
        // nothing is refused by name, never skipped).
        files.retain(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().ends_with(TRACE_SUFFIX))
        });
        files.sort();
        ensure!(!files.is_empty(), "{} holds no *{TRACE_SUFFIX} file", dir.display());
        let mut runs = Vec::with_capacity(files.len());
        let mut landing_now = Vec::new();
        let mut seen: HashMap<TraceHeader, String> = HashMap::new();
        let mut first: Option<(String, TraceHeader)> = None;
        for path in &files {
            let Some(file) = path.file_name().and_then(|n| n.to_str()) else {
                bail!(
                    "{}: the file name is not UTF-8, so its run cannot be named; rename it",
                    path.display()
                );
            };
            let trace = read_trace(path)?;
            if let Some(header) = &trace.header {
                if let Some(other) = seen.insert(header.clone(), file.to_string()) {
                    bail!(
                        "{} and {file} in {} are traces of one run (task {}, configuration {}, seed {}): \
                         it would count twice; remove one",
                        other,
                        dir.display(),
                        header.task,
                        header.configuration,
                        header.seed
                    );
                }
                match &first {
                    None => first = Some((file.to_string(), header.clone())),
                    Some((other, h)) if !pool => {
                        let differ: Vec<String> = kind(h)
                            .iter()
                            .zip(kind(header))
                            .filter(|((_, a), (_, b))| a != b)
                            .map(|((what, a), (_, b))| format!("{what} {a} against {b}"))
                            .collect();
                        ensure!(
                            differ.is_empty(),
                            "{} holds traces of different runs: {other} and {file} differ in {}; \
                             summing them would pool unlike runs: put them in separate folders, or pass --pool \
                             to pool them",
                            dir.display(),
                            differ.join(", ")
                        );
                    }
                    Some(_) => {}
                }
            }
            let generations = &trace.generations;
            if landing_now.len() < generations.len() {
                landing_now.resize(generations.len(), 0);
            }
            for (i, g) in generations.iter().enumerate() {
                landing_now[i] += usize::from(g.lands);
            }
            runs.push(RunSummary::of(
                file.trim_end_matches(TRACE_SUFFIX).to_string(),
                trace.header,
                generations,
            ));
        }
        let about = about(&runs, pool);
        Ok(Group {
            name,
            runs,
            landing_now,
            about,
        })
    }

    /// Per generation g from 1 to the longest trace: how many runs were
    /// traced to g, how many of those had found a first-pass landing by
    /// g, and how many have one as g's best network. A run that ended
    /// before g is not counted at g.
    pub fn by_generation(&self) -> Vec<(usize, usize, usize)> {
        (1..=self.last_generation())
            .map(|g| {
                let traced = self.runs.iter().filter(|r| r.generations >= g);
                let found = traced
                    .clone()
                    .filter(|r| r.first_landing.is_some_and(|f| f <= g))
                    .count();
                (traced.count(), found, self.landing_now.get(g - 1).copied().unwrap_or(0))
            })
            .collect()
    }

    /// The share of the runs traced to generation g (in %) whose best
    /// network has been a first-pass landing by then, for g = 1 to the
    /// longest trace (see [`Group::by_generation`]).
    pub fn found_by(&self) -> Vec<(f64, f64)> {
        let share = |(traced, found, _): (usize, usize, usize)| 100.0 * found as f64 / traced as f64;
        self.by_generation()
            .into_iter()
            .enumerate()
            .map(|(i, counts)| ((i + 1) as f64, share(counts)))
            .collect()
    }

    /// The share of the runs traced to generation g (in %) whose best
    /// network of generation g is a first-pass landing, for g = 1 to the
    /// longest trace.
    pub fn landing_at(&self) -> Vec<(f64, f64)> {
        let share = |(traced, _, now): (usize, usize, usize)| 100.0 * now as f64 / traced as f64;
        self.by_generation()
            .into_iter()
            .enumerate()
            .map(|(i, counts)| ((i + 1) as f64, share(counts)))
            .collect()
    }

    fn last_generation(&self) -> usize {
        self.runs.iter().map(|r| r.generations).max().unwrap_or(0)
    }
}

fn median(values: &[usize]) -> Option<f64> {
    let mut values = values.to_vec();
    values.sort_unstable();
    let n = values.len();
    (n > 0).then(|| {
        if n % 2 == 1 {
            values[n / 2] as f64
        } else {
            (values[n / 2 - 1] + values[n / 2]) as f64 / 2.0
        }
    })
}

/// `text` in a Markdown table cell: `|` escaped.
fn md_cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// `text` as a CSV field: quoted (RFC 4180) when it holds a comma, a
/// quote or a line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

fn or_dash(value: Option<f64>, decimals: usize) -> String {
    value.map_or_else(|| "–".to_string(), |v| format!("{v:.decimals$}"))
}

/// The Markdown summary: one row per group, then what each group's runs
/// are of (task, configuration, budget, model, seeds and builds, from the
/// traces' headers; or that they are of an earlier build and grouped by
/// folder alone).
pub fn summary_markdown(groups: &[Group]) -> String {
    let mut md = String::from(
        "| group | runs | found a landing | median first landing (generation, runs that found one) | \
         generations whose best lands | landings lost after a burst / a topology change / otherwise | \
         final champion a landing | mean-credit rank, landing / other best networks |\n|---|---|---|---|---|---|---|---|\n",
    );
    for g in groups {
        let runs = &g.runs;
        let sum = |f: fn(&RunSummary) -> usize| runs.iter().map(f).sum::<usize>();
        let found: Vec<usize> = runs.iter().filter_map(|r| r.first_landing).collect();
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} / {} / {} | {} | {} / {} |",
            md_cell(&g.name),
            runs.len(),
            found.len(),
            or_dash(median(&found), 0),
            sum(|r| r.landing_generations),
            sum(|r| r.lost_after_burst),
            sum(|r| r.lost_after_topology),
            sum(|r| r.lost_otherwise),
            runs.iter().filter(|r| r.champion_lands).count(),
            or_dash(mean(runs.iter().filter_map(|r| r.landing_rank)), 2),
            or_dash(mean(runs.iter().filter_map(|r| r.other_rank)), 2),
        );
    }
    md.push_str("\nWhat each group's runs are of:\n\n");
    for g in groups {
        let _ = writeln!(md, "- {}: {}", md_cell(&g.name), md_cell(&g.about));
    }
    md
}

/// The per-run CSV, a line per run of every group.
pub fn summary_csv(groups: &[Group]) -> String {
    let mut csv = String::from(
        "group,run,generations,first_landing,landing_generations,lost_after_burst,lost_after_topology,\
         lost_otherwise,champion_lands,landing_rank,other_rank,task,configuration,config,seed,budget,model\n",
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
    for g in groups {
        for r in &g.runs {
            let header = r.header.as_ref().map_or_else(
                || ",,,,,".to_string(),
                |h| {
                    format!(
                        "{},{},{},{},{},{}",
                        h.task,
                        csv_field(&h.configuration),
                        h.config,
                        h.seed,
                        h.generations,
                        h.model
                    )
                },
            );
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{header}",
                csv_field(&g.name),
                csv_field(&r.name),
                r.generations,
                r.first_landing.map_or(String::new(), |f| f.to_string()),
                r.landing_generations,
                r.lost_after_burst,
                r.lost_after_topology,
                r.lost_otherwise,
                u8::from(r.champion_lands),
                opt(r.landing_rank),
                opt(r.other_rank),
            );
        }
    }
    csv
}

/// The figure's numbers as CSV: a line per group and generation, with the
/// runs traced to it, those that had found a first-pass landing by then
/// and those whose best network of that generation is one.
pub fn landing_csv(groups: &[Group]) -> String {
    let mut csv = String::from("group,generation,runs,found_by,landing\n");
    for g in groups {
        for (i, (traced, found, now)) in g.by_generation().into_iter().enumerate() {
            let _ = writeln!(csv, "{},{},{traced},{found},{now}", csv_field(&g.name), i + 1);
        }
    }
    csv
}

/// The figure: per group, the share of runs that have found a first-pass
/// landing by each generation, and of runs whose generation's best network
/// is one.
pub fn landing_figure(groups: &[Group]) -> CurveFigure {
    CurveFigure {
        title: "First-pass landings among the generations' best networks".into(),
        x_desc: "generation".into(),
        y_desc: "runs (%)".into(),
        series: groups
            .iter()
            .flat_map(|g| {
                [
                    Series {
                        label: format!("{}: found one by then ({} runs)", g.name, g.runs.len()),
                        points: g.found_by(),
                        band: None,
                    },
                    Series {
                        label: format!("{}: the generation's best lands", g.name),
                        points: g.landing_at(),
                        band: None,
                    },
                ]
            })
            .collect(),
    }
}

/// The label of each folder of `dirs`: its name, or where two share a
/// name, the path as given. The same folder named twice, or two labels
/// that still agree, is an error.
fn labels(dirs: &[PathBuf]) -> Result<Vec<String>> {
    let mut real: Vec<PathBuf> = Vec::with_capacity(dirs.len());
    for (i, dir) in dirs.iter().enumerate() {
        let path = dir
            .canonicalize()
            .with_context(|| format!("cannot read folder {}", dir.display()))?;
        if let Some(j) = real.iter().position(|r| *r == path) {
            bail!(
                "folder {} is named twice ({} and {}): each folder is one group, and its runs would count twice",
                path.display(),
                dirs[j].display(),
                dirs[i].display()
            );
        }
        real.push(path);
    }
    let names: Vec<String> = real
        .iter()
        .map(|p| {
            p.file_name()
                .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned())
        })
        .collect();
    let labels: Vec<String> = names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            if names.iter().filter(|n| *n == name).count() > 1 {
                let given = dirs[i].to_string_lossy();
                let trimmed = given.trim_end_matches('/');
                if trimmed.is_empty() {
                    given.into_owned()
                } else {
                    trimmed.to_string()
                }
            } else {
                name.clone()
            }
        })
        .collect();
    for (i, label) in labels.iter().enumerate() {
        if let Some(j) = labels[..i].iter().position(|l| l == label) {
            bail!(
                "folders {} and {} would both be labelled {label:?}: rename one, or name them by paths that differ",
                dirs[j].display(),
                dirs[i].display()
            );
        }
    }
    Ok(labels)
}

/// Reads every group's folder and writes `traces.md`, `traces.csv`,
/// `traces-landing.csv` and `traces-landing.svg` / `.png` to `out`, which must be a new or empty
/// folder (results already written are never overwritten, as with
/// `evolve --out`); returns the Markdown and the paths written. With
/// `pool`, a folder may hold traces of different tasks, configurations,
/// generation budgets or models (see [`Group::read`]).
pub fn write_summary(dirs: &[PathBuf], out: &Path, pool: bool) -> Result<(String, Vec<PathBuf>)> {
    ensure!(!dirs.is_empty(), "name at least one folder of traces");
    match std::fs::metadata(out) {
        Ok(meta) if meta.is_dir() => {
            let mut entries = out
                .read_dir()
                .with_context(|| format!("cannot read output folder {}", out.display()))?;
            if entries.next().is_some() {
                bail!(
                    "output folder {} is not empty: results already written are never overwritten; choose another --out",
                    out.display()
                );
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound && out.symlink_metadata().is_err() => {}
        // Anything else (a file, a link to nothing) is refused by name, and nothing made.
        _ => psa_sim::io::create_output_dir(out)?,
    }
    let labels = labels(dirs)?;
    let groups = dirs
        .iter()
        .zip(labels)
        .map(|(d, label)| Group::read(d, label, pool))
        .collect::<Result<Vec<_>>>()?;
    psa_sim::io::create_output_dir(out)?;
    let markdown = summary_markdown(&groups);
    let (md, csv, landing) = (
        out.join("traces.md"),
        out.join("traces.csv"),
        out.join("traces-landing.csv"),
    );
    write_atomic(&md, markdown.as_bytes())?;
    write_atomic(&csv, summary_csv(&groups).as_bytes())?;
    write_atomic(&landing, landing_csv(&groups).as_bytes())?;
    let mut written = vec![md, csv, landing];
    written.extend(write_curve_figure(&landing_figure(&groups), out, "traces-landing")?);
    Ok((markdown, written))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn generation(generation: usize, burst: bool, topology: bool, lands: bool) -> Generation {
        Generation {
            generation,
            burst,
            topology,
            lands,
            champion_lands: lands,
            mean_credit_rank: if lands { 0.4 } else { 0.2 },
        }
    }

    #[test]
    fn a_run_counts_its_first_landing_and_each_loss_by_its_cause() {
        let trace = [
            generation(1, false, false, false),
            generation(2, false, false, true),
            generation(3, true, false, true), // lost at the burst
            generation(4, false, false, false),
            generation(5, false, true, true), // lost at the topology change
            generation(6, false, false, false),
            generation(7, false, false, true), // lost to recombination
            generation(8, false, false, false),
            generation(9, false, false, true),
        ];
        let run = RunSummary::of("r".into(), None, &trace);
        assert_eq!(run.first_landing, Some(2));
        assert_eq!(run.landing_generations, 5);
        assert_eq!(
            (run.lost_after_burst, run.lost_after_topology, run.lost_otherwise),
            (1, 1, 1)
        );
        assert!(run.champion_lands);
        assert_eq!((run.landing_rank, run.other_rank), (Some(0.4), Some(0.2)));
    }

    #[test]
    fn the_share_found_by_a_generation_counts_runs_that_found_one_by_then() {
        let run = |first: Option<usize>| RunSummary {
            name: String::new(),
            generations: 4,
            first_landing: first,
            landing_generations: 0,
            lost_after_burst: 0,
            lost_after_topology: 0,
            lost_otherwise: 0,
            champion_lands: false,
            landing_rank: None,
            other_rank: None,
            header: None,
        };
        let mut group = Group {
            name: "g".into(),
            runs: vec![run(Some(2)), run(None), run(Some(4)), run(Some(2))],
            landing_now: vec![0, 2, 1],
            about: String::new(),
        };
        assert_eq!(group.found_by(), [(1.0, 0.0), (2.0, 50.0), (3.0, 50.0), (4.0, 75.0)]);
        assert_eq!(group.landing_at(), [(1.0, 0.0), (2.0, 50.0), (3.0, 25.0), (4.0, 0.0)]);
        assert_eq!(median(&[4, 2, 2]), Some(2.0));
        assert_eq!(median(&[]), None);
        // A run that ended is not counted past its last generation: two
        // runs ended at generation 2, so generations 3 and 4 are of the
        // other two alone.
        group.runs[0].generations = 2;
        group.runs[3].generations = 2;
        assert_eq!(group.found_by(), [(1.0, 0.0), (2.0, 50.0), (3.0, 0.0), (4.0, 50.0)]);
        assert_eq!(group.landing_at(), [(1.0, 0.0), (2.0, 50.0), (3.0, 50.0), (4.0, 0.0)]);
    }

    #[test]
    fn csv_fields_and_table_cells_keep_their_columns() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(csv_field("plain"), "plain");
        assert_eq!(md_cell("a|b"), "a\\|b");
    }
}
