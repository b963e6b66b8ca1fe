//! The report of a sweep (`psa-esp report` on a folder with `sweep.json`):
//! per variant the Table 1 levels, bursts per run, the robustness collapse
//! ratios, each finding's verdict and the distance to the paper; then the
//! sensitivity map: for each varied setting, the findings whose verdict
//! flips across its values while every other setting stays the same.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Serialize;

use super::distance::Distance;
use super::findings::Verdict;
use super::paper::PAPER_TASKS;
use super::render::{num, with_interval};
use super::tables::Report;
use super::uncertainty::{DistanceIntervals, DistanceSample, Paired};
use super::{GridResults, Metric};
use crate::grid::grid_file;
use crate::grid::sweep::{variant_dir, SweepSpec};
use crate::results::runs_table::{sweep_runs_csv, VariantRuns, RUNS_CSV};
use crate::BASELINE;
use crate::{GridConfig, Preset};

/// One variant's summary.
#[derive(Debug, Clone, Serialize)]
pub struct VariantSummary {
    /// Its folder name.
    pub name: String,
    /// Its varied settings (key, TOML value).
    pub settings: Vec<(String, String)>,
    /// Runs counted / runs of its grid.
    pub runs: (usize, usize),
    /// Baseline champion mean per task 1-3 (Table 1; NaN without runs).
    pub table1: [f64; 3],
    /// Mean burst mutations per run: baseline, max credit.
    pub bursts_per_run: [f64; 2],
    /// Baseline champions' mean under input noise / their clean mean.
    pub noise_ratio: f64,
    /// Baseline champions' mean from random starts / their clean mean (tasks 1 and 3).
    pub random_init_ratio: f64,
    /// Each finding's claim and verdict.
    pub findings: Vec<(String, Verdict)>,
    /// The distance to the paper.
    pub distance: Distance,
    /// The intervals of D and its parts from resampling the seeds.
    pub distance_intervals: DistanceIntervals,
    /// D here minus D of the sweep's reference variant, paired by seed
    /// (`None` for the reference itself).
    pub paired: Option<Paired>,
}

/// A varied setting and the findings whose verdict depends on it.
#[derive(Debug, Clone, Serialize)]
pub struct Sensitivity {
    /// The setting.
    pub key: String,
    /// Its values.
    pub values: Vec<String>,
    /// Findings whose verdict differs between two variants that differ in this setting only.
    pub flips: Vec<String>,
}

/// The whole sweep report (`sweep.json`'s companion `sweep-report.json`).
#[derive(Debug, Clone, Serialize)]
pub struct SweepReport {
    /// The sweep.
    pub sweep: SweepSpec,
    /// Per variant.
    pub variants: Vec<VariantSummary>,
    /// Per varied setting.
    pub sensitivity: Vec<Sensitivity>,
    /// The variant the others are compared with, paired by seed: the first
    /// (the base in one-at-a-time mode; in combinations, every varied
    /// setting at its first value).
    pub reference: String,
    /// Findings reproduced in every variant where they could be judged.
    pub hold_everywhere: Vec<String>,
    /// Findings not reproduced in any variant where they could be judged.
    pub fail_everywhere: Vec<String>,
    /// Findings reproduced in some variants and not in others.
    pub depend: Vec<String>,
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

impl VariantSummary {
    /// The summary of a variant's grid, and D on each of its seed resamples.
    fn of(
        name: String,
        settings: Vec<(String, String)>,
        results: &GridResults,
    ) -> (VariantSummary, Vec<DistanceSample>) {
        let mut report = Report::from_results(results);
        let samples = std::mem::take(&mut report.uncertainty.samples);
        let tasks = &results.spec.tasks;
        let per_run = |config| mean(&results.values(config, tasks, Metric::Bursts));
        let ratio = |metric: Metric| {
            let tested: Vec<&super::RunData> = results
                .runs_of(BASELINE, tasks)
                .filter(|r| r.value(metric).is_some())
                .collect();
            let robust: Vec<f64> = tested.iter().filter_map(|r| r.value(metric)).collect();
            let clean: Vec<f64> = tested.iter().map(|r| r.robustness.clean).collect();
            mean(&robust) / mean(&clean)
        };
        let summary = VariantSummary {
            name,
            settings,
            runs: (results.runs.len(), results.spec.runs().len()),
            table1: PAPER_TASKS.map(|t| mean(&results.values(BASELINE, &[t], Metric::Champion))),
            bursts_per_run: [per_run(BASELINE), per_run(GridConfig::Preset(Preset::MaxCredit))],
            noise_ratio: ratio(Metric::InputNoise),
            random_init_ratio: ratio(Metric::RandomInit),
            findings: report.findings.iter().map(|f| (f.claim.clone(), f.verdict)).collect(),
            distance: report.distance,
            distance_intervals: report.uncertainty.distance,
            paired: None,
        };
        (summary, samples)
    }
}

impl SweepReport {
    /// Reads every variant of the sweep in `dir`.
    pub fn load(dir: &Path) -> Result<SweepReport> {
        Ok(Self::load_with_results(dir)?.0)
    }

