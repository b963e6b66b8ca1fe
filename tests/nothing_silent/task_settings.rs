//! A run is judged on the settings its own task reads (`Task::reads_setting`), in every command.

use super::*;

/// A finished tiny grid of task 2 alone in `dir/name`.
fn task_2_grid(dir: &Path, name: &str) -> PathBuf {
    let out = dir.join(name);
    let mut args = tiny_args(&out);
    let at = args.iter().position(|a| *a == "--tasks").unwrap();
    args[at + 1] = "2";
    ok(&psa_esp(&args));
    out
}

/// Sets the `overrides` of the grid in `grid` (its grid.json) to `toml`.
fn set_grid_overrides(grid: &Path, toml: &str) {
    let path = grid.join("grid.json");
    let mut spec: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    spec["overrides"] = toml.into();
    std::fs::write(&path, serde_json::to_string_pretty(&spec).unwrap()).unwrap();
}

#[test]
fn a_rescoring_setting_no_task_of_the_grid_reads_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let source = copy_of_grid(dir.path());
    for (toml, key) in [
        ("[problem.tasks]\ntask2_spin = 1.0\n", "problem.tasks.task2_spin"),
        (
            "[problem.tasks]\ntask2_velocity = [0.1, 0.0]\n",
            "problem.tasks.task2_velocity",
        ),
        ("[problem.task2]\nsteps = 100\n", "problem.task2.steps"),
    ] {
        rescore_is_refused_as_changing_nothing(dir.path(), &source, toml, key);
    }
}

#[test]
fn a_sweep_of_a_setting_no_task_of_the_grid_reads_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    for (vary, key) in [
        ("problem.tasks.task2_spin=1.0,-1.5", "problem.tasks.task2_spin"),
        ("problem.task2.steps=100,200", "problem.task2.steps"),
    ] {
        let out = dir.path().join("sweep");
        refused(&psa_esp(&tiny_sweep(&out, "1", &[vary])), &[key, "changes nothing"]);
        assert!(!out.exists(), "{vary}: nothing written");
    }
}

#[test]
fn a_sweep_one_at_a_time_or_of_the_other_algorithms_settings_is_refused_when_its_variants_run_the_same_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let one_at_a_time = |vary: &'static [&'static str]| {
        let mut args = tiny_sweep(&out, "1", vary);
        args.extend(["--mode", "one-at-a-time"]);
        args
    };
    // Task 1 reads no task-2 start: each value runs the base's runs.
    for vary in [
        &["problem.tasks.task2_spin=1.0,-1.5"][..],
        &["problem.tasks.task2_spin=1.0"],
    ] {
        refused(
            &psa_esp(&one_at_a_time(vary)),
            &["problem.tasks.task2_spin", "changes nothing"],
        );
        assert!(!out.exists(), "{vary:?}: nothing written");
    }
    // ESP reads no hill-climber setting, the hill-climber no ESP one.
    for (vary, config, key) in [
        ("hill_climb.alpha=0.3,1.0", "baseline", "hill_climb.alpha"),
        ("esp.stagnation=20,30", "hill-climb", "esp.stagnation"),
    ] {
        let mut args = tiny_sweep(&out, "1", &[vary]);
        let at = args.iter().position(|a| *a == "--configs").unwrap();
        args[at + 1] = config;
        refused(&psa_esp(&args), &[key, "changes nothing"]);
        assert!(!out.exists(), "{vary}: nothing written");
    }
    // The base's own value, named, is a row of its own; a value that
    // changes a run is not refused.
    let ok = psa_esp(&one_at_a_time(&["problem.tasks.task1_spin=1.0,2.0"]));
    assert!(ok.status.success(), "{}", stderr(&ok));
}

