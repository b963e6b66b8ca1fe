//! The report on synthetic grids with hand-chosen numbers.

use std::path::{Path, PathBuf};
use strum::VariantArray;

use super::*;
use crate::champion::robustness::{Robustness, TrialSummary};
use crate::grid::{GridPreset, GridSpec, FINISHED_MARKER};
use crate::results::{parse_records, GenerationRow};
use crate::BASELINE;
use crate::{Preset, RunFiles};
use esp_neuroevolution::network::Network;
use psa_sim::physics::BackendKind;
use psa_sim::psa::NetworkFile;

const MAX_CREDIT: GridConfig = GridConfig::Preset(Preset::MaxCredit);

/// Baseline, max credit and input noise on tasks 1 and 2, seeds 1-3 (18 runs), 4 generations.
fn spec() -> GridSpec {
    GridSpec {
        configs: vec![BASELINE, MAX_CREDIT, GridConfig::InputNoise],
        tasks: vec![Task::StopRotation, Task::Turn],
        seeds: 3,
        first_seed: 1,
        generations: 4,
        backend: BackendKind::Native,
        robustness_trials: 10,
        ..GridSpec::from_preset(GridPreset::Quick)
    }
}

/// The hand-chosen numbers of a run: champion, clean, input noise, random init, bursts.
///
/// Champions: baseline 10 s (10, 20, 30 on each task), max credit 10 s + 30,
/// input noise 10 s + 5. Under input noise: baseline keeps 20 %, input
/// noise 50 %; from random initial conditions (task 1) baseline keeps 10 %.
/// Bursts: baseline s, max credit 0, input noise 1.
fn numbers(key: &RunKey) -> (f64, f64, Option<f64>, usize) {
    let s = key.seed as f64;
    let (champion, noise, bursts) = match key.config {
        BASELINE => (10.0 * s, 0.2, key.seed as usize),
        MAX_CREDIT => (10.0 * s + 30.0, 0.2, 0),
        _ => (10.0 * s + 5.0, 0.5, 1),
    };
    let random = key.task.has_random_init().then_some(0.1 * champion);
    (champion, noise * champion, random, bursts)
}

fn write_run(dir: &Path, spec: &GridSpec, key: &RunKey) -> PathBuf {
    let folder = run_dir(dir, key);
    std::fs::create_dir_all(&folder).unwrap();
    let config = spec.run_config(key.config).unwrap();
    std::fs::write(RunFiles::in_dir(&folder).config, config.to_toml().unwrap()).unwrap();
    let (champion, noise, random, bursts) = numbers(key);
    let mut csv = String::from("generation,min,mean,max,best,champion,evaluations,subpops,burst,bursts,lesion\n");
    for g in 1..=spec.generations {
        let f = champion * g as f64 / spec.generations as f64;
        csv.push_str(&format!("{g},0,{},{f},{f},{f},{},5,false,0,\n", f / 2.0, 400 * g));
    }
    std::fs::write(RunFiles::in_dir(&folder).records, csv).unwrap();
    let network = Network::from_neurons(5, 4, &[vec![0.25; 9], vec![-0.5; 9]]).unwrap();
    NetworkFile::new(
        &network,
        key.task,
        &config.problem,
        &crate::build_info(),
        serde_json::Map::new(),
    )
    .save(&RunFiles::in_dir(&folder).champion)
    .unwrap();
    let run = serde_json::json!({
        "task": key.task, "seed": 1234, "label": key.config.name(), "backend": "native",
        "champion_fitness": champion, "champion_generation": spec.generations, "generations": spec.generations,
        "evaluations": 1600, "bursts": bursts, "champion_hidden": 2,
        "build": {"tool_version": "0.1.0", "git_commit": "abc123", "libode_version": "0.16.2"},
        "started": "2026-01-01T00:00:00Z", "finished": "2026-01-01T00:00:01Z", "seconds": 1.5
    });
    std::fs::write(
        RunFiles::in_dir(&folder).summary,
        serde_json::to_string_pretty(&run).unwrap(),
    )
    .unwrap();
    let robustness = Robustness {
        trials: spec.robustness_trials,
        input_noise_sd: 0.05,
        clean: champion,
        input_noise: TrialSummary { mean: noise, sd: 1.0 },
        random_init: random.map(|mean| TrialSummary { mean, sd: 1.0 }),
        rescored: false,
    };
    std::fs::write(
        folder.join(FINISHED_MARKER),
        serde_json::to_string(&robustness).unwrap(),
    )
    .unwrap();
    folder
}