    /// [`SweepReport::load`], keeping each variant's results (in variant order).
    fn load_with_results(dir: &Path) -> Result<(SweepReport, Vec<GridResults>)> {
        let sweep = SweepSpec::load(dir)?;
        let mut variants = Vec::new();
        let mut grids = Vec::new();
        let mut samples: Vec<Vec<DistanceSample>> = Vec::new();
        for variant in sweep.variants() {
            let folder = variant_dir(dir, &variant);
            // A variant the sweep has not reached yet counts as a grid without runs.
            let results = if grid_file(&folder).exists() {
                GridResults::load(&folder)?
            } else {
                GridResults {
                    dir: folder,
                    spec: sweep.variant_grid(&variant)?,
                    runs: Vec::new(),
                    incomplete: Vec::new(),
                    problems: Vec::new(),
                }
            };
            let (summary, own) = VariantSummary::of(variant.name, variant.settings, &results);
            variants.push(summary);
            samples.push(own);
            grids.push(results);
        }
        // Every variant flies the same seeds: resample i draws the same
        // seeds in each, so the differences pair by seed.
        if let Some((reference, others)) = samples.split_first() {
            for ((variant, own), grid) in variants.iter_mut().skip(1).zip(others).zip(&grids[1..]) {
                variant.paired = Some(Paired::of(grid, own, &grids[0], reference));
            }
        }
        let sensitivity = sweep
            .vary
            .iter()
            .map(|v| Sensitivity {
                key: v.key.clone(),
                values: v.values.clone(),
                flips: flips(&variants, &v.key),
            })
            .collect();
        let mut by_claim: BTreeMap<&str, Vec<Verdict>> = BTreeMap::new();
        let mut order = Vec::new();
        for (claim, verdict) in variants.iter().flat_map(|v| &v.findings) {
            if !by_claim.contains_key(claim.as_str()) {
                order.push(claim.clone());
            }
            by_claim.entry(claim).or_default().push(*verdict);
        }
        let judged = |claim: &String| -> Vec<Verdict> {
            by_claim[claim.as_str()]
                .iter()
                .copied()
                .filter(|v| *v != Verdict::NotTestable)
                .collect()
        };
        let select = |keep: &dyn Fn(&[Verdict]) -> bool| -> Vec<String> {
            order.iter().filter(|c| keep(&judged(c))).cloned().collect()
        };
        let report = SweepReport {
            reference: variants.first().map_or(String::new(), |v| v.name.clone()),
            hold_everywhere: select(&|v| !v.is_empty() && v.iter().all(|x| *x == Verdict::Reproduced)),
            fail_everywhere: select(&|v| !v.is_empty() && v.iter().all(|x| *x == Verdict::NotReproduced)),
            depend: select(&|v| v.contains(&Verdict::Reproduced) && v.contains(&Verdict::NotReproduced)),
            sweep,
            variants,
            sensitivity,
        };
        Ok((report, grids))
    }

