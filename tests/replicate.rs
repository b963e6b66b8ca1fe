//! The replication grid end to end: resume after kill -9, damaged and
//! foreign run folders, and the report of a tiny grid.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::{psa_esp, run_file_paths, run_files};

/// A small grid: 3 configurations x task 1 x 4 seeds, on one thread.
fn grid_args(out: &Path) -> Vec<String> {
    [
        "replicate",
        "--configs",
        "baseline,max-credit,hill-climb",
        "--tasks",
        "1",
        "--seeds",
        "4",
        "--generations",
        "25",
        "--robustness-trials",
        "20",
        "--jobs",
        "1",
        "--out",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain([out.to_str().unwrap().to_string()])
    .collect()
}

/// A tiny baseline grid on `tasks` with `seeds` seeds (3 generations, 5
/// robustness trials), written to `out`.
fn tiny_baseline_grid<'a>(tasks: &'a str, seeds: &'a str, out: &'a Path) -> [&'a str; 13] {
    [
        "replicate",
        "--configs",
        "baseline",
        "--tasks",
        tasks,
        "--seeds",
        seeds,
        "--generations",
        "3",
        "--robustness-trials",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]
}

/// Every result file of every run folder, by relative path (provenance
/// times in run.json excluded: they say when, not what).
fn results(dir: &Path) -> Vec<(String, Vec<u8>)> {
    run_file_paths(dir)
        .into_iter()
        .filter(|path| {
            ["records.csv", "champion.json", "robustness.json", "config.toml"]
                .contains(&path.file_name().unwrap().to_str().unwrap())
        })
        .map(|path| {
            let bytes = std::fs::read(&path).unwrap();
            (path.strip_prefix(dir).unwrap().display().to_string(), bytes)
        })
        .collect()
}

fn finished_runs(dir: &Path) -> usize {
    results(dir)
        .iter()
        .filter(|(p, _)| p.ends_with("robustness.json"))
        .count()
}