fn grid() -> (tempfile::TempDir, GridSpec) {
    let dir = tempfile::tempdir().unwrap();
    let spec = spec();
    spec.save(dir.path()).unwrap();
    for key in spec.runs() {
        write_run(dir.path(), &spec, &key);
    }
    (dir, spec)
}

/// [`spec`] on all three tasks (every term of D has runs), written.
fn grid_of_all_tasks() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let spec = GridSpec {
        tasks: Task::VARIANTS.to_vec(),
        ..spec()
    };
    spec.save(dir.path()).unwrap();
    for key in spec.runs() {
        write_run(dir.path(), &spec, &key);
    }
    dir
}

fn table<'a>(report: &'a Report, id: &str) -> &'a Table {
    report.tables.iter().find(|t| t.id == id).unwrap()
}

fn cell<'a>(table: &'a Table, config: GridConfig, metric: Metric, task: &str) -> &'a Row {
    table
        .rows
        .iter()
        .find(|r| r.config == config && r.metric == metric && r.task == task)
        .unwrap_or_else(|| panic!("no row {config} {metric:?} {task} in table {}", table.id))
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9 * b.abs().max(1.0)
}

fn finding<'a>(report: &'a Report, claim: &str) -> &'a Finding {
    report.findings.iter().find(|f| f.claim.contains(claim)).unwrap()
}

#[test]
fn tables_match_hand_computed_numbers() {
    let (dir, _) = grid();
    let results = GridResults::load(dir.path()).unwrap();
    assert_eq!(
        (results.runs.len(), results.incomplete.len(), results.problems.len()),
        (18, 0, 0)
    );
    let report = Report::from_results(&results);

    let t1 = table(&report, "1");
    let r = cell(t1, BASELINE, Metric::Champion, "1");
    assert_eq!((r.n, r.mean, r.sd, r.p), (3, 20.0, 10.0, None));
    assert_eq!(r.paper.unwrap().mean, 42.4);
    let all = cell(t1, BASELINE, Metric::Champion, "All");
    // 10, 20, 30 twice: sum of squares 400, / 5.
    assert_eq!(all.n, 6);
    assert!(close(all.mean, 20.0) && close(all.sd, 80f64.sqrt()));
    // Task 3 is not in the grid: no runs, the paper's numbers still shown.
    let t3 = cell(t1, BASELINE, Metric::Champion, "3");
    assert!(t3.n == 0 && t3.mean.is_nan() && t3.paper.is_some());

    // Welch against the baseline; p from scipy.stats.ttest_ind(..., equal_var=False).
    let t5 = table(&report, "5");
    let r = cell(t5, MAX_CREDIT, Metric::Champion, "1");
    assert_eq!((r.mean, r.sd), (50.0, 10.0));
    assert!((r.p.unwrap() - 0.021311641128756713).abs() < 1e-9);
    let r = cell(t5, MAX_CREDIT, Metric::Champion, "All");
    assert!((r.p.unwrap() - 0.00017074345518010504).abs() < 1e-9);
    assert_eq!(r.paper.unwrap().p, Some(9.5e-5));

    // Robustness: baseline under input noise keeps 20 % (2, 4, 6), random init 10 % on task 1.
    let t2 = table(&report, "2");
    assert_eq!(cell(t2, BASELINE, Metric::InputNoise, "1").mean, 4.0);
    assert_eq!(cell(t2, BASELINE, Metric::RandomInit, "1").mean, 2.0);
    assert_eq!(cell(t2, BASELINE, Metric::Clean, "All").paper.unwrap().mean, 32.8);
    assert!(!t2
        .rows
        .iter()
        .any(|r| r.metric == Metric::RandomInit && r.task != "1" && r.task != "3"));
    let t3 = table(&report, "3");
    let r = cell(t3, GridConfig::InputNoise, Metric::InputNoise, "2");
    assert_eq!((r.n, r.mean), (3, 12.5));
    assert_eq!(r.paper.unwrap().mean, 10.0);

    // Bursts: baseline 1 + 2 + 3 per task.
    let b = report.bursts.iter().find(|b| b.config == BASELINE).unwrap();
    assert_eq!((b.runs, b.total, b.per_run, b.paper_total), (6, 12, 2.0, Some(2448)));

    // Findings: every rule holds on the paper's own numbers.
    assert!(
        report.findings.iter().all(|f| f.holds_in_paper),
        "{:#?}",
        report.findings
    );
    assert_eq!(report.findings.len(), 9);
    assert_eq!(
        finding(&report, "max credit is clearly better").verdict,
        Verdict::Reproduced
    );
    assert_eq!(finding(&report, "systematic").verdict, Verdict::NotTestable);
    assert_eq!(
        finding(&report, "collapse under input noise").verdict,
        Verdict::Reproduced
    );
    assert_eq!(finding(&report, "collapse under random").verdict, Verdict::Reproduced);
    let doubling = finding(&report, "doubles");
    assert_eq!(doubling.verdict, Verdict::Reproduced);
    assert!(close(doubling.here[0].a / doubling.here[0].b, 12.5 / 4.0));
    assert_eq!(finding(&report, "fewer burst").verdict, Verdict::Reproduced);
}

