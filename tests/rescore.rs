//! `psa-esp rescore` end to end: a grid's champions tested again under
//! another scoring fitness give what a grid scored that way from the start
//! gives, byte for byte, without re-evolving; the report reads them;
//! careless use is refused.

mod common;

use std::path::Path;

use common::{psa_esp, run_file_paths};

/// Baseline and max credit on tasks 1 and 2, two seeds, 15 generations,
/// `--config` laid over it where given.
fn replicate(out: &Path, config: Option<&Path>) {
    let mut args = vec![
        "replicate",
        "--configs",
        "baseline,max-credit",
        "--tasks",
        "1,2",
        "--seeds",
        "2",
        "--generations",
        "15",
        "--robustness-trials",
        "8",
        "--threads",
        "2",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(c) = config {
        args.extend(["--config", c.to_str().unwrap()]);
    }
    let o = psa_esp(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn files_named(dir: &Path, name: &str) -> Vec<(String, Vec<u8>)> {
    run_file_paths(dir)
        .into_iter()
        .filter(|p| p.file_name().unwrap() == name)
        .map(|p| {
            (
                p.strip_prefix(dir).unwrap().display().to_string(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect()
}

#[test]
fn rescoring_gives_the_robustness_results_of_a_grid_scored_that_way_from_the_start() {
    let tmp = tempfile::tempdir().unwrap();
    let (original, evolution) = (tmp.path().join("original.toml"), tmp.path().join("evolution.toml"));
    std::fs::write(&original, "[problem.fitness]\nscoring = \"original\"\n").unwrap();
    std::fs::write(&evolution, "[problem.fitness]\nscoring = \"evolution\"\n").unwrap();
    let (grid, scored, rescored) = (
        tmp.path().join("grid"),
        tmp.path().join("scored"),
        tmp.path().join("rescored"),
    );
    replicate(&grid, Some(&evolution));
    replicate(&scored, Some(&original));
    let rescore = || {
        psa_esp(&[
            "rescore",
            grid.to_str().unwrap(),
            "--config",
            original.to_str().unwrap(),
            "--out",
            rescored.to_str().unwrap(),
        ])
    };
    let out = rescore();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("8 re-scored now"));
    // The evolution is the same in all three (the champion and
    // configuration files of the grid scored from the start record its
    // scoring); the tests of the re-scored grid are those of that grid.
    for name in ["records.csv", "champion.json", "config.toml"] {
        assert!(
            files_named(&grid, name) == files_named(&rescored, name),
            "{name} copied"
        );
    }
    assert!(files_named(&grid, "records.csv") == files_named(&scored, "records.csv"));
    let tests = files_named(&rescored, "robustness.json");
    assert_eq!(tests.len(), 8);
    assert!(tests == files_named(&scored, "robustness.json"));
    assert!(tests != files_named(&grid, "robustness.json"));
    assert!(String::from_utf8_lossy(&tests[0].1).contains("\"rescored\": true"));

    // Run again: nothing left to do, nothing changed.
    let again = rescore();
    assert!(String::from_utf8_lossy(&again.stdout).contains("8 already re-scored, 0 re-scored now"));
    assert!(files_named(&rescored, "robustness.json") == tests);

    // The report's Table 1 is the clean test on the original fitness, and it
    // names the readings and the rescoring.
    let report = psa_esp(&["report", rescored.to_str().unwrap()]);
    assert!(report.status.success());
    let md = String::from_utf8_lossy(&report.stdout);
    assert!(md.contains("| re-scored | champions tested again by `psa-esp rescore` with `[problem.fitness]` `scoring = \"original\"` |"), "{md}");
    assert!(
        md.contains("task 1: evolved on the incremental fitness over 500 steps, scored on the original"),
        "{md}"
    );
    let baseline_task1: Vec<f64> = (1..=2)
        .map(|seed| {
            let text =
                std::fs::read_to_string(rescored.join(format!("runs/baseline/task1/seed{seed}/robustness.json")))
                    .unwrap();
            serde_json::from_str::<serde_json::Value>(&text).unwrap()["clean"]
                .as_f64()
                .unwrap()
        })
        .collect();
    let mean = (baseline_task1[0] + baseline_task1[1]) / 2.0;
    assert!(
        md.contains(&format!("| 1 | 2 | {mean:.1} [")),
        "Table 1 task 1 should be {mean:.1}:\n{md}"
    );
}

#[test]
fn rescoring_refuses_a_change_of_the_search_its_own_folder_and_a_folder_that_is_no_grid() {
    let tmp = tempfile::tempdir().unwrap();
    let grid = tmp.path().join("grid");
    let o = psa_esp(
        &common::tiny_grid("replicate", &grid)
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(o.status.success());
    let search = tmp.path().join("search.toml");
    std::fs::write(&search, "[esp]\nstagnation = 10\n").unwrap();
    let scoring = tmp.path().join("scoring.toml");
    std::fs::write(&scoring, "[problem.fitness]\nscoring = \"original\"\n").unwrap();
    let bad = tmp.path().join("bad.toml");
    std::fs::write(&bad, "[problem.fitness]\nscoring = \"best\"\n").unwrap();
    let out = tmp.path().join("out");
    for (args, expected) in [
        (
            vec![
                "rescore",
                grid.to_str().unwrap(),
                "--config",
                search.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            "change the search",
        ),
        (
            vec![
                "rescore",
                grid.to_str().unwrap(),
                "--config",
                scoring.to_str().unwrap(),
                "--out",
                grid.to_str().unwrap(),
            ],
            "is the grid being re-scored",
        ),
        (
            vec![
                "rescore",
                tmp.path().to_str().unwrap(),
                "--config",
                scoring.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            "grid.json",
        ),
        (
            vec![
                "rescore",
                grid.to_str().unwrap(),
                "--config",
                bad.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            "scoring",
        ),
    ] {
        let o = psa_esp(&args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    assert!(!out.join("runs").exists(), "nothing written for refused re-scorings");
}