#[test]
fn a_task_2_run_of_another_start_whose_build_cannot_be_placed_is_not_counted() {
    let dir = tempfile::tempdir().unwrap();
    let grid = task_2_grid(dir.path(), "grid");
    let folder = run_dir(
        &grid,
        &RunKey {
            config: "baseline".parse().unwrap(),
            task: Task::Turn,
            seed: 1,
        },
    );
    let config = folder.join("config.toml");
    let mut table: toml::Table = toml::from_str(&std::fs::read_to_string(&config).unwrap()).unwrap();
    table["problem"]["tasks"]["task2_spin"] = toml::Value::Float(1.0);
    std::fs::write(&config, toml::to_string(&table).unwrap()).unwrap();
    let path = folder.join("run.json");
    let mut run: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let build = run["build"].as_object_mut().unwrap();
    build.remove("defaults");
    build.insert("git_commit".into(), "0123456789abcdef0123456789abcdef01234567".into());
    std::fs::write(&path, serde_json::to_string_pretty(&run).unwrap()).unwrap();
    let report = report_json(&grid);
    assert_eq!(report["runs_counted"], 0, "{report}");
    let problems = report["problems"].to_string();
    assert!(problems.contains("problem.tasks.task2_spin"), "{problems}");
}

#[test]
fn a_task_1_run_is_judged_without_the_problem_task2_table() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let toml = "[problem.task2]\nsteps = 100\n";
    set_grid_overrides(&grid, toml);
    let report = report_json(&grid);
    assert_eq!(report["runs_counted"], 1, "{report}");
    assert_eq!(report["problems"], serde_json::json!([]), "{report}");
    // Resumed with that table: the task-1 run is finished, not refused.
    let config = dir.path().join("task2.toml");
    std::fs::write(&config, toml).unwrap();
    let mut args = tiny_args(&grid);
    args.extend(["--config", config.to_str().unwrap()]);
    ok(&psa_esp(&args));
}

#[test]
fn report_md_lists_every_setting_a_grid_changes_from_the_defaults_that_its_runs_read() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    ok(&psa_esp(&["report", grid.to_str().unwrap()]));
    let plain = std::fs::read_to_string(grid.join("report.md")).unwrap();
    assert!(!plain.contains("changed from the defaults"), "{plain}");
    let readings = plain.lines().find(|l| l.starts_with("| readings |")).unwrap();
    assert!(
        readings.contains("task 1:") && !readings.contains("task 2") && !readings.contains("task 3"),
        "a task-1 grid's readings name task 1 only: {readings}"
    );
    // Settings the grid's task-1 run does not read: its runs are the
    // default grid's, and the label says so by naming nothing.
    set_grid_overrides(
        &grid,
        "[problem.tasks]\ntask2_spin = 1.0\ntask3_speed = 0.3\n[hill_climb]\nalpha = 1.0\n",
    );
    ok(&psa_esp(&["report", grid.to_str().unwrap()]));
    let md = std::fs::read_to_string(grid.join("report.md")).unwrap();
    assert!(!md.contains("changed from the defaults"), "{md}");
    // A setting task 1 reads is named (its run, flown without it, is then not counted).
    set_grid_overrides(&grid, "[problem.tasks]\ntask1_spin = 2.0\ntask2_spin = 1.0\n");
    let o = psa_esp(&["report", grid.to_str().unwrap()]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let md = std::fs::read_to_string(grid.join("report.md")).unwrap();
    assert!(md.contains("`problem.tasks.task1_spin = 2.0` (default 1.0)"), "{md}");
    assert!(!md.contains("task2_spin"), "{md}");
}

#[test]
fn replicate_refuses_a_configuration_setting_no_task_of_its_grid_reads() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("task2.toml");
    for (toml, key) in [
        ("[problem.tasks]\ntask2_spin = 1.0\n", "problem.tasks.task2_spin"),
        ("[problem.task2]\nsteps = 100\n", "problem.task2.steps"),
    ] {
        std::fs::write(&config, toml).unwrap();
        let out = dir.path().join("grid");
        let mut args = tiny_args(&out);
        args.extend(["--config", Box::leak(config.display().to_string().into_boxed_str())]);
        refused(&psa_esp(&args), &[key, "changes nothing", "no task of this grid (1)"]);
        assert!(!out.exists(), "{key}: nothing written");
    }
    // The setting a task of the grid reads is taken, as is the default's value.
    std::fs::write(&config, "[problem.tasks]\ntask1_spin = 2.0\ntask2_spin = -0.75\n").unwrap();
    let mut args = tiny_args(&dir.path().join("ok"));
    args.extend(["--config", Box::leak(config.display().to_string().into_boxed_str())]);
    ok(&psa_esp(&args));
}
