//! The SLURM job array against a real single-node SLURM cluster, started
//! by `scripts/slurm/test-cluster.sh` in a temporary folder: a 3-shard
//! array of a tiny grid and its dependent report job give the same run
//! files as one process, each run done by exactly one shard.
//!
//! Needs root and the Debian packages munge, slurmctld, slurmd and
//! slurm-client (`.ci/install-deps --tests` installs them). Without them the test
//! fails, unless PSA_ESP_SKIP_SLURM=1 says to skip it.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{assert_same_runs, finished_lines, psa_esp, tiny_grid};

fn script(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/slurm").join(name)
}

/// The test cluster, stopped (its own daemons only) when dropped.
struct Cluster {
    dir: PathBuf,
    conf: String,
}

impl Cluster {
    fn start(dir: &Path) -> Cluster {
        let o = Command::new(script("test-cluster.sh"))
            .args(["start", dir.to_str().unwrap()])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&o.stdout);
        let cluster = Cluster {
            dir: dir.to_path_buf(),
            conf: stdout
                .lines()
                .find_map(|l| l.strip_prefix("SLURM_CONF="))
                .unwrap_or_default()
                .to_string(),
        };
        assert!(
            o.status.success() && !cluster.conf.is_empty(),
            "the test cluster did not start: {stdout}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        cluster
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new(script("test-cluster.sh"))
            .args(["stop", self.dir.to_str().unwrap()])
            .status();
    }
}

/// Whether the SLURM and MUNGE programs are installed.
fn slurm_installed() -> bool {
    ["munged", "slurmctld", "slurmd", "sbatch"].iter().all(|tool| {
        Command::new("sh")
            .args(["-c", &format!("command -v {tool}")])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

#[test]
fn a_slurm_job_array_gives_the_single_process_grid() {
    if !slurm_installed() {
        if std::env::var("PSA_ESP_SKIP_SLURM").is_ok_and(|v| v == "1") {
            eprintln!("skipped: slurm not installed (PSA_ESP_SKIP_SLURM=1)");
            return;
        }
        panic!(
            "SLURM is not installed: install the Debian packages munge slurmctld slurmd slurm-client \
             (.ci/install-deps --tests does), or set PSA_ESP_SKIP_SLURM=1 to skip this test"
        );
    }
    let tmp = tempfile::tempdir().unwrap();
    let single = tmp.path().join("single");
    let o = psa_esp(
        &tiny_grid("replicate", &single)
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let cluster = Cluster::start(&tmp.path().join("cluster"));
    let jobs = tmp.path().join("jobs");
    std::fs::create_dir(&jobs).unwrap();
    let grid = tmp.path().join("grid");
    // The grid's options after `replicate`, its --threads left to the script.
    let options: Vec<String> = tiny_grid("replicate", &grid)
        .into_iter()
        .skip(1)
        .collect::<Vec<_>>()
        .chunks(2)
        .filter(|pair| pair[0] != "--threads")
        .flatten()
        .cloned()
        .collect();
    let o = Command::new(script("submit.sh"))
        .args(["--wait", "3", "replicate"])
        .args(&options)
        .current_dir(&jobs)
        .env("SLURM_CONF", &cluster.conf)
        .env("PSA_ESP", env!("CARGO_BIN_EXE_psa-esp"))
        .output()
        .unwrap();
    let logs = || {
        let mut text = String::new();
        for entry in std::fs::read_dir(&jobs).unwrap() {
            let path = entry.unwrap().path();
            text += &format!(
                "== {}\n{}",
                path.display(),
                std::fs::read_to_string(&path).unwrap_or_default()
            );
        }
        text
    };
    assert!(
        o.status.success(),
        "submit.sh failed: {}{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
        logs()
    );

    // One log per shard, each finishing one run (a shard's log is its
    // standard error: a line per finished run), then the report's.
    let mut ran = Vec::new();
    let mut shard_logs = 0;
    for entry in std::fs::read_dir(&jobs).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        if name.starts_with("psa-esp-report-") {
            assert!(
                String::from_utf8_lossy(&text).contains("3 of 3 runs counted"),
                "{}",
                logs()
            );
        } else {
            shard_logs += 1;
            let lines = finished_lines(&text);
            assert_eq!(lines.len(), 1, "{name}: {}", logs());
            ran.extend(lines);
        }
    }
    assert_eq!(shard_logs, 3, "{}", logs());
    ran.sort();
    ran.dedup();
    assert_eq!(ran.len(), 3, "each run by exactly one shard: {ran:?}");
    assert!(grid.join("report.md").exists() && grid.join("runs.csv").exists());
    assert_same_runs(&single, &grid);

    // A failing shard: the report job is cancelled and submit.sh says so.
    let o = Command::new(script("submit.sh"))
        .args(["--wait", "2", "replicate", "--generations", "0", "--out"])
        .arg(tmp.path().join("failing"))
        .current_dir(&jobs)
        .env("SLURM_CONF", &cluster.conf)
        .env("PSA_ESP", env!("CARGO_BIN_EXE_psa-esp"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("JobState=CANCELLED"), "{stdout}");
    assert!(String::from_utf8_lossy(&o.stderr).contains("did not complete"));
    drop(cluster);
}
