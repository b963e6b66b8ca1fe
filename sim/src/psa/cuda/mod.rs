//! The trial kernel of the `cuda` evaluation path and its host side.
//!
//! `trial.cu` flies one trial per thread: the batched `native` kernel
//! ([`super::batch`]) written out in C for one network, operation for
//! operation, in double precision, every `mul_add` an explicit `fma`. It is
//! specialised at compile time ([`Specialisation`]: loop bounds, discrete
//! settings and the exponential's polynomial as constants). NVRTC compiles
//! each specialisation for the GPU with `--fmad=false`; [`host`] compiles
//! the same specialisations with the host C compiler (`-ffp-contract=off`)
//! and [`fly_on_host`] runs them, so the tests hold the kernel's arithmetic
//! to `native` bit for bit on any machine, with or without a GPU.
//!
//! The host draws what the trials need from each network's own stream, in
//! the scalar path's order ([`prepare`]): the random start, then the seed of
//! the noise source, trial by trial; the kernel gets the start, the target
//! and the noise generator's state. A launch carries each distinct hidden
//! neuron once (ESP's networks share their sub-populations' neurons) and
//! each network as a row of neuron indices. [`evaluate_with`] turns the
//! trials' points into each network's fitness and re-runs a network whose
//! flight ended non-finite on the scalar path, which names the error, as
//! the batched path does.

mod device;
pub mod host;

use std::collections::HashMap;

pub use device::{
    compile_for_check, CudaTrials, CudaUnavailable, KernelShape, KERNEL_NAME, KERNEL_SOURCE, THREADS_PER_BLOCK,
};
pub use host::fly_on_host;

use super::settings::readings::READINGS;
use super::trial::{mean_of_trials, TrialRunner};
use super::{PsaError, PsaSettings};
use super::{Task, INPUT_COUNT, THRUSTER_COUNT};
use crate::physics::{BackendKind, PlanarBody, PlanarState};
use esp_neuroevolution::network::{Network, NetworkSet};
use esp_neuroevolution::rng::{expand, Stream};

/// Genes of a hidden neuron: its input weights, then its output weights.
const GENES: usize = INPUT_COUNT + THRUSTER_COUNT;

/// The settings every thread shares, passed to the kernel by value:
/// `PsaParams` of `trial.cu`, field for field.
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
    steps: i32,
    padding: i32,
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
    /// Its network's row in [`TrialBatch::networks`].
    network: i32,
    padding: i32,
}

/// What `trial.cu` is compiled with: the settings that are constants of
/// its code (one compiled kernel per specialisation in use, on the GPU and
/// on the host alike).
#[derive(Debug, Clone, PartialEq)]
pub struct Specialisation {
    /// Hidden neurons a network of the launch has at most (at least 1).
    pub hidden: usize,
    noisy: bool,
    /// Each reading's define and its value ([`READINGS`]' rows with one).
    readings: Vec<(&'static str, bool)>,
    force_support: [i32; THRUSTER_COUNT],
    arm_support: [i32; THRUSTER_COUNT],
    exp_q: Vec<f64>,
    ln2_parts: Vec<f64>,
}

impl Specialisation {
    /// The `-D` options that compile `trial.cu` for this specialisation,
    /// the exponential's coefficients as hexadecimal floating-point
    /// literals, which C and C++ read back to the same bits.
    pub fn defines(&self) -> Vec<String> {
        let flag = |name: &str, on: bool| format!("-D{name}={}", u8::from(on));
        let ints = |values: &[i32]| values.iter().map(i32::to_string).collect::<Vec<_>>().join(",");
        let floats = |values: &[f64]| values.iter().map(|&v| hex_float(v)).collect::<Vec<_>>().join(",");
        let mut defines = vec![format!("-DPSA_HIDDEN={}", self.hidden), flag("PSA_NOISY", self.noisy)];
        defines.extend(self.readings.iter().map(|&(name, on)| flag(name, on)));
        defines.extend([
            format!("-DPSA_FORCE_SUPPORT={}", ints(&self.force_support)),
            format!("-DPSA_ARM_SUPPORT={}", ints(&self.arm_support)),
            format!("-DPSA_EXP_TERMS={}", self.exp_q.len()),
            format!("-DPSA_EXP_Q={}", floats(&self.exp_q)),
            format!("-DPSA_LN2_TERMS={}", self.ln2_parts.len()),
            format!("-DPSA_LN2_PARTS={}", floats(&self.ln2_parts)),
        ]);
        defines
    }

