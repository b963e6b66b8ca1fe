//! The batched evaluation path: blocks of [`LANES`] networks (and of
//! [`NARROW_LANES`] or [`SMALL_LANES`] for what is left over) fly the PSA in
//! lockstep, one per SIMD lane, on the `native` backend's physics.
//!
//! Weights and states are kept as structures of arrays ([`Lanes`]), and every
//! step runs the arithmetic the scalar path ([`TrialRunner`] with the
//! `native` backend) runs, operation for operation, but for two that
//! cannot change a value (clamping noiseless outputs that lie in [0, 1]
//! already, and a NaN check per step, made once per flight instead; see
//! `fly`): the shared generic
//! functions of [`crate::numeric`], [`PlanarBody::step`],
//! [`SensorSettings::inputs_from`](super::SensorSettings::inputs_from) and
//! [`FitnessSettings::points`](super::FitnessSettings::points), and the
//! network's summation order (see
//! [`Network::activate`](esp_neuroevolution::network::Network::activate)). So a
//! network's fitness is bit-identical on both paths and on every
//! [`SimdLevel`]; the tests hold the paths to that on thousands of random
//! networks. The weights are read in place from any [`NetworkSet`], such
//! as ESP's sub-populations.
//!
//! Random starts and the seeds of the noise sources are drawn lane by lane
//! from each network's own stream, in the scalar path's order; the noise
//! itself comes from one [`NoiseSource`] per lane, generated in SIMD by a
//! function of its own for each width and level ([`OutOfLine`]). A lane
//! whose thrust turns NaN (only possible with absurd settings, such as an
//! input scale that overflows) is re-run on the scalar path, which reports
//! the error it raises.

use multiversion::multiversion;

use super::step::{score, sense, Reading};
use super::trial::{mean_of_trials, TrialRunner};
use super::{PsaError, PsaSettings};
use super::{Task, INPUT_COUNT, THRUSTER_COUNT};
use std::ops::Range;

use crate::numeric::{
    clamp_unit, sigmoid_with, Exponential, Float, LaneMask, Lanes, NoiseSource, Normals, OutOfLine, Real, SimdLevel,
    Words,
};
use crate::physics::{BackendKind, PlanarBody, PlanarState};
use esp_neuroevolution::network::{Network, NetworkSet};
use esp_neuroevolution::rng::Stream;

/// Networks evaluated in lockstep by one call of the kernel: four AVX-512
/// registers per value, enough independent work to hide the latency of the
/// long dependency chain of one step.
pub const LANES: usize = 32;
/// AVX-512's width for the last few networks of a batch (at most this
/// many): two AVX-512 registers per value. On the baseline ESP's 400
/// networks a generation (12 wide blocks and 16 left), measured 6 % faster
/// overall than 8 lanes.
pub const NARROW_LANES: usize = 16;
/// AVX2's width for the last few networks of a batch (two AVX2 registers
/// per value), and the portable build's only width. On two threads that
/// both reach the tail, the 16 networks left of the baseline ESP's 400 go
/// one piece of 8 to each thread; in a block of 16, half of its lanes
/// would fly for nothing.
pub const SMALL_LANES: usize = 8;

/// The weights of a block of networks, lane by lane. Lesioned hidden
/// neurons, and the missing neurons of networks smaller than the block's
/// largest, get zero weights: they add exactly +0 to every output.
struct BlockWeights<const N: usize> {
    hidden: usize,
    /// Input weights of hidden neuron k: `input[k * INPUT_COUNT..][..INPUT_COUNT]`.
    input: Vec<Lanes<N>>,
    /// Output weights of hidden neuron k: `output[k * THRUSTER_COUNT..][..THRUSTER_COUNT]`.
    output: Vec<Lanes<N>>,
}

