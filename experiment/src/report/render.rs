//! The report as Markdown and as CSV.

use std::fmt::Write as _;

use super::distance::Distance;
use super::findings::{Comparison, Finding, Rule, ALPHA, COLLAPSE_FRACTION, DOUBLING_RATIO};
use super::paper::PAPER_BURST_RUNS;
use super::tables::{Report, Table};
use super::uncertainty::{GridUncertainty, Interval, LEVEL};
use crate::grid::{GridPreset, GridSpec};
use crate::PAPER_NOISE_SD;
use psa_sim::named::Named;

/// A mean or sd with one decimal; "–" when undefined.
pub(super) fn num(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else {
        format!("{x:.1}")
    }
}

/// A value with its interval, one decimal each: "42.4 [37.1, 47.7]"; the
/// value alone without one.
pub(super) fn with_interval(x: f64, interval: Option<Interval>) -> String {
    match interval {
        Some(i) => format!("{} [{}, {}]", num(x), num(i.lo), num(i.hi)),
        None => num(x),
    }
}

/// A p-value as the paper prints it: up to two decimals from 0.1 up ("0.8"), else
/// scientific with two digits ("1.8e-4"); "–" when undefined.
pub(super) fn fmt_p(p: f64) -> String {
    if p.is_nan() {
        "–".into()
    } else if p == 0.0 {
        "0".into()
    } else if p >= 0.1 {
        let text = format!("{p:.2}");
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{p:.1e}")
    }
}

/// The report as Markdown.
pub fn markdown(report: &Report) -> String {
    let mut md = String::from(
        "# Replication report: Høverstad (GECCO 2007), \"Revisiting the Personal Satellite Assistant\"\n\n",
    );
    banners(&mut md, report);
    grid_section(&mut md, report);
    missing_section(&mut md, report);
    problems_section(&mut md, report);
    md.push_str("## Champion fitness (Tables 1 and 4-7)\n\n");
    for table in report.tables.iter().filter(|t| !matches!(t.id.as_str(), "2" | "3")) {
        table_md(&mut md, table);
        if table.id == "5" {
            bursts_md(&mut md, report);
        }
    }
    md.push_str("## Robustness of the champions (Tables 2 and 3)\n\n");
    let _ = writeln!(
        md,
        "Each champion is flown once clean (standard start, no noise), {} times with Gaussian noise sd {PAPER_NOISE_SD} on every input, \
         and (tasks 1 and 3) {} times from random initial conditions; the tables give mean and sd over the champions of their mean fitness. \
         The paper's clean row is its Table 1.\n",
        report.grid.robustness_trials, report.grid.robustness_trials
    );
    for table in report.tables.iter().filter(|t| matches!(t.id.as_str(), "2" | "3")) {
        table_md(&mut md, table);
    }
    distance_md(&mut md, &report.distance, &report.uncertainty);
    if let Some(against) = &report.against {
        let p = &against.paired;
        let _ = writeln!(
            md,
            "Against `{}` (D = {:.1}), paired by seed: ΔD = {}; this grid is {}.\n",
            against.reference,
            against.reference_total,
            with_interval(p.difference, p.interval),
            p.describe("it")
        );
    }
    findings_md(&mut md, report);
    figures_md(&mut md, report);
    md
}

/// The distance to the paper and its terms, with the intervals of D and
/// its parts from `uncertainty`.
pub(super) fn distance_md(md: &mut String, distance: &Distance, uncertainty: &GridUncertainty) {
    md.push_str(
        "## Distance to the paper

",
    );
    let d = &uncertainty.distance;
    let _ = writeln!(
        md,
        "D = {}: the sum of ((here - paper) / se)^2 over Table 1's and Table 2's means and the two burst totals \
         (the means: {}), the standard deviations of the same cells (the spreads: {}) and max credit's bursts \
         over the baseline's (the burst ratio: {}); se is the paper's sd / sqrt(30) for a mean, sd / sqrt(58) for \
         an sd, sqrt(total) for a total (see docs/model.md). {}\n",
        with_interval(distance.total, d.total),
        with_interval(distance.means, d.means),
        with_interval(distance.spreads, d.spreads),
        with_interval(distance.burst_ratio, d.burst_ratio),
        resampling_note(uncertainty)
    );
    md.push_str("| part | term | here | paper | se | z |\n|---|---|---|---|---|---|\n");
    for t in &distance.terms {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {:+.1} |",
            t.part.name(),
            t.label,
            num(t.here),
            num(t.paper),
            num(t.se),
            t.z
        );
    }
    if !distance.missing.is_empty() {
        let _ = writeln!(md, "\nNot in D (no runs here): {}.", distance.missing.join(", "));
    }
    md.push('\n');
}

