//! Traces read back and summarised: per run, when the generation's best
//! network is first a first-pass landing, how often a landing drops out of
//! a generation's best (after a burst, a topology change or neither), and
//! how mean credit ranks a landing network's neurons against other best
//! networks'; per group of runs (a folder of `*.trace.csv`), the same
//! pooled, a Markdown table and a figure of the share of runs that have
//! found a landing by each generation.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context, Result};

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

/// Reads a trace written by `psa-esp evolve --trace`; a missing column or
/// a value that does not parse is an error naming the file and line.
fn read_trace(path: &Path) -> Result<Vec<Generation>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read trace {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let at = COLUMNS.map(|name| header.iter().position(|h| *h == name));
    let Some(at) = at.iter().copied().collect::<Option<Vec<usize>>>() else {
        bail!(
            "{} is not a trace of `psa-esp evolve --trace`: its header lacks one of {}",
            path.display(),
            COLUMNS.join(", ")
        );
    };
    let mut out = Vec::new();
    for (n, line) in lines.enumerate() {
        let fields: Vec<&str> = line.split(',').collect();
        let field = |i: usize| fields.get(at[i]).copied().unwrap_or("");
        let flag = |i: usize| match field(i) {
            "0" => Ok(false),
            "1" => Ok(true),
            other => bail!(
                "{} line {}: {} is {other:?}, not 0 or 1",
                path.display(),
                n + 2,
                COLUMNS[i]
            ),
        };
        let generation = field(0)
            .parse()
            .with_context(|| format!("{} line {}: generation {:?}", path.display(), n + 2, field(0)))?;
        let mean_credit_rank: f64 = field(5)
            .parse()
            .with_context(|| format!("{} line {}: mean_credit_rank {:?}", path.display(), n + 2, field(5)))?;
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
    Ok(out)
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
}

/// The mean of `values` ([`mean_sd`]'s), if there is any.
fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let values: Vec<f64> = values.collect();
    (!values.is_empty()).then(|| mean_sd(&values).0)
}

impl RunSummary {
    fn of(name: String, trace: &[Generation]) -> RunSummary {
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
        }
    }
}

/// A group of traced runs: a folder's `*.trace.csv`, named by the folder.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// The folder's name.
    pub name: String,
    /// Its runs, in file name order.
    pub runs: Vec<RunSummary>,
    /// Per generation (from 1), how many runs' best network is a
    /// first-pass landing in that generation.
    pub landing_now: Vec<usize>,
}

impl Group {
    /// Reads every `*.trace.csv` of `dir`; a folder without one is an error.
    pub fn read(dir: &Path) -> Result<Group> {
        let name = dir
            .file_name()
            .and_then(|n| n.to_str())
            .with_context(|| format!("{} has no UTF-8 folder name to label its group", dir.display()))?
            .to_string();
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .with_context(|| format!("cannot read folder {}", dir.display()))?
            .map(|entry| entry.map(|e| e.path()))
            .collect::<std::io::Result<_>>()
            .with_context(|| format!("cannot read folder {}", dir.display()))?;
        files.retain(|p| p.is_file() && p.to_str().is_some_and(|s| s.ends_with(TRACE_SUFFIX)));
        files.sort();
        ensure!(!files.is_empty(), "{} holds no *{TRACE_SUFFIX} file", dir.display());
        let mut runs = Vec::with_capacity(files.len());
        let mut landing_now = Vec::new();
        for path in &files {
            let file = path.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            let trace = read_trace(path)?;
            for g in trace.iter().filter(|g| g.lands && g.generation > 0) {
                if landing_now.len() < g.generation {
                    landing_now.resize(g.generation, 0);
                }
                landing_now[g.generation - 1] += 1;
            }
            runs.push(RunSummary::of(file.trim_end_matches(TRACE_SUFFIX).to_string(), &trace));
        }
        Ok(Group {
            name,
            runs,
            landing_now,
        })
    }

    /// The share of runs (in %) whose best network has been a first-pass
    /// landing by generation g, for g = 1 to the longest trace.
    pub fn found_by(&self) -> Vec<(f64, f64)> {
        let n = self.runs.len() as f64;
        (1..=self.last_generation())
            .map(|g| {
                let found = self
                    .runs
                    .iter()
                    .filter(|r| r.first_landing.is_some_and(|f| f <= g))
                    .count();
                (g as f64, 100.0 * found as f64 / n)
            })
            .collect()
    }

    /// The share of runs (in %) whose best network of generation g is a
    /// first-pass landing, for g = 1 to the longest trace.
    pub fn landing_at(&self) -> Vec<(f64, f64)> {
        let n = self.runs.len() as f64;
        (1..=self.last_generation())
            .map(|g| {
                let now = self.landing_now.get(g - 1).copied().unwrap_or(0);
                (g as f64, 100.0 * now as f64 / n)
            })
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

fn or_dash(value: Option<f64>, decimals: usize) -> String {
    value.map_or_else(|| "–".to_string(), |v| format!("{v:.decimals$}"))
}

/// The Markdown summary: one row per group, then one row per run.
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
            g.name,
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
    md
}

/// The per-run CSV, a line per run of every group.
pub fn summary_csv(groups: &[Group]) -> String {
    let mut csv = String::from(
        "group,run,generations,first_landing,landing_generations,lost_after_burst,lost_after_topology,\
         lost_otherwise,champion_lands,landing_rank,other_rank\n",
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
    for g in groups {
        for r in &g.runs {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{}",
                g.name,
                r.name,
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

/// Reads every group's folder and writes `traces.md`, `traces.csv` and
/// `traces-landing.svg` / `.png` to `out` (made if missing); returns the
/// Markdown and the paths written.
pub fn write_summary(dirs: &[PathBuf], out: &Path) -> Result<(String, Vec<PathBuf>)> {
    ensure!(!dirs.is_empty(), "name at least one folder of traces");
    let groups = dirs.iter().map(|d| Group::read(d)).collect::<Result<Vec<_>>>()?;
    std::fs::create_dir_all(out).with_context(|| format!("cannot make {}", out.display()))?;
    let markdown = summary_markdown(&groups);
    let (md, csv) = (out.join("traces.md"), out.join("traces.csv"));
    write_atomic(&md, markdown.as_bytes())?;
    write_atomic(&csv, summary_csv(&groups).as_bytes())?;
    let mut written = vec![md, csv];
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
        let run = RunSummary::of("r".into(), &trace);
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
        };
        let group = Group {
            name: "g".into(),
            runs: vec![run(Some(2)), run(None), run(Some(4)), run(Some(2))],
            landing_now: vec![0, 2, 1],
        };
        assert_eq!(group.found_by(), [(1.0, 0.0), (2.0, 50.0), (3.0, 50.0), (4.0, 75.0)]);
        assert_eq!(group.landing_at(), [(1.0, 0.0), (2.0, 50.0), (3.0, 25.0), (4.0, 0.0)]);
        assert_eq!(median(&[4, 2, 2]), Some(2.0));
        assert_eq!(median(&[]), None);
    }
}