impl<const N: usize> BlockWeights<N> {
    /// The weights of network `lanes[l]` of `networks` in lane `l` (a
    /// block of networks, or one network in every lane).
    fn new<S: NetworkSet + ?Sized>(networks: &S, lanes: impl Iterator<Item = usize> + Clone) -> BlockWeights<N> {
        let hidden = lanes.clone().map(|j| networks.hidden(j)).max().unwrap_or(0);
        let mut input = vec![Lanes::splat(0.0); hidden * INPUT_COUNT];
        let mut output = vec![Lanes::splat(0.0); hidden * THRUSTER_COUNT];
        for (lane, j) in lanes.enumerate() {
            for k in (0..networks.hidden(j)).filter(|&k| !networks.is_lesioned(j, k)) {
                let (w_in, w_out) = networks.neuron(j, k).split_at(INPUT_COUNT);
                for (i, &w) in w_in.iter().enumerate() {
                    input[k * INPUT_COUNT + i][lane] = w;
                }
                for (o, &w) in w_out.iter().enumerate() {
                    output[k * THRUSTER_COUNT + o][lane] = w;
                }
            }
        }
        BlockWeights { hidden, input, output }
    }
}

/// The pieces of a kernel's step that it calls instead of inlining them,
/// each compiled apart for the kernel's SIMD level (`kernel!`): the flight
/// that inlined them (five copies of the logistic function with both
/// exponentials, the Box-Muller transform on every lane in the sensors and
/// the thrusters) made `psa-sim` take 110 s to compile instead of 71 s, and
/// ran no faster (docs/performance.md, "Building"). Every lane goes through exactly the
/// operations it went through inlined.
struct Parts<const N: usize, const NG: usize> {
    /// The logistic function ([`sigmoid_with`]) on a block of `N` lanes.
    single: fn(Lanes<N>, Exponential) -> Lanes<N>,
    /// The logistic function on a group of `NG` lanes.
    group: fn(Lanes<NG>, Exponential) -> Lanes<NG>,
    /// The noise generator's next pair of normal numbers on every lane
    /// ([`OutOfLine`]), for the noise on the sensors and the thrusters.
    pair: fn(&mut NoiseSource<Words<N>>) -> (Lanes<N>, Lanes<N>),
}

/// Everything one trial of a block needs.
struct Flight<'a, const N: usize> {
    settings: &'a PsaSettings,
    body: &'a PlanarBody,
    weights: &'a BlockWeights<N>,
}

