//! The trial kernel of the `cuda` evaluation path and its host side.
//!
//! `trial.cu` flies one trial per thread: the batched `native` kernel
//! ([`super::batch`]) written out in C for one network, operation for
//! operation, in double precision, every `mul_add` an explicit `fma`.
//! NVRTC compiles it for the GPU with `--fmad=false`; the build compiles the
//! same file with the host C compiler (`-ffp-contract=off`), and
//! [`fly_on_host`] runs it, so the tests hold the kernel's arithmetic to
//! `native` bit for bit on any machine, with or without a GPU.
//!
//! The host draws what the trials need from each network's own stream, in
//! the scalar path's order ([`prepare`]): the random start, then the seed of
//! the noise source, trial by trial; the kernel gets the start, the target
//! and the noise generator's state. [`evaluate_with`] turns the trials'
//! points into each network's fitness and re-runs a network whose flight
//! ended non-finite on the scalar path, which names the error, as the
//! batched path does.

mod device;

pub use device::{compile_for_check, CudaTrials, CudaUnavailable, KERNEL_NAME, KERNEL_SOURCE, THREADS_PER_BLOCK};

use super::trial::{mean_of_trials, PsaError, PsaSettings, TrialRunner};
use super::{FitnessKind, FitnessState, HeadingInput, HeadingWrap, SlowingRule, Task, INPUT_COUNT, THRUSTER_COUNT};
use crate::network::NetworkSet;
use crate::physics::{BackendKind, PlanarBody, PlanarState};
use crate::rng::{expand, Stream};

/// The settings every thread shares: `PsaParams` of `trial.cu`, field for field.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, zerocopy::IntoBytes, zerocopy::Immutable)]
pub struct KernelParams {
    position_scale: f64,
    velocity_scale: f64,
    heading_scale: f64,
    angular_velocity_scale: f64,
    bias: f64,
    input_sd: f64,
    output_sd: f64,
    box_half_width: f64,
    heading_window: f64,
    spin_window: f64,
    position_points: f64,
    heading_points: f64,
    force: [[f64; 2]; THRUSTER_COUNT],
    arm: [[f64; 2]; THRUSTER_COUNT],
    inv_mass: f64,
    inv_inertia_z: f64,
    dt: f64,
    exp_q: [f64; 10],
    ln2_parts: [f64; 2],
    force_support: [i32; THRUSTER_COUNT],
    arm_support: [i32; THRUSTER_COUNT],
    steps: i32,
    noisy: i32,
    incremental: i32,
    signed_slowing: i32,
    exp_terms: i32,
    ln2_terms: i32,
    heading_absolute: i32,
    heading_positive: i32,
    bias_noise: i32,
    fitness_sensed: i32,
}

/// One trial: `PsaTrial` of `trial.cu`, field for field.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, zerocopy::IntoBytes, zerocopy::Immutable)]
pub struct KernelTrial {
    position: [f64; 2],
    velocity: [f64; 2],
    quaternion: [f64; 2],
    omega: f64,
    target: [f64; 3],
    noise_state: [u64; 4],
    weights: i32,
    hidden: i32,
}

/// Everything one launch needs: the shared settings, the networks'
/// weights (the active hidden neurons' genes, network after network) and
/// the trials, network by network, the settings' `trials` each.
#[derive(Debug, Clone)]
pub struct TrialBatch {
    /// The shared settings.
    pub params: KernelParams,
    /// The genes of every active hidden neuron, input weights then output weights.
    pub weights: Vec<f64>,
    /// The trials: network `j`'s trial `t` at `j * trials + t`.
    pub trials: Vec<KernelTrial>,
}

/// The kernel's output for a batch: each trial's points, and whether its
/// velocity and spin ended finite.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialPoints {
    /// Points per trial, in the batch's order.
    pub points: Vec<f64>,
    /// 1 where the flight ended finite, 0 where not.
    pub finite: Vec<i32>,
}

/// `values` at the front of an array of `M` (zeros after): a polynomial
/// or ln 2's parts for the kernel, which reads as many as it is told.
fn padded<const M: usize>(values: &[f64]) -> [f64; M] {
    let mut array = [0.0; M];
    array[..values.len()].copy_from_slice(values);
    array
}

