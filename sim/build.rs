//! Compiles the `cuda` path's trial kernel for the host. (The git commit
//! is stamped one crate up, by `psa-experiment`'s build script, so that a
//! commit or an edit elsewhere never recompiles the simulator.)

fn main() {
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