/// One trial of every lane from `state` towards `target` (x, y, heading),
/// with lane l's noise from lane l of `noise` if `NOISY` (compiled apart, so
/// that the noise code costs noiseless flights nothing). Returns the points
/// and which lanes ended with a finite velocity and spin. The logistic
/// functions run `G` neurons at a time, as one block of `NG = G N` lanes:
/// `G = 2` in pairs ([`sigmoid_pair`]), `G >= 4` the hidden neurons in groups
/// of `G` and the four outputs in one group ([`sigmoid_group`]), `G = 1`
/// one by one, each through `parts`. Measured on Zen 5: pairs are faster
/// in the wide AVX-512 kernel and slower on AVX2, which has half as many registers; groups of
/// five made the narrow AVX-512 kernel 16-20 % faster (`psa-esp bench
/// --networks 16`, two runs).
///
/// A lane whose thrust turned NaN is always among those that did not: a NaN
/// command makes its thruster's world-frame force NaN (`PlanarBody` keeps
/// every product of a force that is not axis-aligned, a zero one
/// included), and from then on the velocity and the spin stay NaN. So
/// checking them once, after the flight, finds every such lane (and,
/// conservatively, any lane whose state overflowed), without a check per
/// step.
// Plain index loops over constant ranges in the kernel: a scratch build
// that built these arrays with closures and iterator adaptors ran several
// times slower.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn fly<const N: usize, const NG: usize, const G: usize, const NOISY: bool>(
    flight: &Flight<N>,
    state: &mut PlanarState<Lanes<N>>,
    target: &[Lanes<N>; 3],
    noise: &mut NoiseSource<Words<N>>,
    parts: &Parts<N, NG>,
) -> (Lanes<N>, LaneMask<N>) {
    type V<const N: usize> = Lanes<N>;
    assert!(G <= 2 || G >= THRUSTER_COUNT, "groups hold all four outputs");
    let s = flight.settings;
    let weights = flight.weights;
    let e = s.exponential;
    let zero = V::<N>::splat(0.0);
    let mut points = zero;
    // One call of the sensors (and of their noise) in the loop, not two:
    // each call is a copy of the inlined sensor and noise code, and the
    // copies were much of the noisy kernels' compile time. Step `step`
    // reads the state it starts from and scores the step before it.
    let mut before: Option<Reading<V<N>>> = None;
    let mut previous_omega = zero;
    let noise = &mut OutOfLine {
        source: noise,
        pair: parts.pair,
    };
    for step in 0..=s.steps {
        let reading = read_sensors::<N, NOISY>(s, state, target, noise);
        if let Some(before) = &before {
            points = points
                + score(
                    s.step(),
                    &reading,
                    before,
                    state.position,
                    state.omega,
                    previous_omega,
                    *target,
                );
        }
        if step == s.steps {
            break;
        }
        let inputs = reading.inputs;
        let mut outputs = [zero; THRUSTER_COUNT];
        let (paired, grouped) = (G == 2, G >= THRUSTER_COUNT);
        let mut k = 0;
        while paired && k + 2 <= weights.hidden {
            let [h0, h1] =
                sigmoid_pair::<N, NG>(dot(weights, &inputs, k), dot(weights, &inputs, k + 1), parts.group, e);
            accumulate(weights, &mut outputs, h0, k);
            accumulate(weights, &mut outputs, h1, k + 1);
            k += 2;
        }
        while grouped && k + G <= weights.hidden {
            let mut net = [zero; G];
            for i in 0..G {
                net[i] = dot(weights, &inputs, k + i);
            }
            let h = sigmoid_group::<N, NG, G>(&net, parts.group, e);
            for i in 0..G {
                accumulate(weights, &mut outputs, h[i], k + i);
            }
            k += G;
        }
        for k in k..weights.hidden {
            let h = (parts.single)(dot(weights, &inputs, k), e);
            accumulate(weights, &mut outputs, h, k);
        }
        if paired {
            let [o0, o1] = sigmoid_pair::<N, NG>(outputs[0], outputs[1], parts.group, e);
            let [o2, o3] = sigmoid_pair::<N, NG>(outputs[2], outputs[3], parts.group, e);
            outputs = [o0, o1, o2, o3];
        } else if grouped {
            // All four outputs in one group, padded with zeros.
            let mut net = [zero; G];
            net[..THRUSTER_COUNT].copy_from_slice(&outputs);
            let o = sigmoid_group::<N, NG, G>(&net, parts.group, e);
            outputs.copy_from_slice(&o[..THRUSTER_COUNT]);
        } else {
            for o in &mut outputs {
                *o = (parts.single)(*o, e);
            }
        }
        // The logistic function's values lie in [0, 1] already (1 / (1 + e)
        // with e > 0): clamping changes them only after noise.
        if NOISY {
            s.noise.perturb_outputs(&mut outputs, noise);
            for o in &mut outputs {
                *o = clamp_unit(*o);
            }
        }
        previous_omega = state.omega;
        flight.body.step(state, &outputs);
        before = Some(reading);
    }
    let finite = |v: V<N>| v.abs().le(V::<N>::splat(f64::MAX));
    (
        points,
        finite(state.velocity[0]) & finite(state.velocity[1]) & finite(state.omega),
    )
}

/// The logistic function of two blocks at once, as one block of `N2 = 2 N`
/// lanes: the two evaluations are independent dependency chains, so running
/// them side by side keeps the SIMD units busy while each waits on its
/// exponential and division. Every lane goes through exactly the operations
/// of [`sigmoid_with`], so the values are those of two separate calls. (`N2` is a
/// parameter only because stable Rust cannot write `Lanes<{ 2 * N }>` in
/// generic code.)
#[inline(always)]
fn sigmoid_pair<const N: usize, const N2: usize>(
    a: Lanes<N>,
    b: Lanes<N>,
    logistic: fn(Lanes<N2>, Exponential) -> Lanes<N2>,
    e: Exponential,
) -> [Lanes<N>; 2] {
    assert_eq!(N2, 2 * N, "a pair is two blocks wide");
    let mut both = Lanes::<N2>::splat(0.0);
    both.0[..N].copy_from_slice(&a.0);
    both.0[N..].copy_from_slice(&b.0);
    let both = logistic(both, e);
    let (mut first, mut second) = (Lanes::<N>::splat(0.0), Lanes::<N>::splat(0.0));
    first.0.copy_from_slice(&both.0[..N]);
    second.0.copy_from_slice(&both.0[N..]);
    [first, second]
}