#[test]
fn writes_markdown_figures_csv_and_json() {
    let (dir, _) = grid();
    let outcome = write_report(dir.path(), ReportFormat::Json).unwrap();
    assert_eq!(outcome.exit_code(), 0);
    assert_eq!((outcome.counted, outcome.expected), (18, 18));
    assert_eq!(
        outcome.written,
        vec![
            dir.path().join("report.md"),
            dir.path().join("runs.csv"),
            dir.path().join("report.json")
        ]
    );
    // runs.csv: a row per run; run.json's seed here is the number 1234 (the
    // form older builds wrote), read as well as a string.
    let runs = std::fs::read_to_string(dir.path().join("runs.csv")).unwrap();
    let rows: Vec<&str> = runs.lines().collect();
    assert_eq!(rows.len(), 1 + 18);
    assert!(rows[0].starts_with("configuration,task,seed,run_seed,champion_fitness,"));
    assert!(rows[1].starts_with("baseline,1,1,1234,"), "{}", rows[1]);
    assert!(rows[1].contains(",native,0.1.0,abc123,1.5"), "{}", rows[1]);
    let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert_eq!(md, outcome.markdown);
    for text in [
        "**REDUCED GRID (not the paper's protocol): 3 seeds",
        "2000 generations",
        "configurations left out: systematic",
        "tasks left out: 3",
        "| 1 | 3 | 20.0 [-4.8, 44.8] | 10.0 [5.2, 62.8] | 42.4 | 12.8 |",
        "| 1 | 3 | 50.0 [25.2, 74.8] | 10.0 [5.2, 62.8] | 2.1e-2 | 56.7 | 14.8 | 1.8e-4 |",
        "git commit abc123",
        "**max credit is clearly better than the baseline**",
        "— **reproduced**",
        "not testable",
        "\"better\" = higher mean and Welch p < 0.05",
        "![Figure 4: network fitness per generation, baseline ESP on task 1 (mean over 3 runs)](figures/figure4.png)",
        "[SVG](figures/figure4.svg)",
        "(figures/champion-max-credit.png)",
    ] {
        assert!(md.contains(text), "report.md lacks {text:?}:\n{md}");
    }
    assert!(!md.contains("PARTIAL GRID") && !md.contains("## Problems"));
    let figures = dir.path().join("figures");
    let png = std::fs::read(figures.join("figure4.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));
    let svg = std::fs::read_to_string(figures.join("champion-baseline.svg")).unwrap();
    assert!(svg.trim_end().ends_with("</svg>") && svg.contains("task 2"));
    assert!(outcome.figures.contains(&figures.join("champion-input-noise.png")));

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap()).unwrap();
    assert_eq!(json["runs_counted"], 18);
    assert_eq!(json["tables"][0]["rows"][0]["mean"], 20.0);
    assert_eq!(json["findings"][0]["verdict"], "reproduced");

    let outcome = write_report(dir.path(), ReportFormat::Csv).unwrap();
    assert_eq!(outcome.written[2], dir.path().join("report.csv"));
    let csv = std::fs::read_to_string(dir.path().join("report.csv")).unwrap();
    assert!(csv.starts_with(&format!("{}\n", super::render::REPORT_CSV_HEADER)));
    assert!(
        csv.contains("\n1,baseline,champion,1,3,20,10,,42.4,12.8,,-4.8"),
        "{csv}"
    );
    assert!(csv.contains("\nbursts,baseline,bursts,All,6,2,"), "{csv}");
}

#[test]
fn partial_grid_says_what_is_missing() {
    let (dir, spec) = grid();
    let gone = RunKey {
        config: MAX_CREDIT,
        task: Task::Turn,
        seed: 2,
    };
    std::fs::remove_dir_all(run_dir(dir.path(), &gone)).unwrap();
    let killed = RunKey { seed: 3, ..gone };
    std::fs::remove_file(run_dir(dir.path(), &killed).join(FINISHED_MARKER)).unwrap();
    let outcome = write_report(dir.path(), ReportFormat::Md).unwrap();
    assert_eq!(outcome.exit_code(), 0);
    assert_eq!((outcome.counted, outcome.expected), (16, spec.runs().len()));
    let md = &outcome.markdown;
    assert!(
        md.contains("**PARTIAL GRID: 16 of 18 runs counted; 1 not started, 1 unfinished"),
        "{md}"
    );
    assert!(md.contains("## Missing runs"));
    assert!(md.contains("| max-credit | 2 | 1 | 1 |"), "{md}");
    assert!(md.contains(&run_dir(dir.path(), &gone).display().to_string()));
    let report = Report::from_results(&GridResults::load(dir.path()).unwrap());
    assert_eq!(cell(table(&report, "5"), MAX_CREDIT, Metric::Champion, "2").n, 1);
}

#[test]
fn damaged_and_foreign_folders_are_reported_not_counted() {
    let (dir, _) = grid();
    let key = |config, seed| RunKey {
        config,
        task: Task::StopRotation,
        seed,
    };
    // A truncated run.json.
    let truncated = run_dir(dir.path(), &key(BASELINE, 1)).join(RunFiles::SUMMARY);
    let text = std::fs::read_to_string(&truncated).unwrap();
    std::fs::write(&truncated, &text[..text.len() / 2]).unwrap();
    // A folder holding another configuration.
    let foreign = run_dir(dir.path(), &key(BASELINE, 2));
    let config = std::fs::read_to_string(RunFiles::in_dir(&foreign).config).unwrap();
    std::fs::write(
        RunFiles::in_dir(&foreign).config,
        config.replace("subpop_size = 40", "subpop_size = 20"),
    )
    .unwrap();
    // Garbage in records.csv (right number of lines).
    let garbage = run_dir(dir.path(), &key(MAX_CREDIT, 1)).join(RunFiles::RECORDS);
    std::fs::write(&garbage, "generation,min\nx,y\n1\n2\n3\n").unwrap();

    let outcome = write_report(dir.path(), ReportFormat::Md).unwrap();
    assert_eq!(outcome.exit_code(), 1);
    assert_eq!(outcome.counted, 15);
    assert_eq!(outcome.problems.len(), 3, "{:#?}", outcome.problems);
    for path in [&truncated, &foreign, &garbage] {
        let shown = path.display().to_string();
        assert!(
            outcome.problems.iter().any(|p| p.contains(&shown)),
            "{shown} not in {:#?}",
            outcome.problems
        );
        assert!(outcome.markdown.contains(&shown));
    }
    assert!(outcome.markdown.contains("## Problems") && outcome.markdown.contains("**PROBLEMS: 3 run folder(s)"));
    let report = Report::from_results(&GridResults::load(dir.path()).unwrap());
    let r = cell(table(&report, "1"), BASELINE, Metric::Champion, "1");
    assert_eq!((r.n, r.mean), (1, 30.0));
}

#[test]
fn not_a_grid_is_an_error_naming_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let err = format!("{:#}", write_report(dir.path(), ReportFormat::Md).unwrap_err());
    assert!(
        err.contains(&dir.path().display().to_string()) && err.contains("grid.json"),
        "{err}"
    );
    let missing = dir.path().join("nowhere");
    let err = format!("{:#}", write_report(&missing, ReportFormat::Md).unwrap_err());
    assert!(err.contains("nowhere") && err.contains("not a directory"), "{err}");
    std::fs::write(dir.path().join("grid.json"), "{\"format\": \"something else\"}").unwrap();
    let err = format!("{:#}", write_report(dir.path(), ReportFormat::Md).unwrap_err());
    assert!(err.contains("not a psa-esp grid file"), "{err}");
}

