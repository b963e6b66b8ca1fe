//! Where a result came from: tool version, git commit and libode version,
//! stamped into the binary by `build.rs`.

use serde::Serialize;

/// The build's identity, recorded in every result file.
#[derive(Debug, Clone, Serialize)]
pub struct BuildInfo {
    /// The crate version.
    pub tool_version: &'static str,
    /// The git commit of the build (`-dirty` when it had uncommitted changes).
    pub git_commit: &'static str,
    /// The libode version `ode-sys` was built against.
    pub libode_version: &'static str,
}

/// What `psa-esp --version` prints after the name: the crate version, the
/// commit and the libode version.
pub const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("PSA_ESP_GIT_COMMIT"),
    ", libode ",
    env!("PSA_ESP_LIBODE_VERSION"),
    ")"
);

/// This binary's build identity.
pub fn build_info() -> BuildInfo {
    BuildInfo {
        tool_version: env!("CARGO_PKG_VERSION"),
        git_commit: env!("PSA_ESP_GIT_COMMIT"),
        libode_version: env!("PSA_ESP_LIBODE_VERSION"),
    }
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