/// How the bracketed intervals of D were made, in one sentence.
pub(super) fn resampling_note(uncertainty: &GridUncertainty) -> String {
    format!(
        "In brackets, the {:.0} % interval from {} resamples of the grid's seeds (every run of a drawn seed, drawn with replacement; \
         the 2.5 and 97.5 % quantiles; stream seed {:#x}, so the same on every run; docs/statistics.md).",
        uncertainty.level * 100.0,
        uncertainty.resamples,
        uncertainty.seed
    )
}

fn banners(md: &mut String, report: &Report) {
    if !report.reduced.is_empty() {
        let _ = writeln!(
            md,
            "**REDUCED GRID (not the paper's protocol): {}. \
             Absolute numbers and p-values are not comparable with the paper's; with few seeds per task the tests have little power.**\n",
            report.reduced.join("; ")
        );
    }
    let (missing, unfinished) = report.incomplete_runs();
    if missing + unfinished > 0 {
        let _ = writeln!(
            md,
            "**PARTIAL GRID: {} of {} runs counted; {missing} not started, {unfinished} unfinished (see \"Missing runs\"). \
             Every number below is over the counted runs only.**\n",
            report.runs_counted, report.runs_expected
        );
    }
    if !report.problems.is_empty() {
        let _ = writeln!(
            md,
            "**PROBLEMS: {} run folder(s) are damaged or hold another configuration and are not counted (see \"Problems\").**\n",
            report.problems.len()
        );
    }
    if !report.mixed_models.is_empty() {
        let _ = writeln!(
            md,
            "**MIXED MODELS: runs of one configuration and task flew different models (written by builds with other defaults); \
             every number below averages them: {}.**\n",
            report.mixed_models.join("; ")
        );
    }
}

fn grid_section(md: &mut String, report: &Report) {
    let g = &report.grid;
    let configs: Vec<&str> = g.configs.iter().map(|c| c.name()).collect();
    let tasks: Vec<String> = g.tasks.iter().map(|t| t.to_string()).collect();
    md.push_str("## Grid\n\n| | |\n|---|---|\n");
    let preset = serde_json::to_value(g.preset).ok();
    let preset = preset.as_ref().and_then(|v| v.as_str()).unwrap_or("?");
    let backend = g.backend.to_string();
    let rows = [
        ("preset", preset.to_string()),
        ("configurations", configs.join(", ")),
        ("tasks", tasks.join(", ")),
        ("seeds", format!("{} per configuration and task", g.seeds_label())),
        ("generations (ESP) / cycles (hill-climbing)", g.generations.to_string()),
        ("physics backend", backend),
        (
            "robustness trials",
            format!("{} per test (input noise sd {PAPER_NOISE_SD})", g.robustness_trials),
        ),
        (
            "runs counted",
            format!("{} of {}", report.runs_counted, report.runs_expected),
        ),
        (
            "compute",
            format!("{:.0} s wall-clock over the counted runs", report.compute_seconds),
        ),
    ];
    for (k, v) in rows {
        let _ = writeln!(md, "| {k} | {v} |");
    }
    if !report.readings.is_empty() {
        let _ = writeln!(md, "| readings | {} |", report.readings.join("; "));
    }
    // Every setting the grid's own overrides (`--config`) change from the
    // defaults and a run of the grid reads, so that report.md alone tells
    // two such grids apart, and names nothing its runs do not fly.
    if let Some(text) = &g.overrides {
        let changed = crate::RunConfig::baseline_with(text).and_then(|with| {
            let mut read = Vec::new();
            for differ in crate::grid::differences(&crate::RunConfig::baseline_with("")?, &with)? {
                if g.reads_setting(&differ.0)? {
                    read.push(differ);
                }
            }
            Ok(read)
        });
        let shown: Vec<String> = match changed {
            Ok(differ) => differ
                .iter()
                .map(|(key, default, here)| format!("`{key} = {here}` (default {default})"))
                .collect(),
            Err(e) => vec![format!("unreadable: {e:#}")],
        };
        if !shown.is_empty() {
            let _ = writeln!(md, "| settings changed from the defaults | {} |", shown.join("; "));
        }
    }
    if let Some(rescoring) = &g.rescoring {
        let settings: Vec<String> = rescoring
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| format!("`{l}`"))
            .collect();
        let _ = writeln!(
            md,
            "| re-scored | champions tested again by `psa-esp rescore` with {} |",
            settings.join(" ")
        );
    }
    for b in &report.builds {
        let _ = writeln!(
            md,
            "| build | psa-esp {}, git commit {}, libode {} ({} runs) |",
            b.build.tool_version, b.build.git_commit, b.build.libode_version, b.runs
        );
    }
    let _ = writeln!(
        md,
        "\nFitness is in % of the theoretical maximum. \"here\" is this grid, \"paper\" is Høverstad (2007). \
         p is Welch's two-tailed two-sample t-test with unequal variances, as in the paper: per task (30 vs 30 runs in the paper) \
         and for All (the tasks pooled, 90 vs 90). sd is the sample standard deviation; \"–\" marks a value that needs more runs. \
         In brackets, the {:.0} % interval: Student's t for a mean, the chi-square interval for an sd (docs/statistics.md).\n",
        LEVEL * 100.0
    );
}