impl KernelParams {
    /// The parameters of `settings` (already validated for the task) on `body`.
    pub fn new(settings: &PsaSettings, body: &PlanarBody) -> Result<KernelParams, PsaError> {
        let constants = body.constants();
        if constants.thrusters.len() != THRUSTER_COUNT {
            return Err(PsaError::Setting(format!(
                "the cuda kernel flies {THRUSTER_COUNT} thrusters, the body has {}",
                constants.thrusters.len()
            )));
        }
        let steps = i32::try_from(settings.steps)
            .map_err(|_| PsaError::Setting(format!("{} steps are too many for the cuda kernel", settings.steps)))?;
        let t = &constants.thrusters;
        let (s, f) = (&settings.sensors, &settings.fitness);
        Ok(KernelParams {
            position_scale: s.position_scale,
            velocity_scale: s.velocity_scale,
            heading_scale: s.heading_scale,
            angular_velocity_scale: s.angular_velocity_scale,
            bias: s.bias,
            input_sd: settings.noise.input_sd,
            output_sd: settings.noise.output_sd,
            box_half_width: f.box_half_width,
            heading_window: f.heading_window,
            spin_window: f.spin_window,
            position_points: f.position_points,
            heading_points: f.heading_points,
            force: std::array::from_fn(|i| t[i].force),
            arm: std::array::from_fn(|i| t[i].arm),
            inv_mass: constants.inv_mass,
            inv_inertia_z: constants.inv_inertia_z,
            dt: constants.dt,
            force_support: std::array::from_fn(|i| t[i].force_support),
            arm_support: std::array::from_fn(|i| t[i].arm_support),
            steps,
            noisy: settings.noise.is_active().into(),
            incremental: (f.kind == FitnessKind::Incremental).into(),
            signed_slowing: (f.slowing == SlowingRule::Signed).into(),
            exp_q: padded(settings.exponential.coefficients()),
            ln2_parts: padded(settings.exponential.ln2_parts()),
            exp_terms: settings.exponential.coefficients().len() as i32,
            ln2_terms: settings.exponential.ln2_parts().len() as i32,
            heading_absolute: (s.heading_input == HeadingInput::Absolute).into(),
            heading_positive: (s.heading_wrap == HeadingWrap::Positive).into(),
            bias_noise: settings.noise.on_bias.into(),
            fitness_sensed: (f.state == FitnessState::Sensed).into(),
        })
    }
}

/// The batch for networks `range` of `networks` on `task`, drawing each
/// trial's start and noise seed from `rngs[i]` for network `range.start + i`
/// in the scalar path's order.
///
/// # Panics
/// If `range` and `rngs` differ in length.
pub fn prepare<S: NetworkSet + ?Sized>(
    settings: &PsaSettings,
    body: &PlanarBody,
    task: Task,
    networks: &S,
    range: std::ops::Range<usize>,
    rngs: &mut [Stream],
) -> Result<TrialBatch, PsaError> {
    let mut batch = TrialBatch::new(settings, body)?;
    batch.append(settings, task, networks, range, rngs)?;
    Ok(batch)
}

impl TrialBatch {
    /// A batch of no trials yet, with the parameters of `settings` (already
    /// validated for the task) on `body`.
    pub fn new(settings: &PsaSettings, body: &PlanarBody) -> Result<TrialBatch, PsaError> {
        Ok(TrialBatch {
            params: KernelParams::new(settings, body)?,
            weights: Vec::new(),
            trials: Vec::new(),
        })
    }

