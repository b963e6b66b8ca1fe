//! `bench`'s rows for the cuda path's trial kernel: ns per network-step on
//! the GPU (the kernel alone, by CUDA events, and a launch end to end with
//! its copies) beside the `native` batched path, at several networks per
//! launch (400, one generation of one run; 4,000; 312,000, one generation
//! of every run of the paper grid).

use std::time::Instant;

use anyhow::Result;
use serde::Serialize;

use super::bench_networks::random_networks;
use super::bench_runs::median;
use esp_neuroevolution::network::Network;
use psa_sim::physics::{BackendKind, PlanarBody};
use psa_sim::psa::cuda::{prepare, CudaTrials, HostTrials, TrialFlier};
use psa_sim::psa::{BatchRunner, PsaSettings, Task};

/// Networks the `native` column flies at most.
pub const NATIVE_NETWORKS: usize = 4_000;

/// Networks per launch of the kernel rows, by default.
pub const KERNEL_NETWORKS: [u64; 3] = [400, 4_000, 312_000];

/// One size of the kernel rows.
#[derive(Debug, Clone, Serialize)]
pub struct KernelTiming {
    /// Networks per launch.
    pub networks: u64,
    /// ns per network-step of the kernel alone (the median round; CUDA
    /// events around the launch), where the flier times it (a GPU; not the
    /// host build).
    pub kernel_ns_per_network_step: Option<f64>,
    /// ns per network-step of one launch end to end (the median round):
    /// the copies in and out, the launch and the wait included.
    pub end_to_end_ns_per_network_step: f64,
    /// ns per network-step on the `native` batched path, 1 thread, of the
    /// same networks (the first [`NATIVE_NETWORKS`] of them: one thread's
    /// rate does not depend on how many there are).
    pub native_ns_per_network_step: f64,
}

/// The kernel rows, or why they could not be measured.
#[derive(Debug, Clone, Serialize)]
pub struct KernelBench {
    /// What flew the trials (the GPU, or the host build with `--kernel-host`).
    pub device: String,
    /// One row per size; empty where `unavailable` says why.
    pub rows: Vec<KernelTiming>,
    /// Why there is no GPU, where there is none.
    pub unavailable: Option<String>,
}

/// The kernel built for the host where `on_host` (to exercise these rows
/// without a GPU), else the GPU, or why there is none.
fn flier(on_host: bool) -> std::result::Result<Box<dyn TrialFlier>, String> {
    if on_host {
        return Ok(Box::new(HostTrials));
    }
    CudaTrials::open()
        .map(|gpu| Box::new(gpu) as Box<dyn TrialFlier>)
        .map_err(|e| e.to_string())
}

/// Times the kernel and `native` at each of `sizes` networks per launch,
/// `rounds` rounds each (the median is kept). Without a GPU, no row, and
/// the reason. `on_host`: the kernel built for the host stands in for the GPU.
pub fn kernel_rows(sizes: &[u64], rounds: u64, on_host: bool) -> Result<KernelBench> {
    let flier = match flier(on_host) {
        Ok(flier) => flier,
        Err(why) => {
            return Ok(KernelBench {
                device: "none".into(),
                rows: Vec::new(),
                unavailable: Some(why),
            })
        }
    };
    let settings = PsaSettings {
        backend: BackendKind::Native,
        ..PsaSettings::default()
    };
    let task = Task::StopRotation;
    let body = PlanarBody::new(&settings.body.model()?, &settings.physics)?;
    // The batched path itself, as the kernel rows compare against it.
    let native = BatchRunner::new(&settings, task)?;
    let mut rows = Vec::new();
    for &size in sizes {
        let networks = random_networks(size)?;
        let refs: Vec<&Network> = networks.iter().collect();
        let network_steps = (size as usize * settings.steps * settings.trials) as f64;
        let (mut kernel, mut end_to_end, mut cpu) = (Vec::new(), Vec::new(), Vec::new());
        for round in 0..rounds {
            let mut streams: Vec<_> = (0..networks.len())
                .map(|j| esp_neuroevolution::rng::stream(round, &[j as u64]))
                .collect();
            let batch = prepare(&settings, &body, task, &refs[..], 0..refs.len(), &mut streams.clone())?;
            let start = Instant::now();
            let (_, kernel_seconds) = flier.fly_timed(&batch)?;
            end_to_end.push(start.elapsed().as_secs_f64() * 1e9 / network_steps);
            kernel.extend(kernel_seconds.map(|s| s * 1e9 / network_steps));
            let flown = refs.len().min(NATIVE_NETWORKS);
            let start = Instant::now();
            native.evaluate(&refs[..], 0..flown, &mut streams[..flown])?;
            cpu.push(start.elapsed().as_secs_f64() * 1e9 / (network_steps * flown as f64 / refs.len() as f64));
        }
        rows.push(KernelTiming {
            networks: size,
            kernel_ns_per_network_step: (!kernel.is_empty()).then(|| median(kernel)),
            end_to_end_ns_per_network_step: median(end_to_end),
            native_ns_per_network_step: median(cpu),
        });
    }
    Ok(KernelBench {
        device: flier.describe(),
        rows,
        unavailable: None,
    })
}
