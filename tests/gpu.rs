//! The `cuda` path on real CUDA libraries. Each test runs where what it
//! needs is there and is reported as ignored, by name, where not (this
//! harness decides at run time, and prints why on standard error):
//!
//! - `the_kernel_path_on_the_host_gives_the_native_grid` (always): the
//!   GPU path's plumbing, with the kernel built for the host;
//! - `the_bench_times_the_kernel_beside_native` (always): `bench`'s kernel
//!   rows, the host build standing in for the GPU;
//! - `nvrtc_compiles_the_trial_kernel`: a `cuda` build and NVRTC (no GPU);
//! - `the_gpu_gives_the_scalar_paths_bits`: a `cuda` build, the driver,
//!   NVRTC and a device; the kernel's fitness on the GPU against the scalar
//!   path, bit for bit, on the 1,700 networks of the host build's test;
//! - `the_gpu_grid_is_byte_identical_to_native`: the same, and a tiny grid
//!   with `--backend cuda` against one with `--backend native`, file for file;
//! - `the_cuda_backend_fails_cleanly_without_a_gpu`: where there is no GPU
//!   (or driver, NVRTC or `cuda` build), `--backend cuda` exits 2 naming
//!   what is missing.

mod common;
mod kernel_cases;

use libtest_mimic::{Arguments, Failed, Trial};

/// Set (as CI does), the NVRTC test runs, and fails, where NVRTC is missing
/// instead of being ignored.
const REQUIRE_NVRTC: &str = "PSA_ESP_REQUIRE_NVRTC";
use psa_sim::psa::cuda::{compile_for_check, CudaTrials, CudaUnavailable, KERNEL_NAME};

fn nvrtc_compiles_the_trial_kernel() -> Result<(), Failed> {
    let ptx = compile_for_check().map_err(|e| e.to_string())?;
    if !ptx.contains(&format!(".entry {KERNEL_NAME}")) {
        return Err(format!("the PTX has no entry {KERNEL_NAME}").into());
    }
    // The kernel's explicit fma() calls, in double precision.
    if !ptx.contains("fma.rn.f64") {
        return Err("the PTX has no double-precision fma".into());
    }
    Ok(())
}

fn the_gpu_gives_the_scalar_paths_bits() -> Result<(), Failed> {
    let gpu = CudaTrials::open().map_err(|e| e.to_string())?;
    eprintln!("on {}", gpu.device());
    kernel_cases::assert_kernel_gives_the_scalar_paths_bits(|batch| gpu.fly(batch));
    Ok(())
}

/// A small grid with noise and random starts: `replicate` on `backend`,
/// with `--eval-path path`, if given.
fn small_grid(backend: &str, out: &std::path::Path, path: Option<&str>) -> std::process::Output {
    let out = out.to_str().unwrap();
    let mut command = std::process::Command::new(common::binary());
    command.args([
        "replicate",
        "--preset",
        "quick",
        "--configs",
        "baseline,input-noise,random-init",
        "--tasks",
        "1,2,3",
        "--seeds",
        "2",
        "--generations",
        "5",
        "--robustness-trials",
        "5",
        "--backend",
        backend,
        "--quiet",
        "--lockstep",
        "--out",
        out,
    ]);
    if let Some(path) = path {
        command.args(["--eval-path", path]);
    }
    command.output().unwrap()
}

/// Asserts that the small grid writes the same files run as `a` and as
/// `b`, each a `--backend` and an `--eval-path`, if any.
fn assert_same_grids(a: (&str, Option<&str>), b: (&str, Option<&str>)) -> Result<(), Failed> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let outs = [dir.path().join("a"), dir.path().join("b")];
    for ((backend, path), out) in [a, b].into_iter().zip(&outs) {
        let output = small_grid(backend, out, path);
        if !output.status.success() {
            let stderr = String::from_utf8_lossy(&output.stderr);
            return Err(format!("replicate --backend {backend} with {path:?}: {stderr}").into());
        }
    }
    common::assert_same_runs(&outs[0], &outs[1]);
    Ok(())
}

/// The GPU path's plumbing without a GPU: the small grid in lockstep with
/// every trial flown by the kernel built for the host (`--eval-path kernel-host`,
/// a round's networks of a configuration and task per call, as a GPU gets
/// them) against `native`, file for file.
fn the_kernel_path_on_the_host_gives_the_native_grid() -> Result<(), Failed> {
    assert_same_grids(("native", None), ("native", Some("kernel-host")))
}

