//! Nothing silent: every setting a command takes either acts
//! or is refused, old results stay readable, and no output path can
//! clobber the system. One module per rule, each test named after what it
//! holds; the helpers the modules share are here.

mod bad_files;
mod checkpoints;
#[path = "../common/mod.rs"]
mod common;
mod earlier_files;
mod earlier_grids;
mod grid_files;
mod inert_settings;
mod output_paths;
mod sweeps;
mod task_settings;
mod traces;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use esp_neuroevolution::network::Network;
use psa_experiment::grid::sweep::{parse_vary, SweepMode, SweepSpec, MAX_VARIANT_NAME};
use psa_experiment::grid::{run_dir, GridPreset, GridSpec, RunKey};
use psa_experiment::RunFiles;
use psa_sim::physics::{BackendKind, StartQuaternion};
use psa_sim::psa::settings::defaults::{Placement, CHANGES};
use psa_sim::psa::{FitnessState, HeadingWrap, NetworkFile, PsaSettings, Scoring, Task};

use common::psa_esp;

pub(crate) fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

pub(crate) fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub(crate) fn ok(o: &Output) -> String {
    assert!(o.status.success(), "exit {:?}: {}", o.status.code(), stderr(o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Asserts exit code 2 and a message holding every one of `needles`.
pub(crate) fn refused(o: &Output, needles: &[&str]) -> String {
    let text = stderr(o);
    assert_eq!(o.status.code(), Some(2), "expected exit 2: {text}");
    for needle in needles {
        assert!(text.contains(needle), "the message lacks {needle:?}: {text}");
    }
    assert!(!text.contains("panicked"), "{text}");
    text
}

/// Runs the binary with `args`, killed after `limit` (then `None`).
pub(crate) fn run_within(args: &[&str], limit: Duration) -> Option<Output> {
    let mut child = Command::new(common::binary())
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Some(child.wait_with_output().unwrap())
}

pub(crate) fn make_fifo(path: &Path) {
    assert!(Command::new("mkfifo").arg(path).status().unwrap().success());
}

/// The full hash of the parent of `commit` (a prefix), from the history
/// the table of defaults places builds in.
pub(crate) fn parent_of(commit: &str) -> String {
    match Placement::before_commit(commit) {
        Some(Placement::Commit(parent)) => parent,
        _ => panic!("{commit}: not a commit of the history with a parent"),
    }
}

/// A process id that no process has now: a child that has ended.
pub(crate) fn dead_pid() -> u32 {
    let mut child = Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

/// A finished tiny grid (baseline, task 1, one seed, 3 generations), made
/// once; each test copies it.
pub(crate) fn finished_grid() -> &'static Path {
    static GRID: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, path) = GRID.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("grid");
        ok(&psa_esp(&tiny_args(&out)));
        (dir, out)
    });
    path
}

pub(crate) fn tiny_args(out: &Path) -> Vec<&'static str> {
    let out = Box::leak(out.display().to_string().into_boxed_str());
    vec![
        "replicate",
        "--preset",
        "quick",
        "--configs",
        "baseline",
        "--tasks",
        "1",
        "--seeds",
        "1",
        "--generations",
        "3",
        "--robustness-trials",
        "3",
        "--threads",
        "1",
        "--quiet",
        "--out",
        out,
    ]
}

/// A copy of the finished tiny grid in `dir`.
pub(crate) fn copy_of_grid(dir: &Path) -> PathBuf {
    let copy = dir.join("grid");
    let status = Command::new("cp")
        .arg("-a")
        .arg(finished_grid())
        .arg(&copy)
        .status()
        .unwrap();
    assert!(status.success());
    copy
}

pub(crate) fn run_folder(grid: &Path) -> PathBuf {
    run_dir(
        grid,
        &RunKey {
            config: "baseline".parse().unwrap(),
            task: Task::StopRotation,
            seed: 1,
        },
    )
}

