//! The ODE check of a grid on `native`: every champion flown again on
//! `ode`, its fitness and robustness results recorded in `run.json` and
//! required bit-identical; on by default for the paper preset on `native`.

mod common;

use std::path::Path;

use common::{psa_esp, run_file_paths};

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Every `run.json` under `dir`.
fn summaries(dir: &Path) -> Vec<serde_json::Value> {
    run_file_paths(dir)
        .iter()
        .filter(|p| p.ends_with("run.json"))
        .map(|p| json(p))
        .collect()
}

/// The check of one run: identical, with a finite value for each quantity on both backends.
fn assert_identical_check(summary: &serde_json::Value, task: u64) {
    let check = &summary["ode_check"];
    assert_eq!(check["identical"], true, "{check}");
    let mut names = vec!["clean", "input_noise_mean", "input_noise_sd"];
    if task != 2 {
        names.extend(["random_init_mean", "random_init_sd"]);
    }
    let robustness = check["robustness"].as_object().unwrap();
    assert_eq!(robustness.keys().collect::<Vec<_>>(), names, "{check}");
    for c in robustness.values().chain([&check["fitness"]]) {
        let (native, ode) = (c["native"].as_f64().unwrap(), c["ode"].as_f64().unwrap());
        assert_eq!(native.to_bits(), ode.to_bits(), "{check}");
    }
}

#[test]
fn a_grid_with_the_ode_check_records_identical_values_for_every_champion() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("grid");
    let o = psa_esp(&[
        "replicate",
        "--configs",
        "baseline,input-noise,random-init",
        "--tasks",
        "1,2",
        "--seeds",
        "1",
        "--generations",
        "4",
        "--robustness-trials",
        "6",
        "--backend",
        "native",
        "--ode-check",
        "--jobs",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(json(&out.join("grid.json"))["ode_check"], true);
    let runs = summaries(&out);
    // random-init has no task 2.
    assert_eq!(runs.len(), 5);
    for summary in &runs {
        let task = summary["task"].as_u64().unwrap();
        assert_identical_check(summary, task);
        // Without noise or random starts the re-flown fitness is the
        // champion's own.
        if summary["label"] == "baseline" {
            let fitness = summary["ode_check"]["fitness"]["ode"].as_f64().unwrap();
            assert_eq!(
                fitness.to_bits(),
                summary["champion_fitness"].as_f64().unwrap().to_bits()
            );
        }
    }
    // The robustness file holds the native results the check compared.
    let folder = out.join("runs/baseline/task1/seed1");
    let robustness = json(&folder.join("robustness.json"));
    let summary = json(&folder.join("run.json"));
    assert_eq!(
        robustness["input_noise"]["mean"],
        summary["ode_check"]["robustness"]["input_noise_mean"]["native"]
    );
}

#[test]
fn the_paper_preset_checks_on_ode_by_default_and_the_check_needs_native() {
    let tmp = tempfile::tempdir().unwrap();
    let tiny = [
        "--configs",
        "baseline",
        "--tasks",
        "2",
        "--seeds",
        "1",
        "--generations",
        "2",
    ];
    let run = |name: &str, extra: &[&str]| {
        let out = tmp.path().join(name);
        let mut args = vec!["replicate", "--robustness-trials", "3", "--out", out.to_str().unwrap()];
        args.extend(tiny);
        args.extend(extra);
        (psa_esp(&args), out)
    };
    let (o, out) = run("paper", &["--preset", "paper", "--backend", "native"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(json(&out.join("grid.json"))["ode_check"], true);
    assert_identical_check(&summaries(&out)[0], 2);

    let (o, out) = run(
        "unchecked",
        &["--preset", "paper", "--backend", "native", "--no-ode-check"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(json(&out.join("grid.json"))["ode_check"], false);
    assert!(summaries(&out)[0].get("ode_check").is_none());

    // The quick preset does not check unless asked.
    let (o, out) = run("quick", &["--backend", "native"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(json(&out.join("grid.json"))["ode_check"], false);

    // A grid on ode itself (or rapier) has nothing to check against.
    let (o, _) = run("on-ode", &["--backend", "ode", "--ode-check"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("ODE check") && err.contains("runs on ode"), "{err}");
}

/// The mean fitness `replay` reports for `network` from the random start
/// of seed 62 on `backend`, with `extra` arguments.
fn random_start_fitness(network: &Path, backend: &str, extra: &[&str]) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let mut args = vec!["--random-init", "--seed", "62"];
    args.extend(extra);
    common::replayed_fitness(network, backend, &dir.path().join("replay"), &args)
}

#[test]
fn a_champion_that_parted_the_backends_on_a_random_start_flies_alike_on_both() {
    // The paper grid's hill-climb task-1 seed-25 champion: from this start
    // its trajectories parted when `native` kept the start quaternion
    // unnormalised and ODE normalised it (1.5 % against 1.1 %), which
    // failed that run's ODE check. Its file was written (build 20489d6)
    // before the start quaternion was a setting.
    let network = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/networks/parts-backends-on-random-starts.json");
    let dir = tempfile::tempdir().unwrap();
    let normalised = dir.path().join("normalised.toml");
    std::fs::write(&normalised, "[problem.physics]\nstart_quaternion = \"normalised\"\n").unwrap();
    let today = ["--config", normalised.to_str().unwrap()];
    let ode = random_start_fitness(&network, "ode", &today);
    assert_eq!(
        random_start_fitness(&network, "native", &today).to_bits(),
        ode.to_bits()
    );
    // On the model its file records (its build's raw start, from the table
    // of defaults in sim/src/psa/settings/defaults.rs) it parts as it did; ODE
    // normalises either way.
    let earlier = random_start_fitness(&network, "native", &[]);
    assert_ne!(
        earlier, ode,
        "the raw start quaternion no longer parts the backends here"
    );
    assert_eq!(random_start_fitness(&network, "ode", &[]), ode);
}