/// [`sigmoid_pair`] for `G` blocks, as one block of `NG = G N` lanes.
#[allow(clippy::needless_range_loop)] // as in `fly`
#[inline(always)]
fn sigmoid_group<const N: usize, const NG: usize, const G: usize>(
    blocks: &[Lanes<N>; G],
    logistic: fn(Lanes<NG>, Exponential) -> Lanes<NG>,
    e: Exponential,
) -> [Lanes<N>; G] {
    assert_eq!(NG, G * N, "a group is G blocks wide");
    let mut all = Lanes::<NG>::splat(0.0);
    for i in 0..G {
        all.0[i * N..(i + 1) * N].copy_from_slice(&blocks[i].0);
    }
    let all = logistic(all, e);
    let mut out = *blocks;
    for i in 0..G {
        out[i].0.copy_from_slice(&all.0[i * N..(i + 1) * N]);
    }
    out
}

/// Hidden neuron `k`'s net input: its weighted sum of the inputs, multiplied
/// and added in input order (the scalar network's order).
#[inline(always)]
fn dot<const N: usize>(weights: &BlockWeights<N>, inputs: &[Lanes<N>; INPUT_COUNT], k: usize) -> Lanes<N> {
    let w_in = &weights.input[k * INPUT_COUNT..][..INPUT_COUNT];
    let mut activation = w_in[0] * inputs[0];
    for i in 1..INPUT_COUNT {
        activation = w_in[i].mul_add(inputs[i], activation);
    }
    activation
}

/// Adds hidden neuron `k`'s output `h`, times its output weights, to the
/// outputs' net inputs. Called in neuron order, so each output sums in the
/// scalar network's order.
#[inline(always)]
fn accumulate<const N: usize>(
    weights: &BlockWeights<N>,
    outputs: &mut [Lanes<N>; THRUSTER_COUNT],
    h: Lanes<N>,
    k: usize,
) {
    let w_out = &weights.output[k * THRUSTER_COUNT..][..THRUSTER_COUNT];
    for (o, &w) in outputs.iter_mut().zip(w_out) {
        *o = h.mul_add(w, *o);
    }
}

/// What the sensors read of every lane's `state` against `target`, with
/// noise if `NOISY`. A function inlined by force, not a closure: a closure
/// is compiled without the kernel's target features when it is not
/// inlined, and then each of its `mul_add`s calls a software `fma` (89 %
/// of a noisy flight's time on AVX-512 before this was a function).
#[inline(always)]
fn read_sensors<const N: usize, const NOISY: bool>(
    settings: &PsaSettings,
    state: &PlanarState<Lanes<N>>,
    target: &[Lanes<N>; 3],
    noise: &mut impl Normals<Lanes<N>>,
) -> Reading<Lanes<N>> {
    sense::<Lanes<N>, NOISY>(
        settings.step(),
        state.position,
        state.velocity,
        state.heading(),
        state.omega,
        *target,
        noise,
    )
}

/// `fn $name(..) -> .. $body`, compiled for the `multiversion` target
/// `$target` when given (`[$target]`), else (`[]`) for the build's baseline
/// (the portable kernel and its parts).
///
/// `multiversion` compiles a target's function twice: for the target, and
/// as a fallback for processors without its features. A target's kernel
/// and its parts are only ever called on a processor that has the target
/// ([`BatchRunner::each_block`] runs the portable kernels where the level
/// asked for is missing), so the fallback is `unreachable!`: not another
/// copy of the whole flight for baseline x86-64.
macro_rules! part {
    ([$target:tt], fn $name:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty $body:block) => {
        #[multiversion(targets($target))]
        fn $name($($arg: $ty),*) -> $ret {
            multiversion::target::match_target! {
                $target => $body,
                _ => {
                    let _ = ($($arg),*);
                    unreachable!("{} compiled for {} called on a processor without it", stringify!($name), $target)
                }
            }
        }
    };
    ([], fn $name:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty $body:block) => {
        fn $name($($arg: $ty),*) -> $ret $body
    };
}