pub(crate) fn names_in(dir: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut names: Vec<String> = entries
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Makes the run of the grid in `grid` look written by the build before
/// `changed`: its config.toml without the table's keys, its run.json
/// naming that build.
pub(crate) fn age_run(grid: &Path, changed: &str) {
    age_run_folder(&run_folder(grid), changed);
}

pub(crate) fn network_json(problem: &PsaSettings) -> serde_json::Value {
    let network = Network::from_genes(7, 4, vec![0.25; 2 * 11]).unwrap();
    let file = NetworkFile::new(
        &network,
        Task::StopRotation,
        problem,
        &psa_experiment::build_info(),
        serde_json::Map::new(),
    );
    serde_json::to_value(&file).unwrap()
}

pub(crate) fn load_json(dir: &Path, json: &serde_json::Value) -> Result<PsaSettings, String> {
    let path = dir.join("net.json");
    std::fs::write(&path, json.to_string()).unwrap();
    NetworkFile::load(&path)
        .map(|(file, _)| file.problem.unwrap())
        .map_err(|e| e.to_string())
}

/// Rescores the grid `source` with the settings `toml` into a folder in
/// `dir`: refused, naming `key` as changing nothing, and nothing written.
pub(crate) fn rescore_is_refused_as_changing_nothing(dir: &Path, source: &Path, toml: &str, key: &str) {
    let config = dir.join("rescore.toml");
    std::fs::write(&config, toml).unwrap();
    let out = dir.join("rescored");
    refused(
        &psa_esp(&[
            "rescore",
            source.to_str().unwrap(),
            "--config",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]),
        &[key, "changes nothing"],
    );
    assert!(!out.exists(), "{key}: nothing written");
}

pub(crate) fn sweep_of(grid: GridSpec, vary: &[&str]) -> anyhow::Result<SweepSpec> {
    let vary = vary.iter().map(|v| parse_vary(v)).collect::<anyhow::Result<Vec<_>>>()?;
    SweepSpec::new(grid, vary, SweepMode::Combinations)
}

pub(crate) fn grid(configs: &[&str], tasks: &[Task]) -> GridSpec {
    GridSpec {
        configs: configs.iter().map(|c| c.parse().unwrap()).collect(),
        tasks: tasks.to_vec(),
        seeds: 1,
        first_seed: 1,
        generations: 3,
        robustness_trials: 3,
        ..GridSpec::from_preset(GridPreset::Quick)
    }
}

/// The arguments of a tiny sweep on `tasks` into `out`, varying each of
/// `vary`: the tiny grid's (`tiny_args`) as a sweep.
pub(crate) fn tiny_sweep<'a>(out: &Path, tasks: &'a str, vary: &[&'a str]) -> Vec<&'a str> {
    let mut args = tiny_args(out);
    args[0] = "sweep";
    let at = args.iter().position(|a| *a == "--tasks").unwrap();
    args[at + 1] = tasks;
    for v in vary {
        args.extend(["--vary", v]);
    }
    args
}

/// Every file called `name` under `dir`, sorted.
pub(crate) fn files_named(dir: &Path, name: &str) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).into_iter().flatten() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.file_name().is_some_and(|n| n == name) {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// [`age_run`] for the run in `folder`.
pub(crate) fn age_run_folder(folder: &Path, changed: &str) {
    let text = std::fs::read_to_string(folder.join("config.toml")).unwrap();
    let mut table: toml::Table = toml::from_str(&text).unwrap();
    for row in CHANGES {
        let mut parts: Vec<&str> = row.key.split('.').collect();
        let last = parts.pop().unwrap();
        let mut at = Some(&mut table);
        for part in parts {
            at = at.and_then(|t| t.get_mut(part)).and_then(|v| v.as_table_mut());
        }
        if let Some(t) = at {
            t.remove(last);
        }
    }
    std::fs::write(folder.join("config.toml"), toml::to_string(&table).unwrap()).unwrap();
    let path = folder.join("run.json");
    let mut run: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let build = run["build"].as_object_mut().unwrap();
    build.remove("defaults");
    build.insert("git_commit".into(), parent_of(changed).into());
    std::fs::write(&path, serde_json::to_string_pretty(&run).unwrap()).unwrap();
}

/// `report --format json` of `grid` (exit 1 when a run is not counted),
/// and its report.json.
pub(crate) fn report_json(grid: &Path) -> serde_json::Value {
    let o = psa_esp(&["report", grid.to_str().unwrap(), "--format", "json"]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(grid.join("report.json")).unwrap()).unwrap()
}
