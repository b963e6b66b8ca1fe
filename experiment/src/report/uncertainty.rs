//! How sure the report's numbers are (`docs/statistics.md`):
//!
//! - a table cell's mean carries its 95 % Student t interval (mean ± t(0.975,
//!   n - 1) sd / sqrt(n)), its sd the 95 % chi-square interval of a normal
//!   sample's sd;
//! - D and its three parts, and each finding's verdict, are recomputed on
//!   [`RESAMPLES`] resamples of the grid's seeds: a resample draws as many
//!   seeds as the grid has, with replacement, and takes every run of each
//!   drawn seed (all configurations and tasks together, so that a seed's runs
//!   stay together as they were flown). D's interval is the 2.5 and 97.5 %
//!   quantiles of the resampled values (the percentile bootstrap); a
//!   finding's replication rate is the share of resamples on which its rule
//!   gives the verdict it gives on the grid itself;
//! - two grids on the same seeds (a sweep's variants) are compared paired by
//!   seed: the same resamples for both, the interval of the difference of
//!   their D.
//!
//! The draws come from a fixed stream ([`RESAMPLE_SEED`]), so a report's
//! intervals are the same bytes on every run, thread count and host.

use rand::RngExt;
use rayon::prelude::*;
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF, StudentsT};
use statrs::statistics::{Data, OrderStatistics};

use super::distance::Distance;
use super::findings::{findings, Finding, Verdict};
use super::GridResults;
use crate::results::stats::mean_sd;
use crate::results::RunData;

/// The intervals' confidence level.
pub const LEVEL: f64 = 0.95;
/// Seed resamples behind each bootstrap interval and replication rate.
pub const RESAMPLES: usize = 2000;
/// The seed of the resamples' random stream.
pub const RESAMPLE_SEED: u64 = 0x5EED_B007;

/// A two-sided interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Interval {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Interval {
    /// Whether 0 lies outside the interval.
    pub fn excludes_zero(&self) -> bool {
        self.lo > 0.0 || self.hi < 0.0
    }
}

/// The t interval of the mean of `values`; `None` with fewer than 2.
pub fn mean_interval(values: &[f64]) -> Option<Interval> {
    let (mean, sd) = mean_sd(values);
    let n = values.len() as f64;
    if values.len() < 2 || !sd.is_finite() {
        return None;
    }
    let t = StudentsT::new(0.0, 1.0, n - 1.0).ok()?.inverse_cdf(0.5 + LEVEL / 2.0);
    let half = t * sd / n.sqrt();
    Some(Interval {
        lo: mean - half,
        hi: mean + half,
    })
}

/// The chi-square interval of the standard deviation of `values` (exact
/// for a normal sample); `None` with fewer than 2.
pub fn sd_interval(values: &[f64]) -> Option<Interval> {
    let (_, sd) = mean_sd(values);
    if values.len() < 2 || !sd.is_finite() {
        return None;
    }
    let df = values.len() as f64 - 1.0;
    let chi = ChiSquared::new(df).ok()?;
    let tail = (1.0 - LEVEL) / 2.0;
    Some(Interval {
        lo: (df * sd * sd / chi.inverse_cdf(1.0 - tail)).sqrt(),
        hi: (df * sd * sd / chi.inverse_cdf(tail)).sqrt(),
    })
}

/// The percentile interval of bootstrap `samples` (their 2.5 and 97.5 %
/// quantiles); `None` when a sample is not finite (a part of D missing on
/// some resample) or there are none.
pub fn percentile_interval(samples: &[f64]) -> Option<Interval> {
    if samples.is_empty() || samples.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let mut data = Data::new(samples.to_vec());
    let tail = (1.0 - LEVEL) / 2.0;
    Some(Interval {
        lo: data.quantile(tail),
        hi: data.quantile(1.0 - tail),
    })
}

/// The seeds of resample `index` of a grid of `seeds` seeds from
/// `first_seed`: as many draws, with replacement, from a stream of its own.
pub fn seed_draws(first_seed: u64, seeds: u64, index: usize) -> Vec<u64> {
    let mut rng = esp_neuroevolution::rng::stream(RESAMPLE_SEED, &[index as u64]);
    (0..seeds).map(|_| first_seed + rng.random_range(0..seeds)).collect()
}

/// The grid's runs without their per-generation records (which no
/// resampled statistic reads), grouped by seed in the grid's seed order.
struct BySeed {
    first_seed: u64,
    seeds: u64,
    runs: Vec<Vec<RunData>>,
}