/// The kernel `run` of width `$n` for the target `$target` (`[]`: the
/// baseline), with noise if `$noisy`, evaluating the neurons' logistic
/// functions `$group` neurons at a time (see [`fly`]), and the [`Parts`]
/// it calls, each compiled for the same target.
macro_rules! kernel {
    ($target:tt, $n:expr, $group:expr, $noisy:expr) => {
        part!(
            $target,
            fn single(x: Lanes<{ $n }>, e: Exponential) -> Lanes<{ $n }> {
                sigmoid_with(x, e)
            }
        );
        part!(
            $target,
            fn group(x: Lanes<{ $group * $n }>, e: Exponential) -> Lanes<{ $group * $n }> {
                sigmoid_with(x, e)
            }
        );
        part!(
            $target,
            fn pair(source: &mut NoiseSource<Words<{ $n }>>) -> (Lanes<{ $n }>, Lanes<{ $n }>) {
                source.normal_pair()
            }
        );
        part!(
            $target,
            fn run(
                flight: &Flight<{ $n }>,
                state: &mut PlanarState<Lanes<{ $n }>>,
                target: &[Lanes<{ $n }>; 3],
                noise: &mut NoiseSource<Words<{ $n }>>,
            ) -> (Lanes<{ $n }>, LaneMask<{ $n }>) {
                let parts = Parts { single, group, pair };
                fly::<{ $n }, { $group * $n }, { $group }, { $noisy }>(flight, state, target, noise, &parts)
            }
        );
    };
}

/// The kernels of width `$n` (noisy or not), as a module `$module`: for
/// AVX-512 (the logistic functions `$g512` neurons at a time), AVX2
/// (`$g256`) and the portable build (one at a time), each only where a
/// level uses the width ([`BatchRunner::each_block`]). Every kernel is a
/// large function of its own, and the kernels are most of the crate's
/// compile time (docs/performance.md, "Building").
macro_rules! kernels {
    ($module:ident, $n:expr, $noisy:expr, [$(avx512 $g512:expr)?], [$(avx2 $g256:expr)?], [$(portable $portable:ident)?], $avx512:tt, $avx2:tt) => {
        mod $module {
            use super::*;

            // A module each, so that each kernel gets a codegen unit of
            // its own: the two of a width in one unit were compiled one
            // after the other, on the build's critical path.
            $(pub(super) mod avx512 {
                use super::*;
                kernel!([$avx512], $n, $g512, $noisy);
                pub(in super::super) const RUN: Kernel<{ $n }> = run;
            })?
            $(pub(super) mod avx2 {
                use super::*;
                kernel!([$avx2], $n, $g256, $noisy);
                pub(in super::super) const RUN: Kernel<{ $n }> = run;
            })?
            $(pub(super) mod $portable {
                use super::*;
                kernel!([], $n, 1, $noisy);
                pub(in super::super) const RUN: Kernel<{ $n }> = run;
            })?
        }
    };
}

crate::with_simd_targets!(kernels!(wide, LANES, false, [avx512 2], [avx2 1], [],));
crate::with_simd_targets!(kernels!(wide_noisy, LANES, true, [avx512 2], [avx2 1], [],));
crate::with_simd_targets!(kernels!(narrow, NARROW_LANES, false, [avx512 5], [], [],));
crate::with_simd_targets!(kernels!(narrow_noisy, NARROW_LANES, true, [avx512 5], [], [],));
crate::with_simd_targets!(kernels!(small, SMALL_LANES, false, [], [avx2 1], [portable portable],));
crate::with_simd_targets!(kernels!(small_noisy, SMALL_LANES, true, [], [avx2 1], [portable portable],));

/// A kernel of width N.
type Kernel<const N: usize> =
    fn(&Flight<N>, &mut PlanarState<Lanes<N>>, &[Lanes<N>; 3], &mut NoiseSource<Words<N>>) -> (Lanes<N>, LaneMask<N>);

/// The kernel `clean`, or `noisy` where the settings have noise.
fn pick<const N: usize>(noisy: bool, clean: Kernel<N>, with_noise: Kernel<N>) -> Kernel<N> {
    if noisy {
        with_noise
    } else {
        clean
    }
}

/// Evaluates networks on one task in blocks of [`LANES`], on the `native`
/// backend's physics, with the best [`SimdLevel`] of the CPU.
#[derive(Debug, Clone)]
pub struct BatchRunner {
    settings: PsaSettings,
    task: Task,
    body: PlanarBody,
    level: SimdLevel,
}

