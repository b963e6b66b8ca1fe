//! A run is counted once, and a finished grid holds only its documented files.

use super::*;

// One run counted once.

#[test]
fn a_configuration_or_task_listed_twice_is_refused_and_an_old_grid_counts_each_run_once() {
    let dir = tempfile::tempdir().unwrap();
    for (flag, list, needle) in [
        (
            "--configs",
            "baseline,baseline",
            "configuration baseline is listed twice",
        ),
        ("--tasks", "1,1", "task 1 is listed twice"),
    ] {
        let out = dir.path().join(flag.trim_start_matches('-'));
        let mut args = tiny_args(&out);
        let at = args.iter().position(|a| *a == flag).unwrap();
        args[at + 1] = list;
        refused(&psa_esp(&args), &[needle]);
    }
    // A grid.json that lists a configuration twice (an earlier build wrote them).
    let grid = copy_of_grid(dir.path());
    let path = grid.join("grid.json");
    let mut spec: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    spec["configs"] = serde_json::json!(["baseline", "baseline"]);
    spec["tasks"] = serde_json::json!([1, 1]);
    std::fs::write(&path, spec.to_string()).unwrap();
    let loaded = GridSpec::load(&grid).unwrap();
    assert_eq!(loaded.runs().len(), 1);
    ok(&psa_esp(&["report", grid.to_str().unwrap(), "--format", "json"]));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(grid.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["runs_counted"], 1);
    assert_eq!(report["runs_expected"], 1);
}

// A finished grid holds only its documented files.

#[test]
fn what_killed_processes_left_is_cleared_when_the_grid_is_resumed_or_reported() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let folder = run_folder(&grid);
    let expected = names_in(&folder);
    let host = psa_sim::provenance::host_name();
    let dead = dead_pid();
    // A killed lockstep grid's claim on a finished run.
    let claim = serde_json::json!({
        "host": host,
        "pid": dead,
        "started": "2026-11-27T00:00:00Z",
        "started_unix": 1_700_000_000u64,
    });
    std::fs::write(folder.join("claim.json"), claim.to_string()).unwrap();
    // A checkpoint a lockstep process left.
    std::fs::write(folder.join("checkpoint.json"), "{}").unwrap();
    // Temporary files of killed processes, and one of a live process.
    std::fs::write(folder.join(format!(".run.json.tmp-{host}-{dead}-0")), "x").unwrap();
    std::fs::write(grid.join(format!(".report.md.tmp-{host}-{dead}-1")), "x").unwrap();
    let live = format!(".grid.json.tmp-{host}-{}-2", std::process::id());
    std::fs::write(grid.join(&live), "x").unwrap();
    ok(&psa_esp(&tiny_args(&grid)));
    assert_eq!(names_in(&folder), expected);
    assert!(grid.join(&live).exists(), "a live process's file is left");
    std::fs::write(grid.join(format!(".report.md.tmp-{host}-{dead}-3")), "x").unwrap();
    std::fs::create_dir_all(grid.join("figures")).unwrap();
    std::fs::write(
        grid.join("figures").join(format!(".f.png.tmp-{host}-{dead}-4.png")),
        "x",
    )
    .unwrap();
    ok(&psa_esp(&["report", grid.to_str().unwrap()]));
    let leftovers: Vec<String> = names_in(&grid)
        .into_iter()
        .chain(names_in(&grid.join("figures")))
        .filter(|n| n.contains(&format!("-{dead}-")))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn a_run_resumed_without_lockstep_leaves_no_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let folder = run_folder(&grid);
    let expected = names_in(&folder);
    std::fs::remove_file(folder.join("robustness.json")).unwrap();
    // A saved run that reads (of another search: another seed), as a
    // lockstep process leaves: the ordinary executor runs the run from its
    // start and removes it.
    let saved: esp_neuroevolution::AnyRun = esp_neuroevolution::Esp::new(psa_experiment::paper_esp_settings(), 99)
        .unwrap()
        .start(7, 4)
        .unwrap()
        .into();
    std::fs::write(folder.join("checkpoint.json"), serde_json::to_string(&saved).unwrap()).unwrap();
    ok(&psa_esp(&tiny_args(&grid)));
    assert_eq!(names_in(&folder), expected);
}