fn missing_section(md: &mut String, report: &Report) {
    if report.missing.is_empty() {
        return;
    }
    md.push_str(
        "## Missing runs\n\n| configuration | task | not started | unfinished | e.g. |\n|---|---|---|---|---|\n",
    );
    for c in &report.missing {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            c.config,
            c.task,
            c.missing,
            c.unfinished,
            c.examples
                .iter()
                .map(|e| format!("`{e}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    md.push_str("\nRun `psa-esp replicate` again with the same options to finish them.\n\n");
}

fn problems_section(md: &mut String, report: &Report) {
    if report.problems.is_empty() {
        return;
    }
    md.push_str("## Problems\n\nThese run folders are not counted. Move them away and run `psa-esp replicate` again to redo them.\n\n");
    for p in &report.problems {
        let folder = p.folder.display().to_string();
        let message = p.message.replace('\n', " ");
        if message.contains(&folder) {
            let _ = writeln!(md, "- {message}");
        } else {
            let _ = writeln!(md, "- `{folder}`: {message}");
        }
    }
    md.push('\n');
}

fn table_md(md: &mut String, table: &Table) {
    let _ = writeln!(md, "### {}\n", table.title);
    let many_configs = table.rows.iter().any(|r| r.config != table.rows[0].config);
    let many_metrics = table.rows.iter().any(|r| r.metric != table.rows[0].metric);
    let paper_p = table.rows.iter().any(|r| r.paper.is_some_and(|c| c.p.is_some()));
    let mut header = Vec::new();
    if many_configs {
        header.push("configuration".to_string());
    }
    if many_metrics {
        header.push("test".to_string());
    }
    header.extend(["task", "n", "here mean", "here sd"].map(String::from));
    if table.p_against.is_some() {
        header.push("here p".into());
    }
    header.extend(["paper mean", "paper sd"].map(String::from));
    if paper_p {
        header.push("paper p".into());
    }
    let _ = writeln!(md, "| {} |", header.join(" | "));
    let _ = writeln!(md, "|{}", "---|".repeat(header.len()));
    for r in &table.rows {
        let mut cells = Vec::new();
        if many_configs {
            cells.push(r.config.to_string());
        }
        if many_metrics {
            cells.push(r.metric.describe().to_string());
        }
        cells.extend([
            r.task.clone(),
            r.n.to_string(),
            with_interval(r.mean, r.mean_interval),
            with_interval(r.sd, r.sd_interval),
        ]);
        if table.p_against.is_some() {
            cells.push(r.p.map_or("–".into(), fmt_p));
        }
        cells.push(r.paper.map_or("–".into(), |c| num(c.mean)));
        cells.push(r.paper.map_or("–".into(), |c| num(c.sd)));
        if paper_p {
            cells.push(r.paper.and_then(|c| c.p).map_or("–".into(), fmt_p));
        }
        let _ = writeln!(md, "| {} |", cells.join(" | "));
    }
    if let Some(against) = &table.p_against {
        let _ = writeln!(md, "\np against {against}.");
    }
    md.push('\n');
}

fn bursts_md(md: &mut String, report: &Report) {
    md.push_str("#### Burst mutations\n\n");
    let _ = writeln!(
        md,
        "The paper counts burst mutations over its {PAPER_BURST_RUNS} runs (30 seeds x 3 tasks) of {} generations; \
         \"per {PAPER_BURST_RUNS} runs\" scales this grid's mean to the same number of runs (not of generations: here {} per run).\n",
        GridSpec::from_preset(GridPreset::Paper).generations,
        report.grid.generations
    );
    let _ = writeln!(
        md,
        "| configuration | runs | total here | per run here (sd) | per {PAPER_BURST_RUNS} runs here | paper total ({PAPER_BURST_RUNS} runs) |\n|---|---|---|---|---|---|"
    );
    for b in &report.bursts {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} ({}) | {} | {} |",
            b.config,
            b.runs,
            b.total,
            with_interval(b.per_run, b.per_run_interval),
            num(b.sd),
            if b.per_run.is_nan() {
                "–".into()
            } else {
                format!("{:.0}", b.per_run * PAPER_BURST_RUNS as f64)
            },
            b.paper_total.map_or("–".into(), |t| t.to_string())
        );
    }
    md.push('\n');
}

/// a / b with `decimals` decimals; "–" when undefined or infinite.
fn ratio(a: f64, b: f64, decimals: usize) -> String {
    let r = a / b;
    if r.is_finite() {
        format!("{r:.decimals$}")
    } else {
        "–".into()
    }
}

/// One comparison in words, per rule.
fn comparison(rule: Rule, c: &Comparison) -> String {
    let n = format!("n {} vs {}", c.n_a, c.n_b);
    let p = if c.p.is_nan() {
        String::new()
    } else {
        format!(", p = {}", fmt_p(c.p))
    };
    match rule {
        Rule::Better | Rule::NoWorse | Rule::AboutAsGood => {
            format!("{}: {} vs {} ({n}){p}", c.label, num(c.a), num(c.b))
        }
        Rule::Collapse => format!(
            "{}: {} vs clean {} ({} % of clean; {n})",
            c.label,
            num(c.a),
            num(c.b),
            ratio(100.0 * c.a, c.b, 0)
        ),
        Rule::Doubling => format!(
            "{}: {} vs {} (x{}; {n}){p}",
            c.label,
            num(c.a),
            num(c.b),
            ratio(c.a, c.b, 2)
        ),
        Rule::Fewer => format!("{}: {} vs {} per run ({n} runs){p}", c.label, num(c.a), num(c.b)),
    }
}

fn finding_md(md: &mut String, f: &Finding) {
    let side = |cs: &[Comparison]| cs.iter().map(|c| comparison(f.rule, c)).collect::<Vec<_>>().join("; ");
    let check = if f.holds_in_paper {
        ""
    } else {
        " (the rule does not hold on the paper's own numbers)"
    };
    let replication = f.replication.map_or(String::new(), |r| {
        format!(" (the same on {:.0} % of seed resamples)", r * 100.0)
    });
    let _ = writeln!(
        md,
        "- **{}** ({}). Paper: {}{check}. Here: {}. — **{}**{replication}",
        f.claim,
        f.measure,
        side(&f.paper),
        side(&f.here),
        f.verdict.describe()
    );
}

fn findings_md(md: &mut String, report: &Report) {
    md.push_str("## Findings\n\n");
    let _ = writeln!(
        md,
        "Each finding of the paper is judged by a fixed rule, applied to the paper's numbers (as a check of the rule) and to this grid's:\n\n\
         - \"better\" = higher mean and Welch p < {ALPHA}; \"no worse\" = not (lower mean and p < {ALPHA}); \"about as good\" = p >= {ALPHA} (champion fitness, all tasks pooled, against the baseline);\n\
         - \"collapse\" = mean under the test < {:.0} % of the same champions' clean mean;\n\
         - \"roughly doubling\" = mean of champions evolved under noise >= {DOUBLING_RATIO} x that of champions evolved clean, both tested under noise, on each of tasks 1 and 2;\n\
         - \"fewer\" = lower mean per run (the paper gives totals over 90 runs);\n\
         - \"not testable\" = too few counted runs (a Welch rule needs at least 2 per side, a ratio rule 1).\n\n\
         The replication rate after a verdict is the share of {} resamples of the grid's seeds (as for D's interval) on which the rule gives the same verdict: \
         a verdict near 50 % could go either way on another draw of seeds.\n",
        COLLAPSE_FRACTION * 100.0,
        report.uncertainty.resamples
    );
    if !report.reduced.is_empty() || report.runs_counted < report.runs_expected {
        md.push_str("The grid is reduced or partial: the verdicts rest on fewer runs than the paper's.\n\n");
    }
    for f in &report.findings {
        finding_md(md, f);
    }
    md.push('\n');
}

fn figures_md(md: &mut String, report: &Report) {
    md.push_str("## Figures\n\n");
    for f in &report.figures {
        let _ = writeln!(md, "### {}\n\n![{}]({})\n\n[SVG]({})\n", f.title, f.title, f.png, f.svg);
    }
    for p in &report.figure_problems {
        let _ = writeln!(md, "- not drawn: {p}");
    }
    if report.figures.is_empty() && report.figure_problems.is_empty() {
        md.push_str("No figures: no counted runs.\n");
    }
}

/// A CSV field: empty when undefined.
fn field(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        x.to_string()
    }
}