impl BySeed {
    fn of(results: &GridResults) -> BySeed {
        let spec = &results.spec;
        let mut runs: Vec<Vec<RunData>> = vec![Vec::new(); spec.seeds as usize];
        for run in &results.runs {
            let light = RunData {
                key: run.key,
                summary: run.summary.clone(),
                robustness: run.robustness.clone(),
                records: Vec::new(),
            };
            runs[(run.key.seed - spec.first_seed) as usize].push(light);
        }
        BySeed {
            first_seed: spec.first_seed,
            seeds: spec.seeds,
            runs,
        }
    }

    /// The grid made of the runs of resample `index`'s seeds.
    fn resample(&self, template: &GridResults, index: usize) -> GridResults {
        let runs = seed_draws(self.first_seed, self.seeds, index)
            .into_iter()
            .flat_map(|seed| self.runs[(seed - self.first_seed) as usize].iter().cloned())
            .collect();
        GridResults {
            dir: template.dir.clone(),
            spec: template.spec.clone(),
            runs,
            incomplete: Vec::new(),
            problems: Vec::new(),
        }
    }
}

/// D and its parts on one resample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceSample {
    /// D.
    pub total: f64,
    /// The means.
    pub means: f64,
    /// The spreads.
    pub spreads: f64,
    /// The burst ratio (NaN when the grid lacks it).
    pub burst_ratio: f64,
}

impl DistanceSample {
    /// A resample that measures no comparable D.
    const NONE: DistanceSample = DistanceSample {
        total: f64::NAN,
        means: f64::NAN,
        spreads: f64::NAN,
        burst_ratio: f64::NAN,
    };

    fn of(distance: &Distance) -> DistanceSample {
        let has_ratio = distance
            .terms
            .iter()
            .any(|t| t.part == super::distance::Part::BurstRatio);
        DistanceSample {
            total: distance.total,
            means: distance.means,
            spreads: distance.spreads,
            burst_ratio: if has_ratio { distance.burst_ratio } else { f64::NAN },
        }
    }
}

/// One resample's D and verdicts.
struct Resampled {
    distance: DistanceSample,
    verdicts: Vec<Verdict>,
}

/// The intervals of D and its parts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DistanceIntervals {
    /// D.
    pub total: Option<Interval>,
    /// The means.
    pub means: Option<Interval>,
    /// The spreads.
    pub spreads: Option<Interval>,
    /// The burst ratio.
    pub burst_ratio: Option<Interval>,
}

impl DistanceIntervals {
    /// The percentile intervals of `samples`.
    pub fn of(samples: &[DistanceSample]) -> DistanceIntervals {
        let part = |f: fn(&DistanceSample) -> f64| percentile_interval(&samples.iter().map(f).collect::<Vec<_>>());
        DistanceIntervals {
            total: part(|s| s.total),
            means: part(|s| s.means),
            spreads: part(|s| s.spreads),
            burst_ratio: part(|s| s.burst_ratio),
        }
    }
}

/// What the seed resamples say of a grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridUncertainty {
    /// Resamples of the grid's seeds.
    pub resamples: usize,
    /// The seed of their random stream.
    pub seed: u64,
    /// The confidence level of the intervals.
    pub level: f64,
    /// The intervals of D and its parts.
    pub distance: DistanceIntervals,
    /// D on each resample, in resample order (for paired comparisons).
    #[serde(skip)]
    pub samples: Vec<DistanceSample>,
}

/// D on each of `resamples` seed resamples of `results` (resample `i` is
/// the same draw of seeds for every grid with the same seed range, so two
/// grids' samples pair by index).
pub fn distance_samples(results: &GridResults, resamples: usize) -> Vec<DistanceSample> {
    resampled(results, resamples, false)
        .into_iter()
        .map(|r| r.distance)
        .collect()
}

fn resampled(results: &GridResults, resamples: usize, with_findings: bool) -> Vec<Resampled> {
    let by_seed = BySeed::of(results);
    let missing = Distance::of(results).missing.len();
    (0..resamples)
        .into_par_iter()
        .map(|index| {
            let grid = by_seed.resample(results, index);
            let distance = Distance::of(&grid);
            // A resample that lost a term of the grid's D (a cell with runs
            // of few seeds) measures another sum: no interval then.
            let distance = if distance.missing.len() == missing {
                DistanceSample::of(&distance)
            } else {
                DistanceSample::NONE
            };
            Resampled {
                distance,
                verdicts: if with_findings {
                    findings(&grid).iter().map(|f| f.verdict).collect()
                } else {
                    Vec::new()
                },
            }
        })
        .collect()
}