    /// Which variants are closer to the paper than the reference, in
    /// words: only those whose paired interval of ΔD lies below 0; the
    /// others cannot be told apart from it on these seeds, or are farther.
    pub fn verdict(&self) -> String {
        // Every compared variant in one of three groups by its interval.
        let (mut closer, mut farther, mut undecided) = (Vec::new(), Vec::new(), Vec::new());
        for v in &self.variants {
            match v.paired {
                Some(p) if p.closer() => closer.push(v),
                Some(p) if p.farther() => farther.push(v.name.as_str()),
                Some(_) => undecided.push(v.name.as_str()),
                None => {}
            }
        }
        let list = |names: &[&str]| {
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        };
        let mut text = match closer
            .iter()
            .min_by(|a, b| a.distance.total.total_cmp(&b.distance.total))
        {
            Some(best) => format!(
                "Closest to the paper: {} (D = {:.1}; ΔD from {} {}, an interval below 0).",
                best.name,
                best.distance.total,
                self.reference,
                best.paired
                    .map_or(String::new(), |p| with_interval(p.difference, p.interval))
            ),
            None => format!(
                "No variant is closer to the paper than {} beyond seed noise: no paired interval of ΔD lies below 0.",
                self.reference
            ),
        };
        let names: Vec<&str> = closer.iter().map(|v| v.name.as_str()).collect();
        let _ = write!(
            text,
            " Closer than {} (interval below 0): {}. Farther (above 0): {}. Not told apart from it on these seeds (the interval holds 0): {}.",
            self.reference,
            list(&names),
            list(&farther),
            list(&undecided)
        );
        text
    }

    /// The report as Markdown.
    pub fn markdown(&self) -> String {
        let mut md = String::from("# Sweep report\n\n");
        let varied: Vec<String> = self
            .sweep
            .vary
            .iter()
            .map(|v| format!("`{}` = {}", v.key, v.values.join(", ")))
            .collect();
        let _ = writeln!(
            md,
            "Varied ({:?}): {}. Every variant runs the same grid (seeds {}, {} generations, backend {}); \
             `psa-esp report variants/<variant>` gives a variant's full report.\n",
            self.sweep.mode,
            varied.join("; "),
            self.sweep.grid.seeds_label(),
            self.sweep.grid.generations,
            self.sweep.grid.backend
        );
        md.push_str("## Variants\n\n");
        let _ = write!(
            md,
            "Table 1: baseline champions (%), paper 42.4 / 44.0 / 11.9. Bursts per run: baseline and max credit, \
             paper 27.2 and 20.8. Noise and random-init ratios: the baseline champions' robust mean over their clean mean \
             (paper 0.11 and 0.22). D: the distance to the paper (smaller is closer; docs/model.md), then its parts: \
             the means (Table 1 and 2 means, burst totals), the spreads (their sds) and the burst ratio; \
             in brackets the 95 % interval from resampling the seeds. ΔD: D minus the reference's ({}), \
             paired by seed (the same seed resamples for both), with its 95 % interval (docs/statistics.md).\n\n",
            self.reference
        );
        md.push_str("| variant | runs | T1 task 1 | T1 task 2 | T1 task 3 | bursts base | bursts max | noise ratio | random-init ratio | D | ΔD | means | spreads | burst ratio |\n");
        md.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for v in &self.variants {
            let paired = v
                .paired
                .map_or("reference".to_string(), |p| with_interval(p.difference, p.interval));
            let _ = writeln!(
                md,
                "| {} | {}/{} | {} | {} | {} | {} | {} | {} | {} | {} | {paired} | {} | {} | {} |",
                v.name,
                v.runs.0,
                v.runs.1,
                num(v.table1[0]),
                num(v.table1[1]),
                num(v.table1[2]),
                num(v.bursts_per_run[0]),
                num(v.bursts_per_run[1]),
                ratio(v.noise_ratio),
                ratio(v.random_init_ratio),
                with_interval(v.distance.total, v.distance_intervals.total),
                with_interval(v.distance.means, v.distance_intervals.means),
                with_interval(v.distance.spreads, v.distance_intervals.spreads),
                with_interval(v.distance.burst_ratio, v.distance_intervals.burst_ratio)
            );
        }
        let _ = writeln!(md, "\n{}", self.verdict());
        md.push_str("\n## Findings per variant\n\n");
        let claims: Vec<&String> = self
            .variants
            .first()
            .map(|v| v.findings.iter().map(|(c, _)| c).collect())
            .unwrap_or_default();
        md.push_str("| finding |");
        for v in &self.variants {
            let _ = write!(md, " {} |", v.name);
        }
        md.push_str("\n|---|");
        md.push_str(&"---|".repeat(self.variants.len()));
        md.push('\n');
        for claim in claims {
            let _ = write!(md, "| {claim} |");
            for v in &self.variants {
                let verdict = v.findings.iter().find(|(c, _)| c == claim).map(|(_, x)| *x);
                let mark = match verdict {
                    Some(Verdict::Reproduced) => "yes",
                    Some(Verdict::NotReproduced) => "no",
                    _ => "–",
                };
                let _ = write!(md, " {mark} |");
            }
            md.push('\n');
        }
        md.push_str("\n## Sensitivity\n\n");
        md.push_str("A finding depends on a setting when its verdict differs between two variants that differ in that setting only.\n\n");
        md.push_str("| setting | values | findings that flip |\n|---|---|---|\n");
        for s in &self.sensitivity {
            let flips = if s.flips.is_empty() {
                "none".to_string()
            } else {
                s.flips.join("; ")
            };
            let _ = writeln!(md, "| `{}` | {} | {} |", s.key, s.values.join(", "), flips);
        }
        let list = |md: &mut String, title: &str, claims: &[String]| {
            let _ = writeln!(md, "\n{title}\n");
            if claims.is_empty() {
                md.push_str("- none\n");
            }
            for c in claims {
                let _ = writeln!(md, "- {c}");
            }
        };
        list(&mut md, "Findings that hold in every variant:", &self.hold_everywhere);
        list(&mut md, "Findings that depend on the settings:", &self.depend);
        list(&mut md, "Findings that fail in every variant:", &self.fail_everywhere);
        md
    }
}

fn ratio(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}")
    } else {
        "–".into()
    }
}

