//! Claims: several processes on one grid folder (two terminals, a job
//! array without shards, a re-submitted job) share out its runs. A process
//! claims a run before starting it by creating `claim.json` in the run's
//! folder (atomically: exactly one of several racing processes creates it),
//! naming its host, process id and start time, and removes it once the run
//! is finished. A claim is taken over when its process is gone (same host,
//! process id no longer running, or running a different program since) or
//! when it is older than the claim timeout.

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

/// The claim file in a run folder.
pub const CLAIM_FILE: &str = "claim.json";

/// How old a claim may grow before another process takes it over
/// (`--claim-timeout`): far longer than any run of the paper's grid.
pub const DEFAULT_CLAIM_TIMEOUT: Duration = Duration::from_secs(48 * 3600);

/// What `claim.json` holds.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClaimRecord {
    /// The claiming host ([`psa_sim::provenance::host_name`]).
    pub host: String,
    /// Its process id.
    pub pid: u32,
    /// The process's start time in clock ticks after boot (Linux's
    /// `/proc/PID/stat`), telling a reused process id from the claimant.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub process_start: Option<u64>,
    /// When the run was claimed (RFC 3339).
    pub started: String,
    /// The same, in seconds after 1970-01-01 UTC.
    pub started_unix: u64,
}

impl ClaimRecord {
    /// A claim by this process, now.
    fn mine() -> ClaimRecord {
        let pid = std::process::id();
        ClaimRecord {
            host: psa_sim::provenance::host_name(),
            pid,
            process_start: process_start(pid),
            started: psa_sim::provenance::now_rfc3339(),
            started_unix: unix_now(),
        }
    }

    /// Why the claim may be taken over, if it may: its process is gone, or
    /// it is older than `timeout`.
    pub fn stale(&self, timeout: Duration) -> Option<String> {
        let age = unix_now().saturating_sub(self.started_unix);
        if age > timeout.as_secs() {
            return Some(format!(
                "claimed {age} s ago, longer than the claim timeout of {} s",
                timeout.as_secs()
            ));
        }
        if self.host == psa_sim::provenance::host_name() && !process_alive(self.pid, self.process_start) {
            return Some(format!("process {} on this host is gone", self.pid));
        }
        None
    }
}

impl std::fmt::Display for ClaimRecord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "host {} pid {} since {}", self.host, self.pid, self.started)
    }
}

/// A run this process holds; dropping it removes the claim file (unless
/// another process has taken it over meanwhile).
#[derive(Debug)]
pub struct Claim {
    path: PathBuf,
    text: String,
}

impl Drop for Claim {
    fn drop(&mut self) {
        if std::fs::read_to_string(&self.path).is_ok_and(|text| text == self.text) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// What [`claim`] got.
#[derive(Debug)]
pub enum Attempt {
    /// The run is this process's now.
    Claimed(Claim),
    /// Another live process holds it.
    Held(ClaimRecord),
}

/// Claims the run in `folder` (created if need be), taking over a claim
/// whose process is gone or that is older than `timeout`.
pub fn claim(folder: &Path, timeout: Duration) -> Result<Attempt> {
    psa_sim::io::create_output_dir(folder)?;
    let path = folder.join(CLAIM_FILE);
    // Each pass either claims, finds a live claim, or clears a stale one;
    // only racing processes make it go round more than twice.
    for _ in 0..100 {
        let mut text = serde_json::to_string_pretty(&ClaimRecord::mine())?;
        text.push('\n');
        if psa_sim::io::create_new_atomic(&path, text.as_bytes())? {
            return Ok(Attempt::Claimed(Claim { path, text }));
        }
        let existing = match std::fs::read_to_string(&path) {
            Ok(existing) => existing,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
            Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
        };
        match serde_json::from_str::<ClaimRecord>(&existing) {
            Ok(record) => match record.stale(timeout) {
                Some(_) => take_over(&path, &existing)?,
                None => return Ok(Attempt::Held(record)),
            },
            // Not a claim this tool wrote whole: cleared when it is older
            // than a minute (a file system without hard links shows a claim
            // half-written for a moment).
            Err(_) if modified_before(&path, Duration::from_secs(60)) => take_over(&path, &existing)?,
            Err(_) => std::thread::sleep(Duration::from_millis(100)),
        }
    }
    anyhow::bail!(
        "{}: could not claim the run (other processes keep claiming and clearing it)",
        path.display()
    )
}

/// Removes the claim in the folder of a finished run when its process is
/// gone or it is older than `timeout` (a grid killed while writing, or a
/// lockstep grid killed before releasing its claims, leaves them): a
/// finished run holds only its documented files. A live claim is left.
pub fn clear_stale(folder: &Path, timeout: Duration) -> Result<()> {
    let path = folder.join(CLAIM_FILE);
    let Ok(existing) = psa_sim::io::read_input_text(&path) else {
        return Ok(());
    };
    match serde_json::from_str::<ClaimRecord>(&existing) {
        Ok(record) if record.stale(timeout).is_some() => take_over(&path, &existing),
        Err(_) if modified_before(&path, Duration::from_secs(60)) => take_over(&path, &existing),
        _ => Ok(()),
    }
}

/// Clears the stale claim `path` whose text was `stale`: it is renamed
/// aside first, so that of several processes clearing it at once exactly
/// one does; should the renamed file prove to be a fresh claim made since,
/// it is put back.
fn take_over(path: &Path, stale: &str) -> Result<()> {
    let aside = path.with_file_name(psa_sim::io::temporary_name("claim.json.stale"));
    match std::fs::rename(path, &aside) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e).with_context(|| format!("cannot take over {}", path.display())),
    }
    let moved = std::fs::read_to_string(&aside).unwrap_or_default();
    if moved != stale {
        // Someone claimed the run between our read and the rename: restore it.
        let _ = std::fs::hard_link(&aside, path);
    }
    std::fs::remove_file(&aside).with_context(|| format!("cannot remove {}", aside.display()))
}

