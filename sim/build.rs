//! Names the host C compiler for the `cuda` path's host build of its trial
//! kernel (`psa_sim::psa::cuda::host`), which compiles each specialisation
//! of `src/psa/cuda/trial.cu` when first asked for it. (The git commit is
//! stamped one crate up, by `psa-experiment`'s build script, so that a
//! commit or an edit elsewhere never recompiles the simulator.)

fn main() {
    let compiler = cc::Build::new().get_compiler();
    println!("cargo:rustc-env=PSA_ESP_HOST_CC={}", compiler.path().display());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=CC");
}