/// The findings whose verdict differs between two variants that set every
/// setting but `key` alike (a setting a variant leaves out is at its base).
fn flips(variants: &[VariantSummary], key: &str) -> Vec<String> {
    let mut groups: BTreeMap<Vec<(String, String)>, Vec<&VariantSummary>> = BTreeMap::new();
    for v in variants {
        let others: Vec<(String, String)> = v.settings.iter().filter(|(k, _)| k != key).cloned().collect();
        groups.entry(others).or_default().push(v);
    }
    let mut flipped: Vec<String> = Vec::new();
    for group in groups.values().filter(|g| g.len() > 1) {
        for (i, (claim, _)) in group[0].findings.iter().enumerate() {
            let verdicts: Vec<Verdict> = group
                .iter()
                .filter_map(|v| v.findings.get(i).map(|(_, x)| *x))
                .filter(|x| *x != Verdict::NotTestable)
                .collect();
            let differs = verdicts.windows(2).any(|w| w[0] != w[1]);
            if differs && !flipped.contains(claim) {
                flipped.push(claim.clone());
            }
        }
    }
    flipped
}

/// Reads the sweep in `dir` and writes `sweep-report.md`,
/// `sweep-report.json` and `runs.csv` (every variant's finished runs, a
/// column per varied setting) into it; returns the report and the files.
pub fn write_sweep_report(dir: &Path) -> Result<(SweepReport, String, Vec<PathBuf>)> {
    let (report, grids) = SweepReport::load_with_results(dir)?;
    let markdown = report.markdown();
    let md_path = dir.join("sweep-report.md");
    psa_sim::io::write_atomic(&md_path, markdown.as_bytes())?;
    let json_path = dir.join("sweep-report.json");
    psa_sim::io::write_json(&json_path, &report)?;
    let keys: Vec<String> = report.sweep.vary.iter().map(|v| v.key.clone()).collect();
    let variants: Vec<VariantRuns> = report
        .variants
        .iter()
        .zip(&grids)
        .map(|(variant, grid)| VariantRuns {
            name: &variant.name,
            dir: &grid.dir,
            runs: &grid.runs,
        })
        .collect();
    let runs_path = dir.join(RUNS_CSV);
    psa_sim::io::write_atomic(&runs_path, sweep_runs_csv(&keys, &variants)?.as_bytes())?;
    Ok((report, markdown, vec![md_path, json_path, runs_path]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn variant(settings: &[(&str, &str)], verdicts: &[Verdict]) -> VariantSummary {
        VariantSummary {
            name: format!("{settings:?}"),
            settings: settings.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect(),
            runs: (0, 0),
            table1: [f64::NAN; 3],
            bursts_per_run: [f64::NAN; 2],
            noise_ratio: f64::NAN,
            random_init_ratio: f64::NAN,
            findings: verdicts
                .iter()
                .enumerate()
                .map(|(i, v)| (format!("finding {i}"), *v))
                .collect(),
            distance: Distance {
                total: 0.0,
                means: 0.0,
                spreads: 0.0,
                burst_ratio: 0.0,
                terms: Vec::new(),
                missing: Vec::new(),
            },
            distance_intervals: DistanceIntervals {
                total: None,
                means: None,
                spreads: None,
                burst_ratio: None,
            },
            paired: None,
        }
    }

    fn sweep_of(variants: Vec<VariantSummary>) -> SweepReport {
        SweepReport {
            sweep: SweepSpec::new(
                crate::grid::GridSpec::from_preset(crate::grid::GridPreset::Quick),
                vec![crate::grid::sweep::parse_vary("esp.stagnation=20,30,40,50").unwrap()],
                crate::grid::sweep::SweepMode::Combinations,
            )
            .unwrap(),
            reference: variants[0].name.clone(),
            variants,
            sensitivity: Vec::new(),
            hold_everywhere: Vec::new(),
            fail_everywhere: Vec::new(),
            depend: Vec::new(),
        }
    }

    use crate::report::uncertainty::Interval;

    fn paired(name: &str, total: f64, lo: f64, hi: f64) -> VariantSummary {
        let mut v = variant(&[], &[]);
        v.name = name.into();
        v.distance.total = total;
        v.paired = Some(Paired {
            difference: total - 100.0,
            interval: Some(Interval { lo, hi }),
        });
        v
    }

    #[test]
    fn a_variant_is_named_closer_only_when_its_paired_interval_lies_below_zero() {
        let mut reference = variant(&[], &[]);
        reference.name = "v0".into();
        reference.distance.total = 100.0;
        // The lowest D, but its interval holds 0: not told apart.
        let report = sweep_of(vec![
            reference.clone(),
            paired("v1", 60.0, -90.0, 5.0),
            paired("v2", 130.0, 10.0, 50.0),
        ]);
        let text = report.verdict();
        assert!(
            text.starts_with("No variant is closer to the paper than v0 beyond seed noise"),
            "{text}"
        );
        assert!(
            text.contains("Farther (above 0): v2.") && text.contains("the interval holds 0): v1."),
            "{text}"
        );
        assert!(report.markdown().contains(&text));
        // One interval below 0: that variant is named, even where another has a lower D.
        let report = sweep_of(vec![
            reference,
            paired("v1", 60.0, -90.0, 5.0),
            paired("v2", 80.0, -30.0, -2.0),
        ]);
        let text = report.verdict();
        assert!(
            text.starts_with("Closest to the paper: v2 (D = 80.0; ΔD from v0 -20.0 [-30.0, -2.0]"),
            "{text}"
        );
        assert!(text.contains("Closer than v0 (interval below 0): v2."), "{text}");
    }

    #[test]
    fn a_categorical_reading_flips_the_findings_it_alone_changes() {
        use Verdict::*;
        // One at a time: the base, then each reading alone.
        let variants = [
            variant(&[], &[Reproduced, NotReproduced, NotTestable]),
            variant(
                &[("problem.fitness.scoring", "\"evolution\"")],
                &[NotReproduced, NotReproduced, Reproduced],
            ),
            variant(
                &[("problem.sensors.heading_input", "\"absolute\"")],
                &[Reproduced, Reproduced, NotReproduced],
            ),
        ];
        // A finding not testable on one side does not flip.
        assert_eq!(flips(&variants, "problem.fitness.scoring"), ["finding 0"]);
        assert_eq!(flips(&variants, "problem.sensors.heading_input"), ["finding 1"]);
        // In combinations, two variants that differ in another reading too are not compared.
        let combined = [
            variant(
                &[
                    ("problem.fitness.scoring", "\"original\""),
                    ("problem.fitness.state", "\"truth\""),
                ],
                &[Reproduced],
            ),
            variant(
                &[
                    ("problem.fitness.scoring", "\"evolution\""),
                    ("problem.fitness.state", "\"sensed\""),
                ],
                &[NotReproduced],
            ),
        ];
        assert!(flips(&combined, "problem.fitness.scoring").is_empty());
        assert!(flips(&combined, "problem.fitness.state").is_empty());
    }
}