    /// The specialisation's name: its options in one line, the key of a
    /// cache of compiled kernels.
    pub fn key(&self) -> String {
        self.defines().join(" ")
    }
}

/// `value` as a C hexadecimal floating-point literal (`0x1.8p+1` for 3),
/// exactly: every finite double has one, which compilers read back to the
/// same bits.
///
/// # Panics
/// If `value` is not finite.
pub fn hex_float(value: f64) -> String {
    assert!(value.is_finite(), "{value} has no literal");
    let bits = value.to_bits();
    let sign = if bits >> 63 == 1 { "-" } else { "" };
    let exponent = ((bits >> 52) & 0x7ff) as i64;
    let mantissa = bits & ((1 << 52) - 1);
    match (exponent, mantissa) {
        (0, 0) => format!("{sign}0x0p+0"),
        (0, _) => format!("{sign}0x0.{mantissa:013x}p-1022"),
        _ => format!("{sign}0x1.{mantissa:013x}p{:+}", exponent - 1023),
    }
}

/// Everything one launch needs: the shared settings, the specialisation,
/// each distinct active hidden neuron's genes once, each network's row of
/// neuron indices, and the trials, network by network, the settings'
/// `trials` each (with their noise generators' states where noisy).
#[derive(Debug, Clone)]
pub struct TrialBatch {
    /// The shared settings.
    pub params: KernelParams,
    /// What the kernel is compiled with.
    pub specialisation: Specialisation,
    /// The genes of every distinct active hidden neuron, input weights then
    /// output weights, neuron after neuron.
    pub neurons: Vec<f64>,
    /// Each network's row of `specialisation.hidden` indices into
    /// `neurons` (in neurons): its active neurons in order, then -1.
    pub networks: Vec<i32>,
    /// The trials: network `j`'s trial `t` at `j * trials + t`.
    pub trials: Vec<KernelTrial>,
    /// Each trial's noise generator state (4 words), where the settings
    /// have noise; empty where not.
    pub noise: Vec<u64>,
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

impl KernelParams {
    /// The parameters of `settings` (already validated for the task) on
    /// `body`, and the specialisation for networks of at most `hidden`
    /// active hidden neurons.
    pub fn new(
        settings: &PsaSettings,
        body: &PlanarBody,
        hidden: usize,
    ) -> Result<(KernelParams, Specialisation), PsaError> {
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
        let params = KernelParams {
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
            steps,
            padding: 0,
        };
        let specialisation = Specialisation {
            hidden: hidden.max(1),
            noisy: settings.noise.is_active(),
            readings: READINGS
                .iter()
                .filter_map(|row| row.define.map(|define| (define.name, (define.on)(settings))))
                .collect(),
            force_support: std::array::from_fn(|i| t[i].force_support),
            arm_support: std::array::from_fn(|i| t[i].arm_support),
            exp_q: settings.exponential.coefficients().to_vec(),
            ln2_parts: settings.exponential.ln2_parts().to_vec(),
        };
        Ok((params, specialisation))
    }
}

/// Network `j`'s active (not lesioned) hidden neurons.
fn active_neurons<S: NetworkSet + ?Sized>(networks: &S, j: usize) -> impl Iterator<Item = usize> + '_ {
    (0..networks.hidden(j)).filter(move |&k| !networks.is_lesioned(j, k))
}

/// The most active hidden neurons of networks `range` of `networks` (0 for none).
fn widest<S: NetworkSet + ?Sized>(networks: &S, range: std::ops::Range<usize>) -> usize {
    range.map(|j| active_neurons(networks, j).count()).max().unwrap_or(0)
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
    let mut batch = TrialBatch::new(settings, body, widest(networks, range.clone()))?;
    batch.append(settings, task, networks, range, rngs)?;
    Ok(batch)
}

impl TrialBatch {
    /// A batch of no trials yet, with the parameters of `settings` (already
    /// validated for the task) on `body`, for networks of at most `hidden`
    /// active hidden neurons.
    pub fn new(settings: &PsaSettings, body: &PlanarBody, hidden: usize) -> Result<TrialBatch, PsaError> {
        let (params, specialisation) = KernelParams::new(settings, body, hidden)?;
        Ok(TrialBatch {
            params,
            specialisation,
            neurons: Vec::new(),
            networks: Vec::new(),
            trials: Vec::new(),
            noise: Vec::new(),
        })
    }

