//! A bad network file or run file is named: its key, or the file.

use super::*;

#[test]
fn a_bad_value_in_a_network_file_is_named_by_its_key() {
    let dir = tempfile::tempdir().unwrap();
    for (section, key, value) in [
        ("sensors", "heading_wrap", serde_json::json!("both")),
        ("sensors", "heading_input", serde_json::json!("relative")),
        ("fitness", "scoring", serde_json::json!("best")),
        ("fitness", "state", serde_json::json!("imagined")),
        ("physics", "start_quaternion", serde_json::json!(7)),
    ] {
        let mut json = network_json(&PsaSettings::default());
        json["problem"][section][key] = value;
        let err = load_json(dir.path(), &json).unwrap_err();
        assert!(err.contains(&format!("problem.{section}.{key}")), "{err}");
    }
    let mut json = network_json(&PsaSettings::default());
    json["problem"]["exponential"] = "slow".into();
    let err = load_json(dir.path(), &json).unwrap_err();
    assert!(err.contains("problem.exponential"), "{err}");
    // Replayed from the command line, the error names the key too.
    let mut json = network_json(&PsaSettings::default());
    json["problem"]["sensors"]["heading_wrap"] = "both".into();
    let file = dir.path().join("bad.json");
    std::fs::write(&file, json.to_string()).unwrap();
    let o = psa_esp(&["replay", file.to_str().unwrap(), "--backend", "native"]);
    assert!(!o.status.success());
    let text = stderr(&o);
    assert!(
        text.contains("problem.sensors.heading_wrap") && !text.contains("panicked"),
        "{text}"
    );
}

#[test]
fn a_run_json_that_does_not_parse_is_named_not_config_toml() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    // A run of an earlier build: its config.toml needs run.json's build.
    age_run(&grid, "a70d696");
    let path = run_folder(&grid).join("run.json");
    let mut run: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    run["champion_fitness"] = "HUGE".into();
    let text = serde_json::to_string_pretty(&run).unwrap().replace("\"HUGE\"", "1e999");
    std::fs::write(&path, text).unwrap();
    let report = report_json(&grid);
    assert_eq!(report["runs_counted"], 0, "{report}");
    let problems = report["problems"].to_string();
    assert!(
        problems.contains("run.json: damaged") && !problems.contains("config.toml"),
        "{problems}"
    );
    // Resuming names run.json, not config.toml.
    let text = refused(&psa_esp(&tiny_args(&grid)), &["run.json", "damaged"]);
    assert!(!text.contains("config.toml") && !text.contains("not written"), "{text}");
}

#[test]
fn a_network_file_without_provenance_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let champion = run_folder(&grid).join("champion.json");
    let mut json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&champion).unwrap()).unwrap();
    json.as_object_mut().unwrap().remove("provenance");
    json["problem"]["sensors"]
        .as_object_mut()
        .unwrap()
        .remove("heading_wrap");
    let file = dir.path().join("bare.json");
    std::fs::write(&file, json.to_string()).unwrap();
    refused(
        &psa_esp(&["replay", file.to_str().unwrap()]),
        &["heading_wrap", "no \"provenance\""],
    );
}