#[test]
fn rules_decide_as_defined() {
    assert_eq!(Rule::Better.holds(46.2, 32.8, 9.5e-5), Some(true));
    assert_eq!(Rule::Better.holds(46.2, 32.8, 0.06), Some(false));
    assert_eq!(Rule::Better.holds(20.0, 32.8, 0.001), Some(false));
    assert_eq!(Rule::NoWorse.holds(20.0, 32.8, 0.001), Some(false));
    assert_eq!(Rule::NoWorse.holds(20.0, 32.8, 0.2), Some(true));
    assert_eq!(Rule::AboutAsGood.holds(50.0, 30.0, 0.05), Some(true));
    assert_eq!(Rule::AboutAsGood.holds(50.0, 30.0, f64::NAN), None);
    assert_eq!(Rule::Collapse.holds(16.3, 32.8, f64::NAN), Some(true));
    assert_eq!(Rule::Collapse.holds(16.4, 32.8, f64::NAN), Some(false));
    assert_eq!(Rule::Doubling.holds(15.0, 10.0, f64::NAN), Some(true));
    assert_eq!(Rule::Doubling.holds(f64::NAN, 10.0, f64::NAN), None);
    assert_eq!(Rule::Fewer.holds(1868.0, 2448.0, f64::NAN), Some(true));
}