fn the_gpu_grid_is_byte_identical_to_native() -> Result<(), Failed> {
    assert_same_grids(("native", None), ("cuda", None))
}

/// `bench`'s kernel rows, with the kernel built for the host standing in
/// for the GPU: a row per size, beside `native`.
fn the_bench_times_the_kernel_beside_native() -> Result<(), Failed> {
    let output = std::process::Command::new(common::binary())
        .args([
            "bench",
            "--kernel-host",
            "--steps",
            "500",
            "--rounds",
            "1",
            "--networks",
            "16",
        ])
        .args(["--generations", "2", "--kernel-networks", "8,24", "--json"])
        .output()
        .map_err(|e| e.to_string())?;
    if !output.status.success() {
        return Err(String::from_utf8_lossy(&output.stderr).into_owned().into());
    }
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).map_err(|e| e.to_string())?;
    let kernel = &json["cuda_kernel"];
    let rows = kernel["rows"].as_array().ok_or("no kernel rows")?;
    let sizes: Vec<u64> = rows.iter().filter_map(|r| r["networks"].as_u64()).collect();
    if sizes != [8, 24] || !kernel["device"].as_str().is_some_and(|d| d.contains("host")) {
        return Err(format!("unexpected kernel rows: {kernel}").into());
    }
    for row in rows {
        for key in ["end_to_end_ns_per_network_step", "native_ns_per_network_step"] {
            if !row[key].as_f64().is_some_and(|ns| ns.is_finite() && ns > 0.0) {
                return Err(format!("{key} is not a time: {row}").into());
            }
        }
        // The host build has no CUDA events to time its kernel alone.
        if !row["kernel_ns_per_network_step"].is_null() {
            return Err(format!("the host build timed a kernel alone: {row}").into());
        }
    }
    Ok(())
}

/// Without a GPU (or NVRTC, or a `cuda` build), `--backend cuda` exits 2
/// with the missing piece named, before writing anything.
fn the_cuda_backend_fails_cleanly_without_a_gpu(why: String) -> Result<(), Failed> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let out = dir.path().join("grid");
    let output = small_grid("cuda", &out, None);
    let stderr = String::from_utf8_lossy(&output.stderr);
    if output.status.code() != Some(2) || !stderr.contains(&why) || stderr.contains("panicked") {
        return Err(format!(
            "expected exit 2 naming {why:?}, got {:?}: {stderr}",
            output.status.code()
        )
        .into());
    }
    if out.exists() {
        return Err("the failed grid wrote its folder".into());
    }
    Ok(())
}

fn main() {
    let args = Arguments::from_args();
    let nvrtc = compile_for_check().err();
    let gpu = CudaTrials::open().err();
    for (what, missing) in [("NVRTC", &nvrtc), ("a GPU", &gpu)] {
        if let Some(why) = missing {
            eprintln!("gpu tests: the tests that need {what} are ignored: {why}");
        }
    }
    let needs = |missing: &Option<CudaUnavailable>| missing.is_some();
    let gpu_missing = gpu.as_ref().map(ToString::to_string);
    let tests = vec![
        Trial::test(
            "the_kernel_path_on_the_host_gives_the_native_grid",
            the_kernel_path_on_the_host_gives_the_native_grid,
        ),
        Trial::test(
            "the_bench_times_the_kernel_beside_native",
            the_bench_times_the_kernel_beside_native,
        ),
        Trial::test("nvrtc_compiles_the_trial_kernel", nvrtc_compiles_the_trial_kernel)
            .with_ignored_flag(needs(&nvrtc) && std::env::var_os(REQUIRE_NVRTC).is_none()),
        Trial::test(
            "the_gpu_gives_the_scalar_paths_bits",
            the_gpu_gives_the_scalar_paths_bits,
        )
        .with_ignored_flag(needs(&gpu)),
        Trial::test(
            "the_gpu_grid_is_byte_identical_to_native",
            the_gpu_grid_is_byte_identical_to_native,
        )
        .with_ignored_flag(needs(&gpu)),
        Trial::test("the_cuda_backend_fails_cleanly_without_a_gpu", move || {
            the_cuda_backend_fails_cleanly_without_a_gpu(gpu_missing.clone().unwrap_or_default())
        })
        .with_ignored_flag(!needs(&gpu)),
    ];
    libtest_mimic::run(&args, tests).exit();
}