impl BatchRunner {
    /// A runner for `task`; fails on invalid settings, or when the settings
    /// name a backend other than `native` (the batched path simulates
    /// `native`'s physics only).
    pub fn new(settings: &PsaSettings, task: Task) -> Result<BatchRunner, PsaError> {
        let settings = &settings.for_task(task)?;
        if settings.backend != BackendKind::Native {
            return Err(PsaError::Setting(format!(
                "the batched path runs the native backend only, not {}",
                settings.backend
            )));
        }
        Ok(BatchRunner {
            body: PlanarBody::new(&settings.body.model()?, &settings.physics)?,
            settings: settings.clone(),
            task,
            level: SimdLevel::detect(),
        })
    }

    /// The same runner on `level` (a level the CPU lacks runs the portable code).
    pub fn with_level(mut self, level: SimdLevel) -> BatchRunner {
        self.level = level;
        self
    }

    /// The SIMD level in use.
    pub fn level(&self) -> SimdLevel {
        self.level
    }

    /// The fewest networks worth a block of their own on this runner's
    /// SIMD level: its narrow width, the block a remainder flies in
    /// (AVX-512 [`NARROW_LANES`], AVX2 and the portable build
    /// [`SMALL_LANES`]; full blocks are [`LANES`] wide). On
    /// AVX-512 a block of [`SMALL_LANES`] networks, one register per value,
    /// is bound by the latency of a step's long dependency chain and takes
    /// longer than one of [`NARROW_LANES`]; on AVX2 (two registers per
    /// value) and the portable build it takes less. Measured on Zen 5
    /// (`psa-esp bench --steps 500 --rounds 7 --networks 8`, and `16`, two
    /// runs each): AVX-512 27.9-33.0 against 11.5-11.6 ns per network-step,
    /// so 8 networks take 1.2-1.4 times as long as 16; AVX2 32.6-34.5
    /// against 22.1-22.8 ns, about three quarters as long.
    pub fn narrowest_block(&self) -> usize {
        match self.running_level() {
            SimdLevel::Avx512 => NARROW_LANES,
            SimdLevel::Avx2 | SimdLevel::Portable => SMALL_LANES,
        }
    }

    /// The widest block `level` flies (the batch is cut into such blocks):
    /// [`LANES`] networks on AVX-512 and AVX2, [`SMALL_LANES`] on the
    /// portable build.
    pub fn widest_block(level: SimdLevel) -> usize {
        match level {
            SimdLevel::Avx512 | SimdLevel::Avx2 => LANES,
            SimdLevel::Portable => SMALL_LANES,
        }
    }

    /// The fitness of networks `range` of `networks`, in % of the
    /// theoretical maximum, the mean over `settings.trials` trials: exactly
    /// what [`TrialRunner::evaluate`] gives network `range.start + i` with
    /// stream `rngs[i]`.
    ///
    /// # Panics
    /// If `range` and `rngs` differ in length, or `range` reaches past the
    /// networks.
    pub fn evaluate<S: NetworkSet + ?Sized>(
        &self,
        networks: &S,
        range: Range<usize>,
        rngs: &mut [Stream],
    ) -> Result<Vec<f64>, PsaError> {
        assert_eq!(range.len(), rngs.len(), "one stream per network");
        let mut job = NetworkBlocks {
            runner: self,
            networks,
            first: range.start,
            rngs,
            fitness: Vec::with_capacity(range.len()),
        };
        self.each_block(range.len(), &mut job)?;
        Ok(job.fitness)
    }

    /// Each trial's score of `network`, in % of the theoretical maximum:
    /// exactly what [`TrialRunner::evaluate_trials`] gives with `rng`, the
    /// trials flown side by side, one per lane (the robustness tests' many
    /// trials of one champion). A trial's start and noise seed do not
    /// depend on any flight, so they are drawn first, in the scalar path's
    /// order. Where a start is invalid or a flight ends non-finite, the
    /// scalar path runs the trials again from `rng`'s first position and
    /// names the error in the order it meets it.
    pub fn evaluate_trials(&self, network: &Network, rng: &mut Stream) -> Result<Vec<f64>, PsaError> {
        TrialRunner::check_network(network)?;
        let position = rng.get_word_pos();
        let scalar = |rng: &mut Stream| {
            rng.set_word_pos(position);
            TrialRunner::new(&self.settings, self.task)?.evaluate_trials(network, rng)
        };
        let drawn: Result<Vec<Drawn>, PsaError> = (0..self.settings.trials).map(|_| self.draw(rng)).collect();
        let Ok(drawn) = drawn else {
            return scalar(rng);
        };
        let mut job = TrialBlocks {
            runner: self,
            network,
            drawn: &drawn,
            scores: Vec::with_capacity(drawn.len()),
            finite: true,
        };
        self.each_block(drawn.len(), &mut job)?;
        if job.finite {
            Ok(job.scores)
        } else {
            scalar(rng)
        }
    }