/// Whether `path` was last modified longer than `age` ago.
fn modified_before(path: &Path, age: Duration) -> bool {
    std::fs::metadata(path)
        .and_then(|m| m.modified())
        .is_ok_and(|t| t.elapsed().is_ok_and(|elapsed| elapsed > age))
}

/// Seconds since 1970-01-01 UTC.
fn unix_now() -> u64 {
    SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs())
}

/// The start time of process `pid` in clock ticks after boot (field 22 of
/// `/proc/PID/stat`), where the system has `/proc` and the process runs:
/// one that has exited (a zombie its parent has not reaped, state `Z`, or
/// `X`) has none.
fn process_start(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces.
    let mut fields = stat[stat.rfind(')')? + 1..].split_whitespace();
    if matches!(fields.next()?, "Z" | "X") {
        return None;
    }
    fields.nth(18)?.parse().ok()
}

/// Whether process `pid` of this host still runs and is the one that
/// started at `start`. Without `/proc` it cannot be told: taken as running.
fn process_alive(pid: u32, start: Option<u64>) -> bool {
    if !Path::new("/proc/self/stat").exists() {
        return true;
    }
    match (process_start(pid), start) {
        (None, _) => false,
        (Some(now), Some(then)) => now == then,
        (Some(_), None) => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(host: String, pid: u32, process_start: Option<u64>, age: u64) -> ClaimRecord {
        ClaimRecord {
            host,
            pid,
            process_start,
            started: "2026-01-01T00:00:00Z".into(),
            started_unix: unix_now() - age,
        }
    }

    #[test]
    fn a_claimant_that_has_exited_but_is_not_reaped_is_dead() {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        // Until reaped, the exited child is a zombie: /proc still lists it.
        let zombie = (0..500).any(|_| {
            std::thread::sleep(std::time::Duration::from_millis(10));
            std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|s| s.contains(") Z "))
        });
        assert!(zombie, "the child never showed as a zombie");
        assert!(!process_alive(pid, None));
        child.wait().unwrap();
        // A running process is alive, and its start time is read.
        let me = std::process::id();
        assert!(process_alive(me, process_start(me)));
    }

    #[test]
    fn a_claim_is_held_until_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("seed1");
        let Attempt::Claimed(first) = claim(&folder, DEFAULT_CLAIM_TIMEOUT).unwrap() else {
            panic!("a new run is claimed");
        };
        let found: ClaimRecord =
            serde_json::from_str(&std::fs::read_to_string(folder.join(CLAIM_FILE)).unwrap()).unwrap();
        assert_eq!(
            (found.pid, found.host.clone()),
            (std::process::id(), psa_sim::provenance::host_name())
        );
        match claim(&folder, DEFAULT_CLAIM_TIMEOUT).unwrap() {
            Attempt::Held(record) => assert_eq!(record, found),
            Attempt::Claimed(_) => panic!("a live claim is not taken over"),
        }
        drop(first);
        assert!(!folder.join(CLAIM_FILE).exists());
        assert!(matches!(
            claim(&folder, DEFAULT_CLAIM_TIMEOUT).unwrap(),
            Attempt::Claimed(_)
        ));
        let names: Vec<_> = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert!(names.is_empty(), "nothing left behind: {names:?}");
    }

    #[test]
    fn claims_of_gone_processes_and_old_claims_are_taken_over() {
        let host = psa_sim::provenance::host_name();
        let me = std::process::id();
        let timeout = Duration::from_secs(3600);
        assert_eq!(record(host.clone(), me, process_start(me), 10).stale(timeout), None);
        // A finished child's pid is gone.
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let gone = child.id();
        child.wait().unwrap();
        let why = record(host.clone(), gone, None, 10).stale(timeout).unwrap();
        assert!(why.contains("gone"), "{why}");
        // This pid, started at another time: reused by another process.
        let why = record(host.clone(), me, Some(process_start(me).unwrap() + 1), 10)
            .stale(timeout)
            .unwrap();
        assert!(why.contains("gone"), "{why}");
        // Another host: only the age tells.
        assert_eq!(record("elsewhere".into(), gone, None, 10).stale(timeout), None);
        let why = record("elsewhere".into(), gone, None, 7200).stale(timeout).unwrap();
        assert!(why.contains("claim timeout"), "{why}");

        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("seed1");
        std::fs::create_dir_all(&folder).unwrap();
        let dead = serde_json::to_string(&record(host, gone, None, 10)).unwrap();
        std::fs::write(folder.join(CLAIM_FILE), dead).unwrap();
        let Attempt::Claimed(_claim) = claim(&folder, timeout).unwrap() else {
            panic!("the claim of a gone process is taken over");
        };
        let found: ClaimRecord =
            serde_json::from_str(&std::fs::read_to_string(folder.join(CLAIM_FILE)).unwrap()).unwrap();
        assert_eq!(found.pid, me);
        assert_eq!(
            std::fs::read_dir(&folder).unwrap().count(),
            1,
            "nothing but the claim left"
        );
    }
}
