//! Stamps provenance into the binary: the git commit the build came from
//! (with a `-dirty` suffix for uncommitted changes) and the libode version
//! that `ode-sys` was built against. Every result file records both.
//!
//! Cargo reruns this script when the commit changes (HEAD, the branch's
//! ref, packed refs) or a tracked source changes, never merely because git
//! rewrote its index: in a fresh clone the first `git status` does, and a
//! second build then compiled the whole crate again. Git is asked with
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
    // `ode-sys` declares `links = "ode"` and prints `cargo:version=...`.
    let libode = std::env::var("DEP_ODE_VERSION").unwrap_or_else(|_| "unknown".into());
    println!("cargo:rustc-env=PSA_ESP_LIBODE_VERSION={libode}");
    if commit.is_some() {
        let mut refs = vec!["HEAD".to_string(), "packed-refs".to_string()];
        refs.extend(git(&["symbolic-ref", "-q", "HEAD"]));
        for name in refs {
            if let Some(path) = git(&["rev-parse", "--git-path", &name]) {
                watch(&path);
            }
        }
        // Tracked sources: an edit makes the build dirty, a commit clean.
        for source in ["src", "esp", "ode-sys", "benches", "tests", "Cargo.toml", "Cargo.lock"] {
            watch(source);
        }
    }
    compile_trial_host();
    println!("cargo:rerun-if-changed=build.rs");
}

/// Compiles the `cuda` path's trial kernel (`src/psa/cuda/trial.cu`, CUDA
/// C that is also plain C) for the host as the program `psa-trial-host`,
/// with contraction of multiply-adds off as NVRTC's `--fmad=false`: the
/// tests fly it against `native` bit for bit. Its path goes to the crate
/// as `PSA_ESP_TRIAL_HOST`.
fn compile_trial_host() {
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("psa-trial-host");
    let status = cc::Build::new()
        .get_compiler()
        .to_command()
        .args(["-std=c99", "-O2", "-ffp-contract=off", "-o"])
        .arg(&out)
        .arg("src/psa/cuda/host_driver.c")
        .arg("-lm")
        .status()
        .expect("the C compiler runs");
    assert!(status.success(), "compiling src/psa/cuda/host_driver.c failed");
    println!("cargo:rustc-env=PSA_ESP_TRIAL_HOST={}", out.display());
    for source in ["src/psa/cuda/trial.cu", "src/psa/cuda/host_driver.c"] {
        println!("cargo:rerun-if-changed={source}");
    }
}
