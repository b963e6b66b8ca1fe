//! Helpers shared by the grid tests: running the binary and reading a
//! grid's results for byte-for-byte comparison.
#![allow(dead_code)] // each test file uses its own share

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `psa-esp` with `args`.
pub fn psa_esp(args: &[&str]) -> Output {
    Command::new(binary()).args(args).output().unwrap()
}

/// The `psa-esp` binary: `PSA_ESP_BIN` where set (test binaries carried to
/// another machine, such as a GPU's), else the one cargo built.
pub fn binary() -> PathBuf {
    std::env::var_os("PSA_ESP_BIN").map_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_psa-esp")), PathBuf::from)
}

/// The fitness `psa-esp replay CHAMPION --backend BACKEND --json --out OUT
/// EXTRA...` prints (`fitness_percent_mean`); panics with its stderr if it
/// fails.
pub fn replayed_fitness(champion: &Path, backend: &str, out: &Path, extra: &[&str]) -> f64 {
    let mut args = vec![
        "replay",
        champion.to_str().unwrap(),
        "--backend",
        backend,
        "--json",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = psa_esp(&args);
    assert!(o.status.success(), "replay: {}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    json["fitness_percent_mean"].as_f64().unwrap()
}

/// The arguments of a tiny grid (one seed of baseline on tasks 1-3, five
/// generations) into `out`, after `command` (replicate).
pub fn tiny_grid(command: &str, out: &Path) -> Vec<String> {
    [
        command,
        "--preset",
        "quick",
        "--configs",
        "baseline",
        "--tasks",
        "1,2,3",
        "--seeds",
        "1",
        "--generations",
        "5",
        "--robustness-trials",
        "5",
        "--threads",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

/// The path of every file in every run folder of the grid in `dir`.
pub fn run_file_paths(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.join("runs")];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// Every file of every run folder, by path relative to `dir`, with
/// `run.json`'s times (`started`, `finished`, `seconds`: when, not what)
/// taken out. A claim left behind would show up here too.
pub fn run_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    for path in run_file_paths(dir) {
        let mut bytes = std::fs::read(&path).unwrap();
        if path.file_name().unwrap() == "run.json" {
            let mut summary: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
            let fields = summary.as_object_mut().unwrap();
            for time in ["started", "finished", "seconds"] {
                assert!(fields.remove(time).is_some(), "run.json without {time}");
            }
            bytes = serde_json::to_vec_pretty(&summary).unwrap();
        }
        files.push((path.strip_prefix(dir).unwrap().display().to_string(), bytes));
    }
    files.sort();
    files
}

/// Asserts that grids `a` and `b` hold the same run files, naming the
/// first that differs.
pub fn assert_same_runs(a: &Path, b: &Path) {
    let (a_files, b_files) = (run_files(a), run_files(b));
    let names = |files: &[(String, Vec<u8>)]| files.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a_files), names(&b_files), "different run files");
    for ((name, x), (_, y)) in a_files.iter().zip(&b_files) {
        assert!(x == y, "{name} differs between {} and {}", a.display(), b.display());
    }
}

/// The runs (`configuration task seed`, after `variant: ` in a sweep) a
/// replicate's or a sweep's standard error says it finished.
pub fn finished_lines(stderr: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(stderr)
        .lines()
        .filter_map(|l| match l.split_once(": finished ") {
            Some((variant, run)) => Some(format!("{variant}: {}", run.split(':').next().unwrap())),
            None => Some(l.strip_prefix("finished ")?.split(':').next().unwrap().to_string()),
        })
        .collect()
}
