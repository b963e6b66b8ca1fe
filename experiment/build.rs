//! Stamps the git commit the build came from into the crate (with a
//! `-dirty` suffix for uncommitted changes); every result file records it.
//! It lives here, not in the simulator, so that a commit or an edit
//! recompiles this crate and the binary, never the simulator's kernels.
//!
//! Cargo reruns this script when the commit changes (HEAD, the branch's
//! ref, packed refs) or a tracked source changes, never merely because git
//! rewrote its index: in a fresh clone the first `git status` does, and a
//! second build then compiled the crate again. Git is asked with
//! `--no-optional-locks`, so this script never rewrites the index itself.

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .arg("--no-optional-locks")
        .args(args)
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// Asks cargo to rerun this script when `path` changes, if it exists (a
/// path that does not exist would make cargo rerun it at every build).
fn watch(path: &str) {
    if Path::new(path).exists() {
        println!("cargo:rerun-if-changed={path}");
    }
}

fn main() {
    let commit = git(&["rev-parse", "HEAD"]).map(|hash| {
        let dirty = git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|status| !status.is_empty());
        if dirty {
            format!("{hash}-dirty")
        } else {
            hash
        }
    });
    println!(
        "cargo:rustc-env=PSA_ESP_GIT_COMMIT={}",
        commit.as_deref().unwrap_or("unknown")
    );
    if commit.is_some() {
        let mut refs = vec!["HEAD".to_string(), "packed-refs".to_string()];
        refs.extend(git(&["symbolic-ref", "-q", "HEAD"]));
        for name in refs {
            if let Some(path) = git(&["rev-parse", "--git-path", &name]) {
                watch(&path);
            }
        }
        // The workspace's tracked sources: an edit makes the build dirty,
        // a commit clean.
        for source in [
            "src",
            "sim",
            "experiment",
            "esp",
            "ode-sys",
            "benches",
            "tests",
            "Cargo.toml",
            "Cargo.lock",
        ] {
            watch(&format!("../{source}"));
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
}
