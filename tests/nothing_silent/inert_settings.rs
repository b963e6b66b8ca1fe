//! Settings that do nothing act or are refused.

use super::*;

#[test]
fn a_varied_backend_or_generation_count_is_the_variant_grids_own() {
    let spec = sweep_of(
        grid(&["baseline"], &[Task::StopRotation]),
        &["problem.backend=native,rapier"],
    )
    .unwrap();
    let backends: Vec<BackendKind> = spec
        .variants()
        .iter()
        .map(|v| spec.variant_grid(v).unwrap().backend)
        .collect();
    assert_eq!(backends, [BackendKind::Native, BackendKind::Rapier]);
    let spec = sweep_of(grid(&["baseline"], &[Task::StopRotation]), &["esp.generations=3,4"]).unwrap();
    let generations: Vec<usize> = spec
        .variants()
        .iter()
        .map(|v| spec.variant_grid(v).unwrap().generations)
        .collect();
    assert_eq!(generations, [3, 4]);
    // Through the command line: each variant's runs evolve for its own
    // number of generations.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let mut args = tiny_sweep(&out, "1", &["esp.generations=3,4"]);
    let at = args.iter().position(|a| *a == "--generations").unwrap();
    args.drain(at..at + 2);
    ok(&psa_esp(&args));
    let lines: Vec<usize> = files_named(&out, RunFiles::RECORDS)
        .iter()
        .map(|f| std::fs::read_to_string(f).unwrap().lines().count())
        .collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert_eq!(
        lines[1],
        lines[0] + 1,
        "4 generations record one more than 3: {lines:?}"
    );
    // In a grid's own settings they are refused: the grid sets them.
    let mut own = grid(&["baseline"], &[Task::StopRotation]);
    own.overrides = Some("[problem]\nbackend = \"ode\"\n".into());
    let err = format!("{:#}", own.check_new().unwrap_err());
    assert!(err.contains("problem.backend") && err.contains("--backend"), "{err}");
}

#[test]
fn a_varied_setting_that_changes_no_run_is_refused_naming_it() {
    // The input-noise configuration sets the input noise itself.
    let err = sweep_of(
        grid(&["input-noise"], &[Task::StopRotation]),
        &["problem.noise.input_sd=0.0,0.1"],
    )
    .unwrap_err();
    let err = format!("{err:#}");
    assert!(
        err.contains("problem.noise.input_sd") && err.contains("changes nothing"),
        "{err}"
    );
    // 1 and 1.0 are one value.
    let err = format!("{:#}", parse_vary("problem.tasks.task1_spin=1,1.0").unwrap_err());
    assert!(err.contains("same value"), "{err}");
    // A table and a key inside it: one would silently win.
    let err = sweep_of(
        grid(&["baseline"], &[Task::StopRotation]),
        &[
            "problem.fitness.scoring=original,evolution",
            "problem.fitness={ kind = \"original\" },{ kind = \"incremental\" }",
        ],
    )
    .unwrap_err();
    let err = format!("{err:#}");
    assert!(err.contains("problem.fitness") && err.contains("overlap"), "{err}");
    // The command line refuses them before anything is written.
    let dir = tempfile::tempdir().unwrap();
    for (vary, needles) in [
        (
            "problem.tasks.task1_spin=1,1.0",
            ["problem.tasks.task1_spin", "same value"],
        ),
        (
            "problem.noise.input_sd=0.0,0.1",
            ["problem.noise.input_sd", "changes nothing"],
        ),
    ] {
        let out = dir.path().join("sweep");
        let mut args = tiny_sweep(&out, "1", &[vary]);
        if vary.starts_with("problem.noise") {
            let at = args.iter().position(|a| *a == "baseline").unwrap();
            args[at] = "input-noise";
        }
        refused(&psa_esp(&args), &needles);
        assert!(!out.exists(), "{vary}: nothing written");
    }
}

#[test]
fn a_rescoring_setting_that_changes_no_test_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let source = copy_of_grid(dir.path());
    for (toml, key) in [
        ("[problem.noise]\ninput_sd = 0.2\n", "problem.noise.input_sd"),
        ("[problem.noise]\noutput_sd = 0.2\n", "problem.noise.output_sd"),
        ("[problem]\nrandom_init = true\n", "problem.random_init"),
        ("[problem.fitness]\nkind = \"original\"\n", "problem.fitness.kind"),
    ] {
        rescore_is_refused_as_changing_nothing(dir.path(), &source, toml, key);
    }
}

#[test]
fn a_speedup_floor_over_too_few_networks_to_batch_is_refused() {
    let o = psa_esp(&["bench", "--speedup-floor", "4", "--networks", "1"]);
    refused(&o, &["--networks 1", "nothing to batch"]);
    // The portable build flies blocks of 8: 8 networks are enough there,
    // 7 are not (the message gives the level's own width).
    let portable = [
        "bench",
        "--speedup-level",
        "portable",
        "--speedup-floor",
        "0.001",
        "--rounds",
        "1",
    ];
    let o = psa_esp(&[&portable[..], &["--networks", "7"]].concat());
    refused(&o, &["--networks 7", "blocks of 8", "portable"]);
    let o = psa_esp(&[&portable[..], &["--networks", "8"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
}