    /// Adds the weights and trials of networks `range` of `networks`, as
    /// [`prepare`] makes them, after those already in the batch.
    ///
    /// # Panics
    /// If `range` and `rngs` differ in length.
    pub fn append<S: NetworkSet + ?Sized>(
        &mut self,
        settings: &PsaSettings,
        task: Task,
        networks: &S,
        range: std::ops::Range<usize>,
        rngs: &mut [Stream],
    ) -> Result<(), PsaError> {
        assert_eq!(range.len(), rngs.len(), "one stream per network");
        let too_big = |what: &str| PsaError::Setting(format!("the cuda kernel's batch is too large ({what})"));
        for (j, rng) in range.zip(rngs.iter_mut()) {
            let (inputs, outputs) = networks.shape(j);
            TrialRunner::check_shape(inputs, outputs)?;
            let offset = i32::try_from(self.weights.len()).map_err(|_| too_big("weights"))?;
            let mut hidden: usize = 0;
            for k in (0..networks.hidden(j)).filter(|&k| !networks.is_lesioned(j, k)) {
                self.weights
                    .extend_from_slice(&networks.neuron(j, k)[..INPUT_COUNT + THRUSTER_COUNT]);
                hidden += 1;
            }
            let hidden = i32::try_from(hidden).map_err(|_| too_big("hidden neurons"))?;
            for _ in 0..settings.trials {
                let (start, target) = settings.tasks.start_and_target(task, settings.random_init, rng);
                start.validate()?;
                let state = PlanarState::from_body_state(&start);
                self.trials.push(KernelTrial {
                    position: state.position,
                    velocity: state.velocity,
                    quaternion: state.quaternion,
                    omega: state.omega,
                    target: [target.x, target.y, target.heading],
                    noise_state: expand(settings.noise.draw_seed(rng)),
                    weights: offset,
                    hidden,
                });
            }
        }
        Ok(())
    }
}

/// The fitness of networks `range` of `networks` on `task`, in % of the
/// theoretical maximum, their trials flown by `fly` (the host build,
/// [`fly_on_host`], or a GPU): exactly what [`TrialRunner::evaluate`]
/// gives network `range.start + i` with stream `rngs[i]`, as long as `fly`
/// computes what `trial.cu` says. A network with a non-finite flight is
/// re-run on the scalar path from where its stream stood, which reports
/// the error.
///
/// # Panics
/// If `range` and `rngs` differ in length.
pub fn evaluate_with<S: NetworkSet + ?Sized>(
    settings: &PsaSettings,
    task: Task,
    networks: &S,
    range: std::ops::Range<usize>,
    rngs: &mut [Stream],
    fly: impl FnOnce(&TrialBatch) -> Result<TrialPoints, PsaError>,
) -> Result<Vec<f64>, PsaError> {
    let mut parts = [KernelPart { networks, range, rngs }];
    evaluate_parts_with(settings, task, &mut parts, fly)?
        .pop()
        .expect("one part")
}

/// Networks `range` of `networks`, network `range.start + i` with stream
/// `rngs[i]`: one part of [`evaluate_parts_with`].
pub struct KernelPart<'a, S: ?Sized> {
    /// The networks.
    pub networks: &'a S,
    /// Which of them.
    pub range: std::ops::Range<usize>,
    /// Their streams.
    pub rngs: &'a mut [Stream],
}