    /// The level the kernels run on: the one asked for where the CPU has
    /// it, else the portable build.
    fn running_level(&self) -> SimdLevel {
        if self.level.is_supported() {
            self.level
        } else {
            SimdLevel::Portable
        }
    }

    /// Runs `job` on `count` items cut into blocks, each with the kernel of
    /// its width (noisy where the settings have noise), by the running
    /// level's two widths: full blocks of the wide one, and a remainder of
    /// more than half of it in one padded wide block, else in blocks of the
    /// narrow one (see [`BatchRunner::narrowest_block`]). AVX-512 flies
    /// [`LANES`] and [`NARROW_LANES`], AVX2 [`LANES`] and [`SMALL_LANES`],
    /// the portable build [`SMALL_LANES`] only. Lanes fly independently,
    /// so the cut changes speed, never a result.
    fn each_block(&self, count: usize, job: &mut impl BlockJob) -> Result<(), PsaError> {
        let noisy = self.settings.noise.is_active();
        match self.running_level() {
            SimdLevel::Avx512 => cut(
                count,
                job,
                pick(noisy, wide::avx512::RUN, wide_noisy::avx512::RUN),
                pick(noisy, narrow::avx512::RUN, narrow_noisy::avx512::RUN),
            ),
            SimdLevel::Avx2 => cut(
                count,
                job,
                pick(noisy, wide::avx2::RUN, wide_noisy::avx2::RUN),
                pick(noisy, small::avx2::RUN, small_noisy::avx2::RUN),
            ),
            SimdLevel::Portable => {
                let small = pick(noisy, small::portable::RUN, small_noisy::portable::RUN);
                cut(count, job, small, small)
            }
        }
    }

    /// One trial's start, target and noise seed, drawn from `rng` in the
    /// scalar path's order.
    fn draw(&self, rng: &mut Stream) -> Result<Drawn, PsaError> {
        let s = &self.settings;
        let (start, target) = s.tasks.start_and_target(self.task, s.random_init, rng);
        start.validate()?;
        Ok(Drawn {
            start: self.body.start_state(&start),
            target: [target.x, target.y, target.heading],
            seed: s.noise.draw_seed(rng),
        })
    }

    /// One trial of every lane with `fly`, lane `l` of `weights` from
    /// `drawn[l]` (lanes past `drawn`, at most N, repeat its first trial):
    /// each lane's points and which lanes ended finite.
    fn fly_lanes<const N: usize>(
        &self,
        fly: Kernel<N>,
        weights: &BlockWeights<N>,
        drawn: &[Drawn],
    ) -> (Lanes<N>, LaneMask<N>) {
        let lane = |l: usize| &drawn[if l < drawn.len() { l } else { 0 }];
        let lanes = |f: &dyn Fn(&Drawn) -> f64| Lanes(std::array::from_fn(|l| f(lane(l))));
        let mut state = PlanarState {
            position: [lanes(&|d| d.start.position[0]), lanes(&|d| d.start.position[1])],
            velocity: [lanes(&|d| d.start.velocity[0]), lanes(&|d| d.start.velocity[1])],
            quaternion: [lanes(&|d| d.start.quaternion[0]), lanes(&|d| d.start.quaternion[1])],
            omega: lanes(&|d| d.start.omega),
        };
        let target = [0, 1, 2].map(|i| lanes(&|d| d.target[i]));
        let mut noise = NoiseSource::from_seeds(&std::array::from_fn(|l| lane(l).seed));
        let flight = Flight {
            settings: &self.settings,
            body: &self.body,
            weights,
        };
        fly(&flight, &mut state, &target, &mut noise)
    }
}

/// Runs `job` on `count` items: full blocks of `W` with `wide`, then
/// what is left in one padded block of `W` if it is more than half of
/// `W`, else in blocks of `R` with `narrow`.
fn cut<const W: usize, const R: usize>(
    count: usize,
    job: &mut impl BlockJob,
    wide: Kernel<W>,
    narrow: Kernel<R>,
) -> Result<(), PsaError> {
    let full = count - count % W;
    for start in (0..full).step_by(W) {
        job.run::<W>(wide, start..start + W)?;
    }
    if count - full > W / 2 {
        return job.run::<W>(wide, full..count);
    }
    for start in (full..count).step_by(R) {
        job.run::<R>(narrow, start..count.min(start + R))?;
    }
    Ok(())
}