/// An interval's two ends as CSV fields: empty without one.
fn ends(interval: Option<Interval>) -> [String; 2] {
    interval.map_or([String::new(), String::new()], |i| [field(i.lo), field(i.hi)])
}

/// A text field, quoted (it may hold commas).
fn quoted(text: &str) -> String {
    format!("\"{}\"", text.replace('"', "\"\""))
}

/// The header of `report.csv`.
pub const REPORT_CSV_HEADER: &str =
    "table,configuration,metric,task,n,mean,sd,p,paper_mean,paper_sd,paper_p,mean_lo,mean_hi,sd_lo,sd_hi,verdict,replication";

/// The report as CSV, one row per table cell, with each cell's interval
/// (`mean_lo`, `mean_hi`, `sd_lo`, `sd_hi`); then burst mutations as table
/// "bursts" (mean and sd per run; paper_mean is the paper's total / 90);
/// D and its parts as table "distance" (metric = the part, mean = its value,
/// mean_lo/mean_hi = its seed-resampling interval); each finding as table
/// "finding" (configuration = its claim, verdict, replication = the share
/// of seed resamples with the same verdict).
pub fn csv(report: &Report) -> String {
    let mut csv = format!("{REPORT_CSV_HEADER}\n");
    for t in &report.tables {
        for r in &t.rows {
            let paper = r
                .paper
                .map_or([f64::NAN; 3], |c| [c.mean, c.sd, c.p.unwrap_or(f64::NAN)]);
            let [mean_lo, mean_hi] = ends(r.mean_interval);
            let [sd_lo, sd_hi] = ends(r.sd_interval);
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{mean_lo},{mean_hi},{sd_lo},{sd_hi},,",
                t.id,
                r.config,
                r.metric.describe(),
                r.task,
                r.n,
                field(r.mean),
                field(r.sd),
                field(r.p.unwrap_or(f64::NAN)),
                field(paper[0]),
                field(paper[1]),
                field(paper[2])
            );
        }
    }
    for b in &report.bursts {
        let paper = b.paper_total.map_or(f64::NAN, |t| t as f64 / PAPER_BURST_RUNS as f64);
        let [lo, hi] = ends(b.per_run_interval);
        let _ = writeln!(
            csv,
            "bursts,{},bursts,All,{},{},{},,{},,,{lo},{hi},,,,",
            b.config,
            b.runs,
            field(b.per_run),
            field(b.sd),
            field(paper)
        );
    }
    let d = &report.distance;
    let i = &report.uncertainty.distance;
    for (part, value, interval) in [
        ("D", d.total, i.total),
        ("means", d.means, i.means),
        ("spreads", d.spreads, i.spreads),
        ("burst ratio", d.burst_ratio, i.burst_ratio),
    ] {
        let [lo, hi] = ends(interval);
        let _ = writeln!(csv, "distance,,{part},All,,{},,,,,,{lo},{hi},,,,", field(value));
    }
    if let Some(against) = &report.against {
        let [lo, hi] = ends(against.paired.interval);
        let _ = writeln!(
            csv,
            "distance,{},difference,All,,{},,,,,,{lo},{hi},,,,",
            quoted(&against.reference),
            field(against.paired.difference)
        );
    }
    for f in &report.findings {
        let _ = writeln!(
            csv,
            "finding,{},{},All,,,,,,,,,,,,{},{}",
            quoted(&f.claim),
            quoted(&serde_json::to_value(f.rule).map_or(String::new(), |v| v.as_str().unwrap_or_default().to_string())),
            f.verdict.describe(),
            f.replication.map_or(String::new(), field)
        );
    }
    csv
}