#[test]
fn records_parse_by_header() {
    let rows = parse_records("champion,generation,min,mean,max\n5,1,0,1.5,5\n7,2,0.5,2,7\n").unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(
        rows[1],
        GenerationRow {
            generation: 2,
            min: 0.5,
            mean: 2.0,
            max: 7.0,
            champion: 7.0
        }
    );
    assert!(parse_records("").is_err());
    assert!(parse_records("generation,min,mean,max\n1,0,0,0\n").is_err());
    assert!(parse_records("generation,min,mean,max,champion\n").is_err());
    assert!(parse_records("generation,min,mean,max,champion\n1,0,NaN,0,0\n").is_err());
}

#[test]
fn empty_grid_is_reported_as_partial_and_not_testable() {
    let dir = tempfile::tempdir().unwrap();
    spec().save(dir.path()).unwrap();
    let outcome = write_report(dir.path(), ReportFormat::Json).unwrap();
    assert_eq!((outcome.exit_code(), outcome.counted, outcome.figures.len()), (0, 0, 0));
    let md = &outcome.markdown;
    assert!(md.contains("**PARTIAL GRID: 0 of 18 runs counted; 18 not started, 0 unfinished"));
    assert!(md.contains("No figures: no counted runs."));
    assert!(!md.contains("NaN"), "{md}");
    assert_eq!(md.matches("not testable (too few runs)**").count(), 9);
    // Undefined numbers are null in JSON.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap()).unwrap();
    assert!(json["tables"][0]["rows"][0]["mean"].is_null());
}

#[test]
fn p_values_print_like_the_paper() {
    use super::render::fmt_p;
    let printed: Vec<String> = [0.8, 0.35, 1.0, 0.1, 9.5e-5, 0.014, 0.0, f64::NAN].map(fmt_p).to_vec();
    assert_eq!(printed, ["0.8", "0.35", "1", "0.1", "9.5e-5", "1.4e-2", "0", "–"]);
}