/// [`evaluate_with`] for several parts in one flight of `fly` (one GPU
/// launch): each part's fitness, or its own error (a part's network whose
/// flight ended non-finite fails that part only); an error of the settings
/// or of the flight fails them all.
///
/// # Panics
/// If a part's range and streams differ in length.
pub fn evaluate_parts_with<S: NetworkSet + ?Sized>(
    settings: &PsaSettings,
    task: Task,
    parts: &mut [KernelPart<'_, S>],
    fly: impl FnOnce(&TrialBatch) -> Result<TrialPoints, PsaError>,
) -> Result<Vec<Result<Vec<f64>, PsaError>>, PsaError> {
    let settings = &settings.for_task(task)?;
    if settings.backend != BackendKind::Native {
        return Err(PsaError::Setting(format!(
            "the cuda kernel repeats the native backend's physics only, not {}",
            settings.backend
        )));
    }
    let body = PlanarBody::new(&settings.body.model()?, &settings.physics)?;
    let positions: Vec<Vec<u128>> = parts
        .iter()
        .map(|p| p.rngs.iter().map(|r| r.get_word_pos()).collect())
        .collect();
    let mut batch = TrialBatch::new(settings, &body)?;
    for part in parts.iter_mut() {
        batch.append(settings, task, part.networks, part.range.clone(), part.rngs)?;
    }
    let flown = fly(&batch)?;
    let maximum = settings.fitness.maximum(settings.steps);
    let per = settings.trials;
    let mut first = 0;
    let mut results = Vec::with_capacity(parts.len());
    for (part, positions) in parts.iter_mut().zip(positions) {
        let mut fitness = Vec::with_capacity(part.range.len());
        let mut failed = None;
        for (i, j) in part.range.clone().enumerate() {
            let trials = first + i * per..first + (i + 1) * per;
            if flown.finite[trials.clone()].iter().all(|&f| f != 0) {
                let scores: Vec<f64> = flown.points[trials].iter().map(|p| 100.0 * p / maximum).collect();
                fitness.push(mean_of_trials(&scores));
            } else {
                part.rngs[i].set_word_pos(positions[i]);
                let network = part.networks.network(j);
                match TrialRunner::new(settings, task).and_then(|mut r| r.evaluate(&network, &mut part.rngs[i])) {
                    Ok(f) => fitness.push(f),
                    Err(e) => {
                        failed = Some(e);
                        break;
                    }
                }
            }
        }
        first += part.range.len() * per;
        results.push(failed.map_or(Ok(fitness), Err));
    }
    Ok(results)
}

/// Flies a [`TrialBatch`] as `trial.cu` says: a GPU ([`CudaTrials`]) or
/// the kernel built for the host ([`HostTrials`]).
pub trait TrialFlier: Send + Sync + std::fmt::Debug {
    /// Each trial's points and whether it ended finite.
    fn fly(&self, batch: &TrialBatch) -> Result<TrialPoints, PsaError>;
    /// What flies them, for the user.
    fn describe(&self) -> String;
}

/// The kernel built for the host ([`fly_on_host`]) as a [`TrialFlier`]:
/// the GPU path's plumbing, exactly, on any machine (slowly: one trial
/// after another).
#[derive(Debug, Clone, Copy, Default)]
pub struct HostTrials;

impl TrialFlier for HostTrials {
    fn fly(&self, batch: &TrialBatch) -> Result<TrialPoints, PsaError> {
        fly_on_host(batch)
    }
    fn describe(&self) -> String {
        "the cuda kernel built for the host (psa-trial-host)".into()
    }
}

impl TrialFlier for CudaTrials {
    fn fly(&self, batch: &TrialBatch) -> Result<TrialPoints, PsaError> {
        CudaTrials::fly(self, batch)
    }
    fn describe(&self) -> String {
        self.device().to_string()
    }
}

/// Flies `batch` with the kernel's code compiled for the host
/// (`psa-trial-host`, built by `build.rs`), one trial after another: the
/// GPU's arithmetic on the CPU, for checking the kernel without a GPU.
pub fn fly_on_host(batch: &TrialBatch) -> Result<TrialPoints, PsaError> {
    use std::io::Write;
    use std::process::{Command, Stdio};
    use zerocopy::IntoBytes;
    let count = batch.trials.len();
    let failed = |why: String| PsaError::Setting(format!("the host build of the cuda kernel: {why}"));
    let header = [
        i32::try_from(count).map_err(|_| failed(format!("{count} trials are too many")))?,
        i32::try_from(batch.weights.len()).map_err(|_| failed("too many weights".into()))?,
    ];
    let mut input = Vec::new();
    input.extend_from_slice(header.as_bytes());
    input.extend_from_slice(batch.params.as_bytes());
    input.extend_from_slice(batch.weights.as_bytes());
    input.extend_from_slice(batch.trials.as_bytes());
    let mut child = Command::new(env!("PSA_ESP_TRIAL_HOST"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| failed(e.to_string()))?;
    let mut stdin = child.stdin.take().ok_or_else(|| failed("no standard input".into()))?;
    // Written from a thread of its own, so that a full output pipe cannot
    // stall the write.
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let output = child.wait_with_output().map_err(|e| failed(e.to_string()))?;
    writer
        .join()
        .map_err(|_| failed("the writer panicked".into()))?
        .map_err(|e| failed(e.to_string()))?;
    if !output.status.success() || output.stdout.len() != count * 12 {
        return Err(failed(format!("it ended with {}", output.status)));
    }
    let (points, finite) = output.stdout.split_at(count * 8);
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
