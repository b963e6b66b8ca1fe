//! The report's figures: the paper's Figure 4 (min, mean and max network
//! fitness per generation, baseline on task 1) and one champion-fitness
//! figure per configuration.

use std::path::{Path, PathBuf};

use super::tables::FigureLink;
use super::{GenerationRow, GridResults};
use crate::plots::curves::{write_curve_figure, CurveFigure, Series};
use crate::results::stats::mean_sd;
use crate::{Algorithm, GridConfig, Preset};
use psa_sim::psa::Task;

const Y_DESC: &str = "fitness (% of theoretical maximum)";

/// Per generation index: the generation number and the mean and sd over
/// `runs` of `value` (runs shorter than the longest are left out where they end).
fn average(runs: &[&[GenerationRow]], value: impl Fn(&GenerationRow) -> f64) -> Vec<(f64, f64, f64)> {
    let length = runs.iter().map(|r| r.len()).max().unwrap_or(0);
    (0..length)
        .filter_map(|i| {
            let rows: Vec<&GenerationRow> = runs.iter().filter_map(|r| r.get(i)).collect();
            let values: Vec<f64> = rows.iter().map(|r| value(r)).collect();
            let (mean, sd) = mean_sd(&values);
            let first = rows.first()?;
            Some((first.generation as f64, mean, if sd.is_nan() { 0.0 } else { sd }))
        })
        .collect()
}

fn x_desc(config: GridConfig) -> &'static str {
    if config.config().algorithm == Algorithm::HillClimb {
        "cycle"
    } else {
        "generation"
    }
}

/// Figure 4: min, mean and max network fitness per generation, averaged
/// over the baseline runs on task 1.
fn figure4(results: &GridResults) -> Option<CurveFigure> {
    let config = GridConfig::Preset(Preset::Baseline);
    let runs: Vec<&[GenerationRow]> = results
        .runs_of(config, &[Task::StopRotation])
        .map(|r| r.records.as_slice())
        .collect();
    if runs.is_empty() {
        return None;
    }
    let line = |label: &str, value: fn(&GenerationRow) -> f64| Series {
        label: label.into(),
        points: average(&runs, value).into_iter().map(|(x, m, _)| (x, m)).collect(),
        band: None,
    };
    Some(CurveFigure {
        title: format!(
            "Figure 4: network fitness per generation, baseline ESP on task 1 (mean over {} runs)",
            runs.len()
        ),
        x_desc: x_desc(config).into(),
        y_desc: Y_DESC.into(),
        series: vec![
            line("max (best network of the generation)", |r| r.max),
            line("mean", |r| r.mean),
            line("min (worst network of the generation)", |r| r.min),
        ],
    })
}

/// Champion fitness per generation of `config`: one line per task (mean
/// over seeds), shaded ± sd.
fn config_figure(results: &GridResults, config: GridConfig) -> Option<CurveFigure> {
    let series: Vec<Series> = results
        .spec
        .tasks
        .iter()
        .filter_map(|&task| {
            let runs: Vec<&[GenerationRow]> = results.runs_of(config, &[task]).map(|r| r.records.as_slice()).collect();
            if runs.is_empty() {
                return None;
            }
            let avg = average(&runs, |r| r.champion);
            Some(Series {
                label: format!("task {task} (mean ± sd over {} runs)", runs.len()),
                points: avg.iter().map(|&(x, m, _)| (x, m)).collect(),
                // Fitness is never negative: the band stops at 0.
                band: Some(avg.iter().map(|&(x, m, s)| (x, (m - s).max(0.0), m + s)).collect()),
            })
        })
        .collect();
    (!series.is_empty()).then(|| CurveFigure {
        title: format!("Champion fitness per generation: {config}"),
        x_desc: x_desc(config).into(),
        y_desc: Y_DESC.into(),
        series,
    })
}

/// Draws every figure into `dir` (`figure4`, `champion-<config>`), each as
/// SVG and PNG. Returns the links for the report (relative to the grid
/// directory, `dir`'s parent), the files written, and the figures that
/// could not be drawn.
pub fn write_figures(results: &GridResults, dir: &Path) -> (Vec<FigureLink>, Vec<PathBuf>, Vec<String>) {
    let mut figures: Vec<(String, CurveFigure)> = figure4(results).map(|f| ("figure4".into(), f)).into_iter().collect();
    for &config in &results.spec.configs {
        if let Some(f) = config_figure(results, config) {
            figures.push((format!("champion-{config}"), f));
        }
    }
    let folder = dir
        .file_name()
        .map_or("figures".into(), |n| n.to_string_lossy().into_owned());
    let (mut links, mut written, mut problems) = (Vec::new(), Vec::new(), Vec::new());
    for (stem, figure) in figures {
        match write_curve_figure(&figure, dir, &stem) {
            Ok(paths) => {
                links.push(FigureLink {
                    title: figure.title.clone(),
                    png: format!("{folder}/{stem}.png"),
                    svg: format!("{folder}/{stem}.svg"),
                });
                written.extend(paths);
            }
            Err(e) => problems.push(format!("{stem}: {e:#}")),
        }
    }
    (links, written, problems)
}
