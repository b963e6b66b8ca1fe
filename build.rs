//! Stamps provenance into the binary: the git commit the build came from
//! (with a `-dirty` suffix for uncommitted changes) and the libode version
//! that `ode-sys` was built against. Every result file records both.

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
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
    if let Some(git_dir) = git(&["rev-parse", "--git-dir"]) {
        println!("cargo:rerun-if-changed={git_dir}/HEAD");
        println!("cargo:rerun-if-changed={git_dir}/index");
        if let Some(head_ref) = git(&["symbolic-ref", "-q", "HEAD"]) {
            println!("cargo:rerun-if-changed={git_dir}/{head_ref}");
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
}