#[test]
fn a_grid_killed_part_way_resumes_to_the_same_results() {
    let tmp = tempfile::tempdir().unwrap();
    let (whole, killed) = (tmp.path().join("whole"), tmp.path().join("killed"));
    let o = psa_esp(&grid_args(&whole).iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(finished_runs(&whole), 12);

    // Start the same grid elsewhere and kill -9 it once some runs are done.
    let mut child = Command::new(env!("CARGO_BIN_EXE_psa-esp"))
        .args(grid_args(&killed))
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(120);
    let finished_so_far = |dir: &Path| {
        if dir.join("runs").exists() {
            finished_runs(dir)
        } else {
            0
        }
    };
    while finished_so_far(&killed) < 2 {
        assert!(Instant::now() < deadline, "no run finished in time");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done_before = finished_runs(&killed);
    assert!(
        done_before < 12,
        "the grid finished before it could be killed; make it larger"
    );

    // Resuming (on two threads this time) skips the finished runs and
    // completes the rest identically.
    let mut resume = grid_args(&killed);
    let jobs = resume.iter().position(|a| a == "--jobs").unwrap();
    resume[jobs + 1] = "2".into();
    let o = psa_esp(&resume.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains(&format!("{done_before} already finished")), "{stdout}");
    assert!(
        results(&whole) == results(&killed),
        "resumed grid differs from the uninterrupted one"
    );
}

#[test]
fn a_lockstep_grid_killed_part_way_resumes_from_its_checkpoints_to_the_same_files() {
    let tmp = tempfile::tempdir().unwrap();
    let (whole, killed) = (tmp.path().join("whole"), tmp.path().join("killed"));
    let args = |out: &Path| -> Vec<String> {
        [
            "replicate",
            "--configs",
            "baseline,hill-climb",
            "--tasks",
            "1",
            "--seeds",
            "2",
            "--generations",
            "400",
            "--robustness-trials",
            "5",
            "--lockstep",
            "--threads",
            "2",
            "--out",
            out.to_str().unwrap(),
        ]
        .map(String::from)
        .to_vec()
    };
    let o = psa_esp(&args(&whole).iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    // Kill -9 the same grid elsewhere once every run has a checkpoint.
    let mut child = Command::new(common::binary()).args(args(&killed)).spawn().unwrap();
    let deadline = Instant::now() + Duration::from_secs(120);
    let checkpoints = |dir: &Path| -> usize {
        if !dir.join("runs").exists() {
            return 0;
        }
        run_file_paths(dir)
            .iter()
            .filter(|p| p.ends_with("checkpoint.json"))
            .count()
    };
    while checkpoints(&killed) < 4 {
        assert!(Instant::now() < deadline, "no checkpoints in time");
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(
        finished_runs(&killed),
        0,
        "the grid finished before it could be killed; make it longer"
    );

    // Started again, each run resumes from its checkpoint, and the grid's
    // files are those of the uninterrupted grid, checkpoints gone.
    let o = Command::new(common::binary())
        .args(args(&killed))
        .env("RUST_LOG", "info")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let log = String::from_utf8_lossy(&o.stderr);
    assert_eq!(log.matches("resumed after generation").count(), 4, "{log}");
    assert!(
        run_files(&whole) == run_files(&killed),
        "resumed lockstep grid differs from the uninterrupted one"
    );
}

/// Every run's `run.json` without its times (started, finished, seconds).
fn summaries(dir: &Path) -> Vec<(String, serde_json::Value)> {
    run_file_paths(dir)
        .into_iter()
        .filter(|path| path.ends_with("run.json"))
        .map(|path| {
            let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
            for time in ["started", "finished", "seconds"] {
                json.as_object_mut()
                    .unwrap()
                    .remove(time)
                    .expect("run.json has its times");
            }
            (path.strip_prefix(dir).unwrap().display().to_string(), json)
        })
        .collect()
}

#[test]
fn a_grid_in_lockstep_writes_the_files_of_run_by_run_byte_for_byte() {
    let tmp = tempfile::tempdir().unwrap();
    let (apart, together) = (tmp.path().join("apart"), tmp.path().join("together"));
    // ESP, the hill-climber, input noise and random starts (both draw from the
    // evaluation streams), on task 1.
    let args = |out: &Path, lockstep: bool| {
        let mut args: Vec<String> = [
            "replicate",
            "--configs",
            "baseline,gomez,hill-climb,input-noise,random-init",
            "--tasks",
            "1",
            "--seeds",
            "2",
            "--generations",
            "30",
            "--robustness-trials",
            "10",
            "--out",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([out.to_str().unwrap().to_string()])
        .collect();
        if lockstep {
            args.extend(["--lockstep".into(), "--threads".into(), "2".into()]);
        } else {
            args.extend(["--jobs".into(), "1".into()]);
        }
        args
    };
    for (dir, lockstep) in [(&apart, false), (&together, true)] {
        let o = psa_esp(&args(dir, lockstep).iter().map(String::as_str).collect::<Vec<_>>());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(finished_runs(dir), 10);
    }
    assert!(
        results(&apart) == results(&together),
        "lockstep grid differs from the run-by-run one"
    );
    assert_eq!(summaries(&apart), summaries(&together));
    assert_eq!(summaries(&apart).len(), 10);
    // Gomez's ESP, not in the paper, gets its table when the grid runs it.
    let o = psa_esp(&["report", apart.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(apart.join("report.md")).unwrap();
    assert!(md.contains("### Gomez's ESP"), "{md}");
}

#[test]
fn damaged_or_foreign_run_folders_are_reported_and_left_untouched() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("grid");
    let args = tiny_baseline_grid("2", "3", &dir);
    assert!(psa_esp(&args).status.success());
    let seed1 = dir.join("runs/baseline/task2/seed1");
    let seed2 = dir.join("runs/baseline/task2/seed2");
    let seed3 = dir.join("runs/baseline/task2/seed3");
    // A truncated summary, a missing champion, another configuration under the same name.
    let summary = std::fs::read_to_string(seed1.join("run.json")).unwrap();
    std::fs::write(seed1.join("run.json"), &summary[..summary.len() / 2]).unwrap();
    std::fs::remove_file(seed2.join("champion.json")).unwrap();
    let config = std::fs::read_to_string(seed3.join("config.toml")).unwrap();
    std::fs::write(
        seed3.join("config.toml"),
        config.replace("subpop_size = 40", "subpop_size = 20"),
    )
    .unwrap();
    let before = results(&dir);
    let o = psa_esp(&args);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    for (folder, needle) in [
        (&seed1, "run.json"),
        (&seed2, "champion.json"),
        (&seed3, "different configuration"),
    ] {
        assert!(err.contains(folder.to_str().unwrap()), "{err}");
        assert!(err.contains(needle), "{err}");
    }
    assert!(results(&dir) == before, "a damaged folder was overwritten");
    // A directory of someone else's: run folders but no grid.json.
    std::fs::remove_file(dir.join("grid.json")).unwrap();
    let o = psa_esp(&args);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no grid.json"));
}

#[test]
fn a_run_is_judged_on_the_settings_its_task_reads_only() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("grid");
    let args = tiny_baseline_grid("1,2", "1", &dir);
    assert!(psa_esp(&args).status.success());
    // Both runs as a build with another task-2 start would have written them.
    let task1 = dir.join("runs/baseline/task1/seed1");
    let task2 = dir.join("runs/baseline/task2/seed1");
    for folder in [&task1, &task2] {
        let config = std::fs::read_to_string(folder.join("config.toml")).unwrap();
        let line = config.lines().find(|l| l.starts_with("task2_spin = ")).unwrap();
        std::fs::write(folder.join("config.toml"), config.replace(line, "task2_spin = 0.3")).unwrap();
    }
    let before = results(&dir);
    let o = psa_esp(&args);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    // Task 2 reads its start: refused, named. Task 1 does not: the same run.
    assert!(
        err.contains(task2.to_str().unwrap()) && err.contains("problem.tasks.task2_spin"),
        "{err}"
    );
    assert!(!err.contains(task1.to_str().unwrap()), "{err}");
    // No build ever started task 2 at 0.3 rad/s: a run of another grid,
    // which `report` refuses too, and the refusal says so.
    assert!(
        err.contains("another grid") && err.contains("does not count either") && !err.contains("`report` reads it"),
        "{err}"
    );
    let o = psa_esp(&["report", dir.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("task2/seed1"));
    assert!(results(&dir) == before, "a run folder was overwritten");
    // Without the task-2 run, the grid resumes it and keeps task 1's.
    std::fs::remove_dir_all(&task2).unwrap();
    let o = psa_esp(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read_to_string(task1.join("config.toml"))
        .unwrap()
        .contains("task2_spin = 0.3"));
    let o = psa_esp(&["report", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_tiny_grid_reports_every_table_and_figure() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("tiny");
    let o = psa_esp(&[
        "replicate",
        "--seeds",
        "2",
        "--generations",
        "3",
        "--robustness-trials",
        "3",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = psa_esp(&["report", dir.to_str().unwrap(), "--format", "json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for needle in [
        "REDUCED GRID",
        "Table 1",
        "Table 2",
        "Table 3",
        "Table 4",
        "Table 5",
        "Table 6",
        "Table 7",
        "Burst mutations",
        "max credit is clearly better",
        "figures/figure4.png",
    ] {
        assert!(md.contains(needle), "report lacks {needle:?}");
    }
    assert!(!md.contains("NaN"), "{md}");
    // The default grid is the paper's: no table for Gomez's ESP.
    assert!(!md.contains("Gomez's ESP"), "{md}");
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    assert!(report.is_object());
    let figures: Vec<_> = std::fs::read_dir(dir.join("figures"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    // Figure 4 and one curve per configuration of the paper (gomez is not
    // one), each as SVG and PNG.
    assert_eq!(figures.len(), 2 * 9, "{figures:?}");
    for f in figures.iter().filter(|f| f.extension().unwrap() == "png") {
        assert!(std::fs::read(f).unwrap().starts_with(b"\x89PNG"), "{}", f.display());
        let name = f.file_name().unwrap().to_str().unwrap();
        assert!(md.contains(&format!("figures/{name}")), "{name} not linked");
    }
    // A partial grid says what is missing.
    std::fs::remove_dir_all(dir.join("runs/hill-climb/task3")).unwrap();
    let o = psa_esp(&["report", dir.to_str().unwrap()]);
    assert!(o.status.success());
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("PARTIAL GRID") && md.contains("hill-climb"), "{md}");
}

/// A folder's files as [`run_files`] gives them: (relative path, bytes).
type Files = Vec<(String, Vec<u8>)>;

/// Every file of every run of every variant of the sweep in `dir`, by variant.
fn sweep_files(dir: &Path) -> Vec<(String, Files)> {
    let mut variants: Vec<_> = std::fs::read_dir(dir.join("variants"))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .collect();
    variants.sort();
    variants
        .iter()
        .map(|v| (v.file_name().unwrap().to_string_lossy().into_owned(), run_files(v)))
        .collect()
}

#[test]
fn a_sweep_in_lockstep_advances_every_variant_in_one_pass_to_the_files_of_run_by_run() {
    let tmp = tempfile::tempdir().unwrap();
    let (apart, together) = (tmp.path().join("apart"), tmp.path().join("together"));
    let args = |out: &Path, lockstep: bool| -> Vec<String> {
        let mut args: Vec<String> = [
            "sweep",
            "--vary",
            "esp.stagnation=5,10",
            "--configs",
            "baseline",
            "--tasks",
            "1",
            "--seeds",
            "2",
            "--generations",
            "150",
            "--robustness-trials",
            "5",
            "--out",
            out.to_str().unwrap(),
        ]
        .map(String::from)
        .to_vec();
        if lockstep {
            args.extend(["--lockstep", "--threads", "2"].map(String::from));
        } else {
            args.extend(["--jobs", "1"].map(String::from));
        }
        args
    };
    let o = psa_esp(&args(&apart, false).iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    // In one pass every run of both variants holds a checkpoint at once
    // (variant after variant, the second would start only once the first's
    // runs had ended and dropped theirs): kill -9 the sweep then.
    let mut child = Command::new(common::binary())
        .args(args(&together, true))
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(120);
    let checkpoints = |dir: &Path| -> usize {
        let Ok(variants) = std::fs::read_dir(dir.join("variants")) else {
            return 0;
        };
        variants
            .map(|v| v.unwrap().path())
            .filter(|v| v.join("runs").exists())
            .flat_map(|v| run_file_paths(&v))
            .filter(|p| p.ends_with("checkpoint.json"))
            .count()
    };
    while checkpoints(&together) < 4 {
        assert!(
            Instant::now() < deadline,
            "not every variant's runs held a checkpoint in time"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();

    // Resumed, the sweep's files are those of the run-by-run sweep.
    let o = psa_esp(&args(&together, true).iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let files = sweep_files(&apart);
    assert_eq!(files.len(), 2);
    assert!(files
        .iter()
        .all(|(_, runs)| runs.iter().filter(|(p, _)| p.ends_with("robustness.json")).count() == 2));
    assert!(
        files == sweep_files(&together),
        "the lockstep sweep differs from the run-by-run one"
    );
}

#[test]
fn a_first_seed_grid_runs_the_seeds_of_a_larger_grid_byte_for_byte_and_extends_a_grid_at_its_end() {
    let tmp = tempfile::tempdir().unwrap();
    let (whole, part, joined) = (
        tmp.path().join("whole"),
        tmp.path().join("part"),
        tmp.path().join("joined"),
    );
    let with_first = |args: [&str; 13], first: &str| {
        let mut v = args.to_vec();
        v.splice(1..1, ["--first-seed", first]);
        v.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let run = |args: &[String]| {
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        psa_esp(&refs)
    };
    assert!(psa_esp(&tiny_baseline_grid("1", "4", &whole)).status.success());
    let o = run(&with_first(tiny_baseline_grid("1", "2", &part), "3"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Seeds 3 and 4 of the larger grid, byte for byte, under their own names.
    let part_files = results(&part);
    assert_eq!(part_files.len(), 2 * 4);
    let whole_files = results(&whole);
    for (path, bytes) in &part_files {
        assert!(path.contains("seed3") || path.contains("seed4"), "{path}");
        let same = whole_files.iter().find(|(p, _)| p == path).unwrap();
        assert!(&same.1 == bytes, "{path} differs from the larger grid's");
    }
    let grid: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(part.join("grid.json")).unwrap()).unwrap();
    assert_eq!(grid["first_seed"], 3);
    let o = psa_esp(&["report", part.to_str().unwrap()]);
    assert!(o.status.success());
    let md = std::fs::read_to_string(part.join("report.md")).unwrap();
    assert!(md.contains("| seeds | 3 to 4 per configuration and task |"), "{md}");
    // Resuming needs the same first seed: without it, refused and named.
    let o = psa_esp(&tiny_baseline_grid("1", "2", &part));
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("seeds 1 to 2") && err.contains("--first-seed 5"), "{err}");
    // A grid of seeds 1-2 extended by seeds 3-4 in one command: the files of seeds 1-4.
    assert!(psa_esp(&tiny_baseline_grid("1", "2", &joined)).status.success());
    let o = run(&with_first(tiny_baseline_grid("1", "2", &joined), "3"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(results(&joined) == whole_files);
    assert_eq!(
        std::fs::read(joined.join("grid.json")).unwrap(),
        std::fs::read(whole.join("grid.json")).unwrap()
    );
    // Seeds that overlap a grid's only in part, or would pass the largest seed, are refused.
    let o = run(&with_first(tiny_baseline_grid("1", "3", &joined), "3"));
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("clash"));
    let o = run(&with_first(
        tiny_baseline_grid("1", "2", &tmp.path().join("far")),
        &u64::MAX.to_string(),
    ));
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("largest seed"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!tmp.path().join("far").exists());
}

#[test]
fn a_sweep_runs_a_run_its_variants_share_once_and_writes_the_files_a_run_of_each_variant_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let (sweep, alone) = (tmp.path().join("sweep"), tmp.path().join("alone"));
    let config = tmp.path().join("start.toml");
    std::fs::write(&config, "[problem.tasks]\ntask2_spin = 0.5\n").unwrap();
    // Task 2's start changes task 2's runs only: task 1's are the base's.
    let sweep_args = [
        "sweep",
        "--vary",
        "problem.tasks.task2_spin=-0.75,0.5",
        "--configs",
        "baseline",
        "--tasks",
        "1,2",
        "--seeds",
        "2",
        "--generations",
        "3",
        "--robustness-trials",
        "5",
        "--out",
        sweep.to_str().unwrap(),
    ];
    let o = psa_esp(&sweep_args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("(2 of them shared with an earlier variant, run once: 2 written from it now)"),
        "{out}"
    );
    // The second variant's files are those of a grid run under its setting, byte for byte.
    let mut args = tiny_baseline_grid("1,2", "2", &alone).to_vec();
    args.extend(["--config", config.to_str().unwrap()]);
    assert!(psa_esp(&args).status.success());
    let variant = std::fs::read_dir(sweep.join("variants"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().contains("v1-"))
        .unwrap();
    let shared = results(&variant);
    assert_eq!(shared.len(), 4 * 4);
    assert!(
        shared == results(&alone),
        "the shared runs differ from runs of their own"
    );
    let champion = std::fs::read_to_string(variant.join("runs/baseline/task1/seed1/champion.json")).unwrap();
    assert!(champion.contains("\"task2_spin\": 0.5"));
    // Resumed, nothing runs again: the one shared run gone is written again from its source.
    let rewritten_once = || {
        let o = psa_esp(&sweep_args);
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(
            out.contains("1 written from it now") && out.contains("0 run now"),
            "{out}"
        );
        assert!(results(&variant) == shared);
    };
    std::fs::remove_dir_all(variant.join("runs/baseline/task1/seed2")).unwrap();
    rewritten_once();
    // A shared run left unfinished (a process killed while it flew it) is written over.
    std::fs::remove_file(variant.join("runs/baseline/task1/seed2/robustness.json")).unwrap();
    std::fs::write(variant.join("runs/baseline/task1/seed2/records.csv"), "generation\n").unwrap();
    rewritten_once();
}
