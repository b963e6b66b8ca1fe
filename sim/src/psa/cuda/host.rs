//! The host build of the trial kernel: `trial.cu` compiled with the host C
//! compiler (the one the build used, `-ffp-contract=off`, the
//! specialisation's `-D` options, as NVRTC compiles it for the GPU) into
//! the program `psa-trial-host`, and [`fly_on_host`], which runs it. Each
//! specialisation is compiled once, when first asked for, into a cache
//! folder under the system's temporary folder, named by a hash of the
//! sources, the compiler and the options.

use std::collections::hash_map::DefaultHasher;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex, OnceLock};

use zerocopy::IntoBytes;

use super::{Specialisation, TrialBatch, TrialPoints, KERNEL_SOURCE};
use crate::psa::PsaError;

/// The host program's `main`, which includes `trial.cu`.
const DRIVER_SOURCE: &str = include_str!("host_driver.c");
/// The C compiler of the build (the `cc` crate's choice, as `build.rs` saw it).
const COMPILER: &str = env!("PSA_ESP_HOST_CC");

fn failed(why: impl std::fmt::Display) -> PsaError {
    PsaError::Setting(format!("the host build of the cuda kernel: {why}"))
}

/// The host program of `specialisation`, compiled if not yet in the cache.
pub fn program(specialisation: &Specialisation) -> Result<PathBuf, PsaError> {
    type Compiled = Arc<OnceLock<Result<PathBuf, String>>>;
    static PROGRAMS: OnceLock<Mutex<HashMap<String, Compiled>>> = OnceLock::new();
    let key = specialisation.key();
    let slot = PROGRAMS
        .get_or_init(Default::default)
        .lock()
        .map_err(|_| failed("a compilation panicked"))?
        .entry(key)
        .or_default()
        .clone();
    slot.get_or_init(|| compile(specialisation).map_err(|e| e.to_string()))
        .clone()
        .map_err(failed)
}

/// Compiles `specialisation` into the cache folder (or finds it there).
fn compile(specialisation: &Specialisation) -> std::io::Result<PathBuf> {
    let options = specialisation.defines();
    let mut hasher = DefaultHasher::new();
    (KERNEL_SOURCE, DRIVER_SOURCE, COMPILER, &options).hash(&mut hasher);
    let name = format!("psa-trial-host-{:016x}", hasher.finish());
    let cache = std::env::temp_dir().join("psa-esp-kernel-host");
    let program = cache.join(&name);
    if program.is_file() {
        return Ok(program);
    }
    // Sources and program under names of this process's own, then renamed
    // into place: processes that compile the same one at once never see a
    // half-written program.
    let work = cache.join(format!("{name}.{}", std::process::id()));
    std::fs::create_dir_all(&work)?;
    std::fs::write(work.join("trial.cu"), KERNEL_SOURCE)?;
    std::fs::write(work.join("host_driver.c"), DRIVER_SOURCE)?;
    let output = Command::new(COMPILER)
        .args(["-std=c99", "-O2", "-ffp-contract=off"])
        .args(&options)
        .arg("-o")
        .arg(work.join("program"))
        .arg(work.join("host_driver.c"))
        .arg("-lm")
        .output()
        .map_err(|e| std::io::Error::new(e.kind(), format!("cannot run the C compiler {COMPILER}: {e}")))?;
    if !output.status.success() {
        let _ = std::fs::remove_dir_all(&work);
        return Err(std::io::Error::other(format!(
            "{COMPILER} failed on trial.cu ({}): {}",
            options.join(" "),
            String::from_utf8_lossy(&output.stderr)
        )));
    }
    std::fs::rename(work.join("program"), &program)?;
    std::fs::remove_dir_all(&work)?;
    Ok(program)
}

/// Flies `batch` with the kernel's code compiled for the host, one trial
/// after another: the GPU's arithmetic on the CPU, for checking the kernel
/// without a GPU.
pub fn fly_on_host(batch: &TrialBatch) -> Result<TrialPoints, PsaError> {
    let count = batch.trials.len();
    let length = |n: usize, what: &str| i32::try_from(n).map_err(|_| failed(format!("too many {what}")));
    let counts = [
        length(count, "trials")?,
        length(batch.neurons.len(), "neurons")?,
        length(batch.networks.len(), "networks")?,
        length(batch.noise.len(), "noise words")?,
    ];
    let mut input = Vec::new();
    input.extend_from_slice(counts.as_bytes());
    input.extend_from_slice(batch.params.as_bytes());
    input.extend_from_slice(batch.neurons.as_bytes());
    input.extend_from_slice(batch.networks.as_bytes());
    input.extend_from_slice(batch.trials.as_bytes());
    input.extend_from_slice(batch.noise.as_bytes());
    let output = run(&program(&batch.specialisation)?, input)?;
    if output.len() != count * 12 {
        return Err(failed(format!("{} bytes of output for {count} trials", output.len())));
    }
    let (points, finite) = output.split_at(count * 8);
    Ok(TrialPoints {
        points: points
            .chunks_exact(8)
            .map(|b| f64::from_ne_bytes(b.try_into().expect("8 bytes")))
            .collect(),
        finite: finite
            .chunks_exact(4)
            .map(|b| i32::from_ne_bytes(b.try_into().expect("4 bytes")))
            .collect(),
    })
}

/// Runs `program` with `input` on its standard input; its standard output.
fn run(program: &Path, input: Vec<u8>) -> Result<Vec<u8>, PsaError> {
    let mut child = Command::new(program)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| failed(format!("cannot run {}: {e}", program.display())))?;
    let mut stdin = child.stdin.take().ok_or_else(|| failed("no standard input"))?;
    // Written from a thread of its own, so that a full output pipe cannot
    // stall the write.
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let output = child.wait_with_output().map_err(failed)?;
    writer
        .join()
        .map_err(|_| failed("the writer panicked"))?
        .map_err(failed)?;
    if !output.status.success() {
        return Err(failed(format!("it ended with {}", output.status)));
    }
    Ok(output.stdout)
}