/// One trial's start, target (x, y, heading) and noise seed.
struct Drawn {
    start: PlanarState<f64>,
    target: [f64; 3],
    seed: u64,
}

/// Work done block by block by [`BatchRunner::each_block`].
trait BlockJob {
    /// Items `block` (at most N) with the kernel `fly` of width N.
    fn run<const N: usize>(&mut self, fly: Kernel<N>, block: Range<usize>) -> Result<(), PsaError>;
}

/// Networks flown a block at a time, one per lane, every trial of the
/// block in turn ([`BatchRunner::evaluate`]).
struct NetworkBlocks<'a, S: NetworkSet + ?Sized> {
    runner: &'a BatchRunner,
    networks: &'a S,
    /// The network of the first stream.
    first: usize,
    /// One stream per network.
    rngs: &'a mut [Stream],
    fitness: Vec<f64>,
}

impl<S: NetworkSet + ?Sized> BlockJob for NetworkBlocks<'_, S> {
    fn run<const N: usize>(&mut self, fly: Kernel<N>, block: Range<usize>) -> Result<(), PsaError> {
        let networks = block.start + self.first..block.end + self.first;
        for j in networks.clone() {
            let (inputs, outputs) = self.networks.shape(j);
            TrialRunner::check_shape(inputs, outputs)?;
        }
        let (runner, s) = (self.runner, &self.runner.settings);
        let rngs = &mut self.rngs[block];
        // Where each stream stood, for a lane that must be re-run.
        let positions: Vec<u128> = rngs.iter().map(|r| r.get_word_pos()).collect();
        let weights = BlockWeights::<N>::new(self.networks, networks.clone());
        let maximum = s.fitness.maximum(s.steps);
        // trials[lane * s.trials + t]: lane's fitness in trial t.
        let mut trials = vec![0.0; networks.len() * s.trials];
        let mut valid = Lanes::<N>::splat(0.0).le(Lanes::splat(0.0));
        for t in 0..s.trials {
            let drawn = rngs
                .iter_mut()
                .map(|rng| runner.draw(rng))
                .collect::<Result<Vec<_>, _>>()?;
            let (points, ok) = runner.fly_lanes(fly, &weights, &drawn);
            valid = valid & ok;
            for lane in 0..networks.len() {
                trials[lane * s.trials + t] = 100.0 * points[lane] / maximum;
            }
        }
        for (lane, trial) in trials.chunks_exact(s.trials).enumerate() {
            if valid.0[lane] != 0 {
                self.fitness.push(mean_of_trials(trial));
            } else {
                // The scalar path, from the lane's original stream, names the problem.
                rngs[lane].set_word_pos(positions[lane]);
                let network = self.networks.network(networks.start + lane);
                self.fitness
                    .push(TrialRunner::new(s, runner.task)?.evaluate(&network, &mut rngs[lane])?);
            }
        }
        Ok(())
    }
}

/// One network's trials flown a block at a time, one trial per lane
/// ([`BatchRunner::evaluate_trials`]).
struct TrialBlocks<'a> {
    runner: &'a BatchRunner,
    network: &'a Network,
    drawn: &'a [Drawn],
    scores: Vec<f64>,
    /// Whether every flight so far ended finite.
    finite: bool,
}

impl BlockJob for TrialBlocks<'_> {
    fn run<const N: usize>(&mut self, fly: Kernel<N>, block: Range<usize>) -> Result<(), PsaError> {
        let s = &self.runner.settings;
        let networks = std::slice::from_ref(self.network);
        let weights = BlockWeights::<N>::new(networks, std::iter::repeat_n(0, block.len()));
        let (points, ok) = self.runner.fly_lanes(fly, &weights, &self.drawn[block.clone()]);
        let maximum = s.fitness.maximum(s.steps);
        for lane in 0..block.len() {
            self.finite &= ok.0[lane] != 0;
            self.scores.push(100.0 * points[lane] / maximum);
        }
        Ok(())
    }
}