#[test]
fn distance_terms_follow_their_definitions() {
    let (dir, _) = grid();
    let results = GridResults::load(dir.path()).unwrap();
    let d = Distance::of(&results);
    let term = |label: &str| d.terms.iter().find(|t| t.label == label).unwrap();
    // Table 1 task 1: baseline champions 10, 20, 30: mean 20, sd 10.
    let mean = term("Table 1 task 1");
    assert_eq!((mean.part, mean.here, mean.paper), (Part::Mean, 20.0, 42.4));
    assert!(close(mean.se, 12.8 / 30f64.sqrt()));
    let sd = term("Table 1 task 1 sd");
    assert_eq!((sd.part, sd.here, sd.paper), (Part::Spread, 10.0, 12.8));
    // The se of a sample sd over the paper's 30 runs: sd / sqrt(2 x 29).
    assert!(close(sd.se, 12.8 / 58f64.sqrt()));
    assert!(close(sd.z, (10.0 - 12.8) / (12.8 / 58f64.sqrt())));
    // No task 3 here: the burst totals and their ratio are missing, not counted.
    assert!(d.missing.iter().any(|m| m == "bursts max-credit / baseline"));
    assert!(d.missing.iter().any(|m| m.starts_with("bursts baseline")));
    let parts: f64 = Part::VARIANTS
        .iter()
        .map(|&p| d.terms.iter().filter(|t| t.part == p).map(|t| t.z * t.z).sum::<f64>())
        .sum();
    assert!(close(parts, d.total) && close(d.means + d.spreads + d.burst_ratio, d.total));
    assert!(
        d.burst_ratio == 0.0 && d.burst_ratio.is_sign_positive(),
        "a missing part prints as 0, not -0"
    );
}

#[test]
fn the_burst_ratio_is_max_credit_over_baseline_in_the_se_of_two_counts() {
    let dir = grid_of_all_tasks();
    let d = Distance::of(&GridResults::load(dir.path()).unwrap());
    let ratio = d.terms.iter().find(|t| t.part == Part::BurstRatio).unwrap();
    // Max credit never bursts here; the baseline bursts s times in seed s.
    let paper = 1868.0 / 2448.0;
    assert_eq!((ratio.here, ratio.paper), (0.0, paper));
    assert!(close(ratio.se, paper * (1.0 / 2448.0 + 1.0 / 1868.0f64).sqrt()));
    assert!(close(d.burst_ratio, ratio.z * ratio.z));
}

/// The grid made of the runs of `seeds` (with repeats), as a resample is.
fn with_seeds(results: &GridResults, seeds: &[u64]) -> GridResults {
    GridResults {
        runs: seeds
            .iter()
            .flat_map(|&s| results.runs.iter().filter(move |r| r.key.seed == s).cloned())
            .collect(),
        ..results.clone()
    }
}

/// Whether `x` lies between the order statistics around quantile `q` of `sorted`.
fn near_quantile(x: f64, sorted: &[f64], q: f64) -> bool {
    let at = q * (sorted.len() - 1) as f64;
    let (below, above) = (
        sorted[(at.floor() as usize).saturating_sub(1)],
        sorted[(at.ceil() as usize + 1).min(sorted.len() - 1)],
    );
    below - 1e-9 <= x && x <= above + 1e-9
}

