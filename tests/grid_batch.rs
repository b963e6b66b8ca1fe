//! The grid as a batch job: shards, several processes on one folder,
//! progress lines on a pipe, and runs.csv with exact seeds.

mod common;

use std::collections::BTreeSet;
use std::process::{Command, Stdio};

use common::{assert_same_runs, finished_lines, psa_esp, tiny_grid};
use psa_experiment::grid::runner::run_seed;
use psa_experiment::grid::GridSpec;

fn args(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// The binary run with `a` and `--shard shard`.
fn run_shard(mut a: Vec<String>, shard: &str) -> std::process::Output {
    a.extend(["--shard".into(), shard.into()]);
    psa_esp(&args(&a))
}

/// The binary run with `a`, which must succeed.
fn succeed(a: &[&str]) -> std::process::Output {
    let o = psa_esp(a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// A grid of 9 runs: baseline, max-credit and hill-climb on tasks 1-3, one seed.
fn nine_runs(out: &std::path::Path) -> Vec<String> {
    let mut a = tiny_grid("replicate", out);
    let configs = a.iter().position(|x| x == "--configs").unwrap();
    a[configs + 1] = "baseline,max-credit,hill-climb".into();
    a
}

#[test]
fn shards_together_give_the_single_process_grid() {
    let tmp = tempfile::tempdir().unwrap();
    let (single, sharded) = (tmp.path().join("single"), tmp.path().join("sharded"));
    succeed(&args(&nine_runs(&single)));

    let mut ran = Vec::new();
    for shard in ["2/3", "0/3", "1/3"] {
        let o = run_shard(nine_runs(&sharded), shard);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(stdout.contains(&format!("shard {shard}): 3 runs")), "{stdout}");
        let lines = finished_lines(&o.stderr);
        assert_eq!(lines.len(), 3, "{}", String::from_utf8_lossy(&o.stderr));
        // Round-robin over the run order: shard 1 of 3 takes runs 1, 4, 7.
        if shard == "1/3" {
            let order = GridSpec::load(&sharded).unwrap().runs();
            let expected: Vec<String> = [1, 4, 7]
                .iter()
                .map(|&i| format!("{} task {} seed {}", order[i].config, order[i].task, order[i].seed))
                .collect();
            assert_eq!(lines, expected);
        }
        ran.extend(lines);
    }
    assert_eq!(ran.iter().collect::<BTreeSet<_>>().len(), 9, "{ran:?}");
    assert_same_runs(&single, &sharded);

    // The report counts every shard's runs.
    let o = succeed(&["report", sharded.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("9 of 9 runs counted"));

    // A shard of a finished grid has nothing left to do.
    let o = run_shard(nine_runs(&sharded), "1/3");
    assert!(String::from_utf8_lossy(&o.stdout).contains("3 runs, 3 already finished, 0 run now"));
}

/// A sweep of two variants (`esp.stagnation` 3 and 5) of baseline on tasks
/// 1 and 2, one seed: 4 runs.
fn two_variant_sweep(out: &std::path::Path) -> Vec<String> {
    let mut a = tiny_grid("sweep", out);
    let tasks = a.iter().position(|x| x == "--tasks").unwrap();
    a[tasks + 1] = "1,2".into();
    a.extend(["--vary".into(), "esp.stagnation=3,5".into()]);
    a
}

#[test]
fn a_sharded_sweep_gives_the_single_process_sweep_and_one_runs_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let (single, sharded) = (tmp.path().join("single"), tmp.path().join("sharded"));
    succeed(&args(&two_variant_sweep(&single)));

    let mut ran = Vec::new();
    for shard in ["1/2", "0/2"] {
        let o = run_shard(two_variant_sweep(&sharded), shard);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        // The shard splits the sweep's whole run order: 2 of its 4 runs each.
        let lines = finished_lines(&o.stderr);
        assert_eq!(lines.len(), 2, "{}", String::from_utf8_lossy(&o.stderr));
        ran.extend(lines.into_iter().map(|l| format!("{shard} {l}")));
    }
    let mut variants: Vec<_> = std::fs::read_dir(single.join("variants"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    variants.sort();
    assert_eq!(variants.len(), 2, "{variants:?}");
    for variant in &variants {
        assert_same_runs(
            &single.join("variants").join(variant),
            &sharded.join("variants").join(variant),
        );
    }

    // The sweep's report writes one runs.csv over both variants, with the
    // varied setting's value in a column of its own.
    succeed(&["report", sharded.to_str().unwrap()]);
    let csv = std::fs::read_to_string(sharded.join("runs.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .starts_with("variant,esp.stagnation,configuration,task,seed,run_seed,"),
        "{csv}"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let cells: Vec<(&str, &str, &str)> = rows.iter().map(|r| (r[0], r[1], r[3])).collect();
    let (v0, v1) = (variants[0].to_str().unwrap(), variants[1].to_str().unwrap());
    assert_eq!(
        cells,
        [(v0, "3", "1"), (v0, "3", "2"), (v1, "5", "1"), (v1, "5", "2")],
        "{csv}"
    );
}

#[test]
fn a_bad_shard_is_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    for (shard, says) in [("3/3", "below the count"), ("1", "INDEX/COUNT"), ("0/0", "[1,")] {
        let o = run_shard(tiny_grid("replicate", &tmp.path().join("g")), shard);
        assert_eq!(o.status.code(), Some(2), "{shard}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("--shard") && err.contains(says), "{shard}: {err}");
    }
    assert!(!tmp.path().join("g").exists(), "nothing written");
}

#[test]
fn three_processes_on_one_folder_run_every_run_once() {
    let tmp = tempfile::tempdir().unwrap();
    let (single, shared) = (tmp.path().join("single"), tmp.path().join("shared"));
    succeed(&args(&nine_runs(&single)));

    let children: Vec<_> = (0..3)
        .map(|_| {
            Command::new(env!("CARGO_BIN_EXE_psa-esp"))
                .args(nine_runs(&shared))
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut ran = Vec::new();
    for child in children {
        let o = child.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        ran.extend(finished_lines(&o.stderr));
    }
    ran.sort();
    let distinct: BTreeSet<_> = ran.iter().collect();
    assert_eq!((ran.len(), distinct.len()), (9, 9), "every run exactly once: {ran:?}");
    assert_same_runs(&single, &shared);
}

#[test]
fn a_piped_replicate_prints_a_line_per_finished_run() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("grid");
    let o = psa_esp(&args(&tiny_grid("replicate", &dir)));
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("finished ")).collect();
    assert_eq!(lines.len(), 3, "{err}");
    for (i, line) in lines.iter().enumerate() {
        assert!(line.contains("champion") && line.contains(" %"), "{line}");
        assert!(line.contains(&format!("; {}/3 runs done, ETA ", i + 1)), "{line}");
    }
    assert!(
        !err.contains('\r') && !err.contains('\x1b'),
        "no bar drawn on a pipe: {err:?}"
    );

    // --quiet: nothing on standard error.
    let mut a = tiny_grid("replicate", &tmp.path().join("quiet"));
    a.push("--quiet".into());
    let o = psa_esp(&args(&a));
    assert!(o.status.success());
    assert_eq!(String::from_utf8_lossy(&o.stderr), "");
}

#[test]
fn runs_csv_and_the_json_files_keep_every_seed_exact() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("grid");
    let o = psa_esp(&args(&tiny_grid("replicate", &dir)));
    assert!(o.status.success());
    succeed(&["report", dir.to_str().unwrap()]);

    let csv = std::fs::read_to_string(dir.join("runs.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3);
    let spec = GridSpec::load(&dir).unwrap();
    let mut above_2_53 = 0;
    for (row, key) in rows.iter().zip(spec.runs()) {
        let seed = run_seed(&key);
        above_2_53 += usize::from(seed > 1 << 53);
        assert_eq!(row[col("configuration")], "baseline");
        assert_eq!(row[col("task")], key.task.to_string());
        assert_eq!(row[col("run_seed")], seed.to_string());
        assert_eq!(row[col("backend")], "native");
        let folder = psa_experiment::grid::run_dir(&dir, &key);
        let summary: serde_json::Value =
            serde_json::from_slice(&std::fs::read(folder.join("run.json")).unwrap()).unwrap();
        assert_eq!(summary["seed"], serde_json::Value::String(seed.to_string()));
        // The same number exactly (the CSV may write 4.0 as "4").
        let fitness: f64 = row[col("champion_fitness")].parse().unwrap();
        assert_eq!(
            Some(fitness.to_bits()),
            summary["champion_fitness"].as_f64().map(f64::to_bits)
        );
        assert_eq!(row[col("evaluations")], summary["evaluations"].to_string());
        let champion: serde_json::Value =
            serde_json::from_slice(&std::fs::read(folder.join("champion.json")).unwrap()).unwrap();
        assert_eq!(
            champion["provenance"]["seed"],
            serde_json::Value::String(seed.to_string())
        );
        // Task 2 has no random-initialisation test.
        assert_eq!(row[col("random_init_mean")].is_empty(), key.task.number() == 2);
    }
    assert!(above_2_53 > 0, "no seed above 2^53 to test");

    // The seed read back from run.json repeats the run with `evolve`.
    let key = spec.runs()[0];
    let folder = psa_experiment::grid::run_dir(&dir, &key);
    let summary: serde_json::Value = serde_json::from_slice(&std::fs::read(folder.join("run.json")).unwrap()).unwrap();
    let seed = summary["seed"].as_str().unwrap();
    let again = tmp.path().join("again");
    let o = psa_esp(&[
        "evolve",
        "--task",
        "1",
        "--preset",
        "baseline",
        "--generations",
        "5",
        "--backend",
        "native",
        "--seed",
        seed,
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(again.join("records.csv")).unwrap(),
        std::fs::read(folder.join("records.csv")).unwrap()
    );
}