    /// Adds the neurons, rows and trials of networks `range` of `networks`,
    /// as [`prepare`] makes them, after those already in the batch. A
    /// neuron that several of these networks share (the same genes in
    /// memory, as in ESP's sub-populations) goes in once.
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
        let width = self.specialisation.hidden;
        let mut known: HashMap<*const f64, i32> = HashMap::new();
        for (j, rng) in range.zip(rngs.iter_mut()) {
            let (inputs, outputs) = networks.shape(j);
            TrialRunner::check_shape(inputs, outputs)?;
            let row = i32::try_from(self.networks.len() / width).map_err(|_| too_big("networks"))?;
            let mut active = 0;
            for k in active_neurons(networks, j) {
                let genes = &networks.neuron(j, k)[..GENES];
                let index = match known.get(&genes.as_ptr()) {
                    Some(&index) => index,
                    None => {
                        let index = i32::try_from(self.neurons.len() / GENES).map_err(|_| too_big("neurons"))?;
                        self.neurons.extend_from_slice(genes);
                        known.insert(genes.as_ptr(), index);
                        index
                    }
                };
                self.networks.push(index);
                active += 1;
            }
            if active > width {
                return Err(too_big(&format!("{active} hidden neurons in a batch made for {width}")));
            }
            self.networks.extend(std::iter::repeat_n(-1, width - active));
            for _ in 0..settings.trials {
                let (start, target) = settings.tasks.start_and_target(task, settings.random_init, rng);
                start.validate()?;
                let state = PlanarState::start(&start, settings.physics.start_quaternion);
                self.trials.push(KernelTrial {
                    position: state.position,
                    velocity: state.velocity,
                    quaternion: state.quaternion,
                    omega: state.omega,
                    target: [target.x, target.y, target.heading],
                    network: row,
                    padding: 0,
                });
                let seed = settings.noise.draw_seed(rng);
                if self.specialisation.noisy {
                    self.noise.extend_from_slice(&expand(seed));
                }
            }
        }
        i32::try_from(self.trials.len()).map_err(|_| too_big("trials"))?;
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
    let scores = trial_scores_of_parts(settings, task, parts, fly)?;
    Ok(scores
        .into_iter()
        .map(|part| part.map(|networks| networks.iter().map(|trials| mean_of_trials(trials)).collect()))
        .collect())
}

/// Each trial's score (in % of the theoretical maximum) of `network` on
/// `task`, its trials flown by `fly`: exactly what
/// [`TrialRunner::evaluate_trials`] gives with `rng` (the robustness
/// tests' many trials of one champion in one launch).
pub fn trial_scores_with(
    settings: &PsaSettings,
    task: Task,
    network: &Network,
    rng: &mut Stream,
    fly: impl FnOnce(&TrialBatch) -> Result<TrialPoints, PsaError>,
) -> Result<Vec<f64>, PsaError> {
    let networks = [network];
    let mut parts = [KernelPart {
        networks: &networks[..],
        range: 0..1,
        rngs: std::slice::from_mut(rng),
    }];
    let mut scores = trial_scores_of_parts(settings, task, &mut parts, fly)?
        .pop()
        .expect("one part")?;
    Ok(scores.pop().expect("one network"))
}

/// A part's networks' trial scores, network by network, or its error.
type PartScores = Result<Vec<Vec<f64>>, PsaError>;

/// Each part's networks' trial scores (in % of the theoretical maximum),
/// all parts flown in one flight of `fly`, or the part's own error.
fn trial_scores_of_parts<S: NetworkSet + ?Sized>(
    settings: &PsaSettings,
    task: Task,
    parts: &mut [KernelPart<'_, S>],
    fly: impl FnOnce(&TrialBatch) -> Result<TrialPoints, PsaError>,
) -> Result<Vec<PartScores>, PsaError> {
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
    let hidden = parts.iter().map(|p| widest(p.networks, p.range.clone())).max();
    let mut batch = TrialBatch::new(settings, &body, hidden.unwrap_or(0))?;
    for part in parts.iter_mut() {
        batch.append(settings, task, part.networks, part.range.clone(), part.rngs)?;
    }
    let flown = fly(&batch)?;
    let maximum = settings.fitness.maximum(settings.steps);
    let per = settings.trials;
    let mut first = 0;
    let mut results = Vec::with_capacity(parts.len());
    for (part, positions) in parts.iter_mut().zip(positions) {
        let mut scores = Vec::with_capacity(part.range.len());
        let mut failed = None;
        for (i, j) in part.range.clone().enumerate() {
            let trials = first + i * per..first + (i + 1) * per;
            if flown.finite[trials.clone()].iter().all(|&f| f != 0) {
                scores.push(flown.points[trials].iter().map(|p| 100.0 * p / maximum).collect());
            } else {
                part.rngs[i].set_word_pos(positions[i]);
                let network = part.networks.network(j);
                match TrialRunner::new(settings, task).and_then(|mut r| r.evaluate_trials(&network, &mut part.rngs[i]))
                {
                    Ok(trial_scores) => scores.push(trial_scores),
                    Err(e) => {
                        failed = Some(e);
                        break;
                    }
                }
            }
        }
        first += part.range.len() * per;
        results.push(failed.map_or(Ok(scores), Err));
    }
    Ok(results)
}

/// Flies a [`TrialBatch`] as `trial.cu` says: a GPU ([`CudaTrials`]) or
/// the kernel built for the host ([`HostTrials`]).
pub trait TrialFlier: Send + Sync + std::fmt::Debug {
    /// Each trial's points and whether it ended finite.
    fn fly(&self, batch: &TrialBatch) -> Result<TrialPoints, PsaError>;
    /// [`TrialFlier::fly`], with the kernel's own time in seconds where
    /// the flier measures it (a GPU's events; not the copies).
    fn fly_timed(&self, batch: &TrialBatch) -> Result<(TrialPoints, Option<f64>), PsaError> {
        self.fly(batch).map(|points| (points, None))
    }
    /// What flies them, for the user.
    fn describe(&self) -> String;
    /// Wall time so far with at least one flight under way, where the
    /// flier keeps it (a GPU).
    fn busy(&self) -> Option<std::time::Duration> {
        None
    }
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
    fn fly_timed(&self, batch: &TrialBatch) -> Result<(TrialPoints, Option<f64>), PsaError> {
        CudaTrials::fly_timed(self, batch).map(|(points, seconds)| (points, Some(seconds)))
    }
    fn describe(&self) -> String {
        self.device().to_string()
    }
    fn busy(&self) -> Option<std::time::Duration> {
        Some(CudaTrials::busy(self))
    }
}

#[cfg(test)]
mod tests {
    use super::hex_float;

    #[test]
    fn hex_floats_spell_out_every_bit() {
        assert_eq!(hex_float(1.0), "0x1.0000000000000p+0");
        assert_eq!(hex_float(-3.0), "-0x1.8000000000000p+1");
        assert_eq!(hex_float(0.0), "0x0p+0");
        assert_eq!(hex_float(f64::MIN_POSITIVE), "0x1.0000000000000p-1022");
        assert_eq!(hex_float(f64::from_bits(1)), "0x0.0000000000001p-1022");
        assert_eq!(hex_float(std::f64::consts::LN_2), "0x1.62e42fefa39efp-1");
    }
}
