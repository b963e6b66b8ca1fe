//! Where a result came from: the build's identity as every result file
//! records it, this host's name and the time. The git commit is stamped
//! one crate up, by `psa-experiment` (`psa_experiment::build_info`), so
//! that a commit never recompiles the simulator.

use serde::{Deserialize, Serialize};

/// The build's identity, recorded in every result file (`run.json`'s
/// `build`, a network file's `provenance`).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct BuildInfo {
    /// The crate version.
    pub tool_version: String,
    /// The git commit of the build (`-dirty` when it had uncommitted changes).
    pub git_commit: String,
    /// The libode version `ode-sys` was built against.
    pub libode_version: String,
    /// How many rows the build's table of defaults had
    /// ([`crate::psa::settings::defaults`]); absent in files of builds before it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub defaults: Option<u64>,
}

/// The current UTC time as RFC 3339, to the second.
pub fn now_rfc3339() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

/// This host's name: `/proc/sys/kernel/hostname` on Linux, else `$HOSTNAME`,
/// else `localhost`; any character but ASCII letters, digits, `.`, `-` and
/// `_` is replaced by `_`, so that it can go into a file name.
pub fn host_name() -> String {
    let name = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|n| n.trim().to_string())
        .filter(|n| !n.is_empty())
        .unwrap_or_else(|| "localhost".into());
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}