/// The seed-resampling intervals of D; sets the replication rate of each
/// of `judged` (the grid's own findings): the share of resamples whose
/// verdict is the grid's (`None` for a finding not testable on the grid).
pub fn grid_uncertainty(results: &GridResults, judged: &mut [Finding], resamples: usize) -> GridUncertainty {
    let samples = resampled(results, resamples, true);
    let distances: Vec<DistanceSample> = samples.iter().map(|s| s.distance).collect();
    for (i, f) in judged.iter_mut().enumerate() {
        f.replication = (f.verdict != Verdict::NotTestable && !samples.is_empty()).then(|| {
            let same = samples.iter().filter(|s| s.verdicts.get(i) == Some(&f.verdict)).count();
            same as f64 / samples.len() as f64
        });
    }
    GridUncertainty {
        resamples,
        seed: RESAMPLE_SEED,
        level: LEVEL,
        distance: DistanceIntervals::of(&distances),
        samples: distances,
    }
}

/// D of one grid minus D of a reference grid on the same seeds, paired by
/// seed: resample i draws the same seeds in both.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Paired {
    /// D here minus the reference's D; NaN when either grid lacks a term
    /// of D (no runs for it): their D sum different terms.
    pub difference: f64,
    /// Its interval over the same seed resamples of both grids (`None` when
    /// either grid lacks a term of D, on the grid or on a resample).
    pub interval: Option<Interval>,
}

impl Paired {
    /// The paired difference of `results` (with `samples`, its
    /// [`distance_samples`]) from `reference` (with its own), which must
    /// fly the same seeds.
    pub fn of(
        results: &GridResults,
        samples: &[DistanceSample],
        reference: &GridResults,
        reference_samples: &[DistanceSample],
    ) -> Paired {
        let (d, r) = (Distance::of(results), Distance::of(reference));
        let complete = d.missing.is_empty() && r.missing.is_empty();
        let differences: Vec<f64> = samples
            .iter()
            .zip(reference_samples)
            .map(|(a, b)| a.total - b.total)
            .collect();
        Paired {
            difference: if complete { d.total - r.total } else { f64::NAN },
            interval: complete.then(|| percentile_interval(&differences)).flatten(),
        }
    }

    /// Whether the interval lies wholly below 0: closer to the paper than
    /// the reference beyond seed noise.
    pub fn closer(&self) -> bool {
        self.interval.is_some_and(|i| i.hi < 0.0)
    }

    /// Whether the interval lies wholly above 0: farther beyond seed noise.
    pub fn farther(&self) -> bool {
        self.interval.is_some_and(|i| i.lo > 0.0)
    }

    /// The comparison in words, naming `reference`.
    pub fn describe(&self, reference: &str) -> String {
        let how = if self.closer() {
            "closer to the paper than"
        } else if self.farther() {
            "farther from the paper than"
        } else if self.interval.is_some() {
            "not told apart on these seeds from"
        } else {
            "not comparable (a term of D lacks runs) with"
        };
        format!("{how} {reference}")
    }
}

/// A grid's D against another grid's on the same seeds (`report --against`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Against {
    /// The reference grid's folder.
    pub reference: String,
    /// Its D.
    pub reference_total: f64,
    /// D here minus its D, paired by seed.
    pub paired: Paired,
}

impl Against {
    /// `results` (with `samples`, its [`distance_samples`]) against
    /// `reference`; an error unless both fly the same seeds.
    pub fn of(results: &GridResults, samples: &[DistanceSample], reference: &GridResults) -> anyhow::Result<Against> {
        let (a, b) = (&results.spec, &reference.spec);
        if a.seed_range() != b.seed_range() {
            anyhow::bail!(
                "{} flies seeds {} and {} seeds {}: a paired comparison needs the same seeds",
                results.dir.display(),
                a.seeds_label(),
                reference.dir.display(),
                b.seeds_label()
            );
        }
        let reference_samples = distance_samples(reference, samples.len());
        Ok(Against {
            reference: reference.dir.display().to_string(),
            reference_total: Distance::of(reference).total,
            paired: Paired::of(results, samples, reference, &reference_samples),
        })
    }
}
