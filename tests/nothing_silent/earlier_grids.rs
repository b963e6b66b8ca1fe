//! Grids of earlier builds stay readable.

use super::*;

#[test]
fn a_report_says_above_its_tables_when_its_runs_flew_different_models() {
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("grid");
    let mut args = tiny_args(&grid);
    let at = args.iter().position(|a| *a == "--seeds").unwrap();
    args[at + 1] = "2";
    ok(&psa_esp(&args));
    // Seed 2 as a build before the positive heading wrap wrote it: counted
    // (this grid under its build's defaults), but another model.
    age_run_folder(&grid.join("runs/baseline/task1/seed2"), "a70d696");
    let o = psa_esp(&["report", grid.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("mixed models"), "{}", stderr(&o));
    let md = std::fs::read_to_string(grid.join("report.md")).unwrap();
    let banner = md.lines().find(|l| l.starts_with("**MIXED MODELS")).expect("a banner");
    assert!(
        banner.contains("baseline task 1: `problem.noise.on_bias` = false in 1 (seeds 2), true in 1 (seeds 1)"),
        "{banner}"
    );
    assert!(md.find("**MIXED MODELS").unwrap() < md.find("## Grid").unwrap());
    // One model: no banner.
    std::fs::remove_dir_all(grid.join("runs/baseline/task1/seed2")).unwrap();
    ok(&psa_esp(&args));
    let o = psa_esp(&["report", grid.to_str().unwrap()]);
    assert!(!stderr(&o).contains("mixed models"));
}

#[test]
fn a_grid_of_an_earlier_build_is_reported_and_resuming_it_names_the_setting_and_the_build() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    age_run(&grid, "a70d696");
    let report = psa_esp(&["report", grid.to_str().unwrap(), "--format", "json"]);
    ok(&report);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(grid.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["runs_counted"], 1, "{}", stderr(&report));
    let readings = json["readings"].to_string();
    assert!(
        readings.contains("(-pi, pi]"),
        "the run's own heading range: {readings}"
    );
    // Resuming with this build's defaults: refused, naming the settings
    // (one its build did not have yet, read from the table) and the build.
    refused(
        &psa_esp(&tiny_args(&grid)),
        &[
            "esp.stagnation = 40 there",
            "problem.noise.on_bias = false there",
            &parent_of("a70d696"),
        ],
    );
    // Re-scoring reads it too, under its own model.
    let config = dir.path().join("rescore.toml");
    std::fs::write(&config, "[problem.fitness]\nscoring = \"incremental\"\n").unwrap();
    let out = dir.path().join("rescored");
    ok(&psa_esp(&[
        "rescore",
        grid.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    ok(&psa_esp(&["report", out.to_str().unwrap()]));
}