#[test]
fn intervals_and_replication_rates_match_a_direct_computation() {
    use super::uncertainty::{seed_draws, LEVEL, RESAMPLES};
    // All three tasks, so that every term of D has runs.
    let dir = grid_of_all_tasks();
    let results = GridResults::load(dir.path()).unwrap();
    let report = Report::from_results(&results);
    assert!(report.distance.missing.is_empty());

    // A cell: baseline champions on task 1 are 10, 20, 30 (mean 20, sd 10,
    // n 3). Student's t(0.975, 2) = 4.302652729911275; the chi-square with
    // 2 degrees of freedom has quantiles -2 ln(1 - q).
    let row = cell(table(&report, "1"), BASELINE, Metric::Champion, "1");
    let mean = row.mean_interval.unwrap();
    let half = 4.302652729911275 * 10.0 / 3f64.sqrt();
    assert!(close(mean.lo, 20.0 - half) && close(mean.hi, 20.0 + half), "{mean:?}");
    let sd = row.sd_interval.unwrap();
    let tail = (1.0 - LEVEL) / 2.0;
    let chi = |q: f64| -2.0 * (1.0 - q).ln();
    assert!(close(sd.lo, (200.0 / chi(1.0 - tail)).sqrt()), "{sd:?}");
    assert!(close(sd.hi, (200.0 / chi(tail)).sqrt()), "{sd:?}");

    // D and the verdicts on every resample, computed here from the draws.
    let resampled: Vec<GridResults> = (0..RESAMPLES)
        .map(|i| with_seeds(&results, &seed_draws(1, 3, i)))
        .collect();
    let mut totals: Vec<f64> = resampled.iter().map(|g| Distance::of(g).total).collect();
    totals.sort_by(f64::total_cmp);
    let d = report.uncertainty.distance.total.unwrap();
    assert!(
        near_quantile(d.lo, &totals, tail) && near_quantile(d.hi, &totals, 1.0 - tail),
        "{d:?}"
    );
    assert!(d.lo < d.hi, "three seeds that differ give a spread");
    let verdicts: Vec<Vec<Verdict>> = resampled
        .iter()
        .map(|g| super::findings::findings(g).iter().map(|f| f.verdict).collect())
        .collect();
    for (i, f) in report.findings.iter().enumerate() {
        let same = verdicts.iter().filter(|v| v[i] == f.verdict).count();
        let expected = (f.verdict != Verdict::NotTestable).then_some(same as f64 / RESAMPLES as f64);
        assert_eq!(f.replication, expected, "{}", f.claim);
    }
    // Max credit's bursts (0) are below the baseline's (the seed) on every resample.
    assert_eq!(finding(&report, "fewer burst").replication, Some(1.0));

    // The same in the files: report.md, report.csv and report.json.
    write_report(dir.path(), ReportFormat::Csv).unwrap();
    let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(
        md.contains(&format!(
            "| 1 | 3 | 20.0 [{:.1}, {:.1}] | 10.0 [",
            20.0 - half,
            20.0 + half
        )),
        "{md}"
    );
    assert!(
        md.contains(&format!("D = {:.1} [{:.1}, {:.1}]", report.distance.total, d.lo, d.hi)),
        "{md}"
    );
    assert!(md.contains("(the same on 100 % of seed resamples)"), "{md}");
    let csv = std::fs::read_to_string(dir.path().join("report.csv")).unwrap();
    assert!(
        csv.contains(&format!(
            "distance,,D,All,,{},,,,,,{},{},,,,",
            report.distance.total, d.lo, d.hi
        )),
        "{csv}"
    );
    assert!(csv.contains("finding,\"max credit needs fewer burst mutations than the baseline\",\"fewer\",All,,,,,,,,,,,,reproduced,1\n"), "{csv}");
    write_report(dir.path(), ReportFormat::Json).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap()).unwrap();
    assert_eq!(json["uncertainty"]["distance"]["total"]["lo"], d.lo);
    assert_eq!(json["uncertainty"]["resamples"], RESAMPLES);
    assert_eq!(json["tables"][0]["rows"][0]["mean_interval"]["hi"], mean.hi);
    // The same numbers on every run.
    assert_eq!(Report::from_results(&results).uncertainty, report.uncertainty);
}

#[test]
fn a_grid_against_another_on_the_same_seeds_is_compared_paired_and_on_other_seeds_refused() {
    let (dir, same) = (grid_of_all_tasks(), grid_of_all_tasks());
    let spec = GridSpec::load(dir.path()).unwrap();
    let outcome = write_report_against(dir.path(), ReportFormat::Csv, Some(same.path())).unwrap();
    // The same runs: ΔD is 0 on every resample, so not told apart.
    assert!(
        outcome
            .markdown
            .contains("paired by seed: ΔD = 0.0 [0.0, 0.0]; this grid is not told apart on these seeds from it."),
        "{}",
        outcome.markdown
    );
    let csv = std::fs::read_to_string(dir.path().join("report.csv")).unwrap();
    assert!(csv.contains(",difference,All,,0,,,,,,0,0,,,,\n"), "{csv}");
    let shifted = tempfile::tempdir().unwrap();
    let other = GridSpec {
        first_seed: 2,
        ..spec.clone()
    };
    other.save(shifted.path()).unwrap();
    let err = write_report_against(dir.path(), ReportFormat::Md, Some(shifted.path())).unwrap_err();
    let text = format!("{err:#}");
    assert!(text.contains("seeds 1 to 3") && text.contains("seeds 2 to 4"), "{text}");
}
