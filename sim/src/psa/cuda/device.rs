//! The trial kernel on an NVIDIA GPU (the `cuda` cargo feature): NVRTC
//! compiles `trial.cu` at run time with `--fmad=false`, once per
//! [`Specialisation`] in use, and [`CudaTrials`] flies a [`TrialBatch`]
//! with one thread per trial.
//!
//! Each calling thread gets a slot of its own (a stream, pinned host
//! buffers and device buffers, kept and grown between launches), so the
//! launches of a grid's configurations run side by side on the device,
//! without a lock around them, and their copies are direct (DMA from
//! page-locked memory).
//!
//! The CUDA libraries are loaded when first asked for (`cudarc`'s dynamic
//! loading), so a build with the feature runs on machines without them;
//! `cudarc` panics when a library it calls is absent, so [`CudaTrials::open`]
//! probes for the driver and NVRTC first and says which is missing. Those
//! two probes, the kernel's parameters, the page-locked buffers and the
//! kernel launch are this module's `unsafe` code, the only `unsafe` of the
//! project outside `ode-sys` and the ODE wrapper.

use std::fmt;

use super::{Specialisation, TrialBatch, TrialPoints};
use crate::psa::PsaError;

/// Why the GPU cannot fly trials here.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CudaUnavailable {
    /// This build has no `cuda` feature.
    NotBuilt,
    /// The CUDA driver library (`libcuda.so`) is not found.
    NoDriver,
    /// The NVRTC library (`libnvrtc.so`) is not found.
    NoNvrtc,
    /// The driver is there, but it reports no CUDA device.
    NoDevice,
    /// The driver failed (initialising, opening the device, loading the kernel).
    Driver(String),
    /// NVRTC did not compile the kernel.
    Compile(String),
    /// A setting of the GPU path is invalid (named in the message).
    Setting(String),
}

impl fmt::Display for CudaUnavailable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CudaUnavailable::NotBuilt => write!(
                f,
                "this psa-esp was built without the `cuda` feature (build it with `cargo build --release --features cuda`)"
            ),
            CudaUnavailable::NoDriver => write!(
                f,
                "no CUDA driver: the library libcuda.so is not found (install the NVIDIA driver, or add its folder to LD_LIBRARY_PATH)"
            ),
            CudaUnavailable::NoNvrtc => write!(
                f,
                "no NVRTC: the library libnvrtc.so is not found (install the CUDA runtime compiler, or add its folder to LD_LIBRARY_PATH)"
            ),
            CudaUnavailable::NoDevice => write!(f, "no CUDA device: the driver reports none"),
            CudaUnavailable::Driver(why) => write!(f, "the CUDA driver failed: {why}"),
            CudaUnavailable::Compile(why) => write!(f, "NVRTC did not compile the trial kernel: {why}"),
            CudaUnavailable::Setting(why) => write!(f, "{why}"),
        }
    }
}

impl std::error::Error for CudaUnavailable {}

/// The kernel's source, compiled by NVRTC at run time.
pub const KERNEL_SOURCE: &str = include_str!("trial.cu");
/// The kernel's entry point in [`KERNEL_SOURCE`].
pub const KERNEL_NAME: &str = "psa_trials";
/// Threads per block by default (`PSA_BLOCK`, which the kernel's
/// `__launch_bounds__` promises): fp64 with the whole trial and the
/// network's weights in registers needs many registers a thread.
pub const THREADS_PER_BLOCK: u32 = 128;

/// Blocks an SM is to hold at once by default: 128-thread blocks then get
/// at most 128 registers a thread (some spilled to the L1 cache), 16 warps
/// an SM; on an H100 0.048 ns per network-step at 312,000 networks against
/// 0.055 at 3 blocks (168 registers) and 0.072 at 1 (181 registers, 8
/// warps; docs/gpu.md).
pub const MIN_BLOCKS_PER_SM: u32 = 4;

/// How the kernel is laid out on the device: threads per block, the
/// blocks an SM is to hold at once (`__launch_bounds__`' second number,
/// which caps the registers a thread gets), and how many steps of a trial
/// one pass of its loop flies (the unrolling lets a step's fitness overlap
/// the next step). It changes speed only, never a result. The defaults,
/// unless the environment sets `PSA_ESP_CUDA_BLOCK`,
/// `PSA_ESP_CUDA_MIN_BLOCKS` or `PSA_ESP_CUDA_UNROLL` (for tuning on a new
/// device; see docs/gpu.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelShape {
    /// Threads per block.
    pub block: u32,
    /// Blocks an SM is to hold at once.
    pub min_blocks: u32,
    /// Steps a pass of the trial's loop.
    pub unroll: u32,
}

impl KernelShape {
    /// The defaults, or the environment's values.
    pub fn from_env() -> Result<KernelShape, String> {
        KernelShape::from_values(|name| std::env::var(name).ok())
    }

    /// The shape that `value` gives each variable (`PSA_ESP_CUDA_BLOCK`,
    /// `PSA_ESP_CUDA_MIN_BLOCKS`, `PSA_ESP_CUDA_UNROLL`), the default where
    /// it gives none; an error naming a variable whose value is not a
    /// whole number in its range (or, for the block, a multiple of 32).
    pub fn from_values(value: impl Fn(&str) -> Option<String>) -> Result<KernelShape, String> {
        let read = |name: &str, default: u32, most: u32| -> Result<u32, String> {
            match value(name) {
                None => Ok(default),
                Some(text) => match text.parse::<u32>() {
                    Ok(value) if (1..=most).contains(&value) => Ok(value),
                    _ => Err(format!("{name}={text:?}: expected a whole number from 1 to {most}")),
                },
            }
        };
        let block = read("PSA_ESP_CUDA_BLOCK", THREADS_PER_BLOCK, 1024)?;
        if block % 32 != 0 {
            return Err(format!("PSA_ESP_CUDA_BLOCK={block}: expected a multiple of 32"));
        }
        Ok(KernelShape {
            block,
            min_blocks: read("PSA_ESP_CUDA_MIN_BLOCKS", MIN_BLOCKS_PER_SM, 32)?,
            unroll: read("PSA_ESP_CUDA_UNROLL", 1, 8)?,
        })
    }

    /// Its `-D` options.
    #[cfg_attr(not(feature = "cuda"), allow(dead_code))]
    fn defines(self) -> [String; 3] {
        [
            format!("-DPSA_BLOCK={}", self.block),
            format!("-DPSA_MIN_BLOCKS={}", self.min_blocks),
            format!("-DPSA_STEP_UNROLL={}", self.unroll),
        ]
    }
}

impl fmt::Display for KernelShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} threads a block, at least {} blocks an SM, {} step(s) a pass",
            self.block, self.min_blocks, self.unroll
        )
    }
}

#[cfg(feature = "cuda")]
mod gpu {
    use std::collections::HashMap;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{Arc, Mutex, OnceLock, RwLock};
    use std::time::{Duration, Instant};

    use cudarc::driver::sys::CUevent_flags;
    use cudarc::driver::{
        CudaContext, CudaEvent, CudaFunction, CudaSlice, CudaStream, DeviceRepr, LaunchConfig, PinnedHostSlice,
        PushKernelArg,
    };
    use cudarc::nvrtc::{compile_ptx_with_opts, CompileOptions, Ptx};
    use zerocopy::IntoBytes;

    use super::{CudaUnavailable, KernelShape, KERNEL_NAME, KERNEL_SOURCE};
    use crate::psa::cuda::{KernelParams, Specialisation, TrialBatch, TrialPoints};
    use crate::psa::PsaError;

    // SAFETY: `KernelParams` is `#[repr(C)]` of f64 and i32 fields with no
    // padding (zerocopy's `IntoBytes` derive proves it), field for field
    // `PsaParams` of trial.cu, which the kernel takes by value: the driver
    // copies its bytes into the kernel's parameter space.
    unsafe impl DeviceRepr for KernelParams {}

    /// Whether the driver library loads.
    pub fn driver_present() -> bool {
        // SAFETY: `is_culib_present` only tries to load the library by its
        // usual names (libloading); loading the NVIDIA driver library runs
        // no code of ours and has no precondition.
        unsafe { cudarc::driver::sys::is_culib_present() }
    }

    /// Whether the NVRTC library loads.
    pub fn nvrtc_present() -> bool {
        // SAFETY: as in `driver_present`, for NVRTC.
        unsafe { cudarc::nvrtc::sys::is_culib_present() }
    }

    /// `trial.cu` compiled to PTX for `specialisation` with `--fmad=false`
    /// (no contraction into fused multiply-adds: the kernel's `fma` calls
    /// are its only ones), for `architecture` (`compute_90`, say) or
    /// NVRTC's default.
    pub fn compile(
        specialisation: &Specialisation,
        shape: KernelShape,
        architecture: Option<String>,
    ) -> Result<Ptx, CudaUnavailable> {
        if !nvrtc_present() {
            return Err(CudaUnavailable::NoNvrtc);
        }
        let mut options = specialisation.defines();
        options.extend(shape.defines());
        options.extend(architecture.map(|a| format!("--gpu-architecture={a}")));
        // One NVRTC compilation at a time: a specialisation is compiled
        // once, so nothing waits long, and no NVRTC version's thread
        // safety is relied on.
        static NVRTC: Mutex<()> = Mutex::new(());
        let _one_at_a_time = NVRTC
            .lock()
            .map_err(|_| CudaUnavailable::Compile("a compilation panicked".into()))?;
        let options = CompileOptions {
            fmad: Some(false),
            ftz: Some(false),
            prec_div: Some(true),
            prec_sqrt: Some(true),
            use_fast_math: Some(false),
            options,
            name: Some("trial.cu".into()),
            ..Default::default()
        };
        compile_ptx_with_opts(KERNEL_SOURCE, options).map_err(|e| CudaUnavailable::Compile(e.to_string()))
    }

    /// A compiled kernel, shared by the threads that ask for it at once,
    /// and whether it has been launched yet.
    type Compiled = Arc<(OnceLock<Result<CudaFunction, String>>, AtomicBool)>;

    /// The kernel on one device, ready to fly batches.
    pub struct Loaded {
        pub device: String,
        context: Arc<CudaContext>,
        architecture: String,
        shape: KernelShape,
        /// The kernel of each specialisation in use, compiled when first asked for.
        kernels: Mutex<HashMap<String, Compiled>>,
        /// Slots not in use; a launch takes one (or makes one) and gives it back.
        slots: Mutex<Vec<Slot>>,
        /// Held shared by every launch in flight, and alone by a kernel's
        /// loading and first launch (which may resize the device's local
        /// memory): no module is loaded or first run beside other work.
        launches: RwLock<()>,
        /// Wall time with at least one launch in flight.
        busy: Mutex<Busy>,
    }

    /// Launches in flight, since when, and the wall time with any in flight so far.
    #[derive(Default)]
    struct Busy {
        in_flight: usize,
        since: Option<Instant>,
        total: Duration,
    }

    impl std::fmt::Debug for Loaded {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.debug_struct("Loaded")
                .field("device", &self.device)
                .finish_non_exhaustive()
        }
    }

    fn driver(e: impl std::fmt::Display) -> CudaUnavailable {
        CudaUnavailable::Driver(e.to_string())
    }

    fn failed(e: impl std::fmt::Display) -> PsaError {
        PsaError::Setting(format!("the cuda kernel: {e}"))
    }

    /// Device 0, with the kernel of `check` compiled for it (so that a
    /// device or NVRTC that cannot run it is found before any work).
    pub fn open(check: &Specialisation, shape: KernelShape) -> Result<Loaded, CudaUnavailable> {
        if !driver_present() {
            return Err(CudaUnavailable::NoDriver);
        }
        if !nvrtc_present() {
            return Err(CudaUnavailable::NoNvrtc);
        }
        if CudaContext::device_count().map_err(driver)? < 1 {
            return Err(CudaUnavailable::NoDevice);
        }
        let context = CudaContext::new(0).map_err(driver)?;
        let (major, minor) = context.compute_capability().map_err(driver)?;
        let device = format!(
            "{} (compute capability {major}.{minor}; {shape})",
            context.name().map_err(driver)?
        );
        let loaded = Loaded {
            device,
            context,
            architecture: format!("compute_{major}{minor}"),
            shape,
            kernels: Mutex::new(HashMap::new()),
            slots: Mutex::new(Vec::new()),
            launches: RwLock::new(()),
            busy: Mutex::new(Busy::default()),
        };
        let entry = loaded.entry(check).map_err(driver)?;
        loaded.load(&entry, check)?;
        Ok(loaded)
    }

    /// A launch's buffers: a stream, page-locked host memory for the
    /// inputs and outputs, their device copies, and two events that time
    /// the kernel. Grown when a launch needs more, never shrunk.
    struct Slot {
        stream: Arc<CudaStream>,
        upload: PinnedHostSlice<u8>,
        download: PinnedHostSlice<u8>,
        inputs: CudaSlice<u8>,
        outputs: CudaSlice<u8>,
        start: CudaEvent,
        stop: CudaEvent,
    }

    /// Page-locked host memory of `bytes` bytes, zeroed.
    fn pinned(context: &Arc<CudaContext>, bytes: usize) -> Result<PinnedHostSlice<u8>, PsaError> {
        // SAFETY: the allocation is uninitialised, so it is zeroed through
        // its pointer before any slice of it is made; u8 has no invalid
        // values. Flags 0: cached memory, which the host reads back fast.
        unsafe {
            let mut memory = context.alloc_pinned_with_flags::<u8>(bytes.max(1), 0).map_err(failed)?;
            std::ptr::write_bytes(memory.as_mut_ptr().map_err(failed)?, 0, bytes.max(1));
            Ok(memory)
        }
    }

    /// Where each section of a launch's buffer starts: sections in order,
    /// each at a multiple of 256 bytes.
    fn layout(lengths: &[usize]) -> (Vec<usize>, usize) {
        let mut offsets = Vec::with_capacity(lengths.len());
        let mut end = 0;
        for &length in lengths {
            offsets.push(end);
            end = (end + length).next_multiple_of(256);
        }
        (offsets, end.max(256))
    }

    impl Slot {
        fn new(context: &Arc<CudaContext>) -> Result<Slot, PsaError> {
            let stream = context.new_stream().map_err(failed)?;
            let timing = Some(CUevent_flags::CU_EVENT_DEFAULT);
            Ok(Slot {
                upload: pinned(context, 256)?,
                download: pinned(context, 256)?,
                inputs: stream.alloc_zeros::<u8>(256).map_err(failed)?,
                outputs: stream.alloc_zeros::<u8>(256).map_err(failed)?,
                start: context.new_event(timing).map_err(failed)?,
                stop: context.new_event(timing).map_err(failed)?,
                stream,
            })
        }

        /// Makes room for `inputs` and `outputs` bytes (half as much again,
        /// where it grows, so that a slowly growing batch reallocates seldom).
        fn reserve(&mut self, context: &Arc<CudaContext>, inputs: usize, outputs: usize) -> Result<(), PsaError> {
            if self.upload.len() < inputs {
                let bytes = inputs + inputs / 2;
                self.upload = pinned(context, bytes)?;
                self.inputs = self.stream.alloc_zeros::<u8>(bytes).map_err(failed)?;
            }
            if self.download.len() < outputs {
                let bytes = outputs + outputs / 2;
                self.download = pinned(context, bytes)?;
                self.outputs = self.stream.alloc_zeros::<u8>(bytes).map_err(failed)?;
            }
            Ok(())
        }
    }

    impl Loaded {
        /// The entry of `specialisation`'s kernel (compiled or not yet).
        fn entry(&self, specialisation: &Specialisation) -> Result<Compiled, PsaError> {
            Ok(self
                .kernels
                .lock()
                .map_err(|_| failed("a compilation panicked"))?
                .entry(specialisation.key())
                .or_default()
                .clone())
        }

        /// The kernel of `entry` (of `specialisation`), compiled and loaded
        /// when first asked for.
        fn load(&self, entry: &Compiled, specialisation: &Specialisation) -> Result<CudaFunction, CudaUnavailable> {
            entry
                .0
                .get_or_init(|| {
                    let ptx = compile(specialisation, self.shape, Some(self.architecture.clone()))
                        .map_err(|e| e.to_string())?;
                    let module = self.context.load_module(ptx).map_err(|e| e.to_string())?;
                    module.load_function(KERNEL_NAME).map_err(|e| e.to_string())
                })
                .clone()
                .map_err(CudaUnavailable::Compile)
        }

        /// Flies every trial of `batch`, one thread each: the points, and
        /// the kernel's own time in seconds (CUDA events; the copies not
        /// included). A kernel's loading and first launch have the device
        /// to themselves; every other launch runs beside the others.
        pub fn fly(&self, batch: &TrialBatch) -> Result<(TrialPoints, f64), PsaError> {
            if batch.trials.is_empty() {
                let none = TrialPoints {
                    points: Vec::new(),
                    finite: Vec::new(),
                };
                return Ok((none, 0.0));
            }
            let entry = self.entry(&batch.specialisation)?;
            let flown = if entry.1.load(Ordering::Acquire) {
                let _shared = self.launches.read().map_err(|_| failed("a launch panicked"))?;
                let function = self.load(&entry, &batch.specialisation).map_err(failed)?;
                self.fly_in_slot(&function, batch)
            } else {
                let _alone = self.launches.write().map_err(|_| failed("a launch panicked"))?;
                let function = self.load(&entry, &batch.specialisation).map_err(failed)?;
                let flown = self.fly_in_slot(&function, batch);
                entry.1.store(true, Ordering::Release);
                flown
            };
            flown.map_err(|e| {
                let count = batch.trials.len();
                let key = batch.specialisation.key();
                PsaError::Setting(format!("{e} (a launch of {count} trials, specialisation {key})"))
            })
        }

        /// [`Loaded::fly`] on a slot of the pool (or a new one).
        fn fly_in_slot(&self, function: &CudaFunction, batch: &TrialBatch) -> Result<(TrialPoints, f64), PsaError> {
            let taken = self.slots.lock().map_err(|_| failed("a launch panicked"))?.pop();
            let mut slot = match taken {
                Some(slot) => slot,
                None => Slot::new(&self.context)?,
            };
            self.count_busy(true);
            let flown = self.fly_in(&mut slot, function, batch);
            self.count_busy(false);
            self.slots.lock().map_err(|_| failed("a launch panicked"))?.push(slot);
            flown
        }

        /// Counts a launch in (`start`) or out of flight.
        fn count_busy(&self, start: bool) {
            let Ok(mut busy) = self.busy.lock() else { return };
            if start {
                busy.in_flight += 1;
                if busy.in_flight == 1 {
                    busy.since = Some(Instant::now());
                }
            } else {
                busy.in_flight = busy.in_flight.saturating_sub(1);
                if busy.in_flight == 0 {
                    if let Some(since) = busy.since.take() {
                        busy.total += since.elapsed();
                    }
                }
            }
        }

        /// Wall time so far with at least one launch in flight (its
        /// copies, kernel and wait included).
        pub fn busy(&self) -> Duration {
            self.busy.lock().map(|busy| busy.total).unwrap_or_default()
        }

        fn fly_in(
            &self,
            slot: &mut Slot,
            function: &CudaFunction,
            batch: &TrialBatch,
        ) -> Result<(TrialPoints, f64), PsaError> {
            let count = batch.trials.len();
            let too_many = |_| failed(format!("{count} trials are too many for one launch"));
            let count_arg = i32::try_from(count).map_err(too_many)?;
            let block = self.shape.block;
            let blocks = u32::try_from(count.div_ceil(block as usize)).map_err(too_many)?;
            let sections: [&[u8]; 4] = [
                batch.neurons.as_bytes(),
                batch.networks.as_bytes(),
                batch.trials.as_bytes(),
                batch.noise.as_bytes(),
            ];
            let (at, in_bytes) = layout(&sections.map(<[u8]>::len));
            let (out, out_bytes) = layout(&[count * 8, count * 4]);
            slot.reserve(&self.context, in_bytes, out_bytes)?;
            {
                let host = slot.upload.as_mut_slice().map_err(failed)?;
                for (section, &offset) in sections.iter().zip(&at) {
                    host[offset..offset + section.len()].copy_from_slice(section);
                }
            }
            let s = &slot.stream;
            // Plain slices of page-locked memory: the copies are direct and
            // asynchronous, ordered on the slot's stream, which is
            // synchronised below before the host memory is read or reused.
            let upload = &slot.upload.as_slice().map_err(failed)?[..in_bytes];
            s.memcpy_htod(upload, &mut slot.inputs.slice_mut(..in_bytes))
                .map_err(failed)?;
            let view = |i: usize| slot.inputs.slice(at[i]..at[i] + sections[i].len());
            let (neurons, networks, trials, noise) = (view(0), view(1), view(2), view(3));
            let (mut points, mut finite) = slot.outputs.split_at_mut(out[1]);
            let mut points = points.slice_mut(..count * 8);
            let mut finite = finite.slice_mut(..count * 4);
            let config = LaunchConfig {
                grid_dim: (blocks, 1, 1),
                block_dim: (block, 1, 1),
                shared_mem_bytes: 0,
            };
            slot.start.record(s).map_err(failed)?;
            let mut launch = s.launch_builder(function);
            launch
                .arg(&batch.params)
                .arg(&neurons)
                .arg(&networks)
                .arg(&trials)
                .arg(&noise)
                .arg(&count_arg)
                .arg(&mut points)
                .arg(&mut finite);
            // SAFETY: the arguments are, in order, what `psa_trials` in
            // trial.cu takes: a PsaParams by value (`KernelParams`, its
            // `#[repr(C)]` mirror), the neurons' genes (f64), the networks'
            // rows (i32, `hidden` a row, as the kernel was specialised), the
            // PsaTrials (their `#[repr(C)]` mirrors, checked against the C
            // layout by the host build's tests), the noise states (4 u64 a
            // trial where the kernel is noisy), the count (i32), and room
            // for `count` f64 points and `count` i32 flags. Each section
            // lies at a 256-byte boundary of a device buffer at least as
            // long as the batch, and lives until the stream is synchronised
            // below; thread i < count touches trial i, its outputs, its
            // noise state, and the row and neurons that trial i names,
            // which `TrialBatch::append` made in range.
            unsafe { launch.launch(config) }.map_err(failed)?;
            slot.stop.record(s).map_err(failed)?;
            let download = &mut slot.download.as_mut_slice().map_err(failed)?[..out_bytes];
            s.memcpy_dtoh(&slot.outputs.slice(..out_bytes), download)
                .map_err(failed)?;
            s.synchronize().map_err(failed)?;
            let seconds = f64::from(slot.start.elapsed_ms(&slot.stop).map_err(failed)?) / 1e3;
            let download = &slot.download.as_slice().map_err(failed)?[..out_bytes];
            let points = download[..count * 8]
                .chunks_exact(8)
                .map(|b| f64::from_ne_bytes(b.try_into().expect("8 bytes")))
                .collect();
            let finite = download[out[1]..out[1] + count * 4]
                .chunks_exact(4)
                .map(|b| i32::from_ne_bytes(b.try_into().expect("4 bytes")))
                .collect();
            Ok((TrialPoints { points, finite }, seconds))
        }
    }
}

/// The trial kernel loaded on the machine's first CUDA device.
#[derive(Debug)]
pub struct CudaTrials {
    #[cfg(feature = "cuda")]
    loaded: gpu::Loaded,
    /// Without the feature, none can be made.
    #[cfg(not(feature = "cuda"))]
    never: std::convert::Infallible,
}

#[cfg_attr(not(feature = "cuda"), allow(dead_code))]
/// The specialisation of the default settings with 5 hidden neurons (the
/// paper's networks): the kernel compiled to check NVRTC and the device.
fn default_specialisation() -> Specialisation {
    use crate::physics::{BackendKind, PlanarBody};
    use crate::psa::PsaSettings;
    let settings = PsaSettings {
        backend: BackendKind::Native,
        ..PsaSettings::default()
    };
    let model = settings.body.model().expect("the default body is valid");
    let body = PlanarBody::new(&model, &settings.physics).expect("the default body is valid");
    super::KernelParams::new(&settings, &body, 5)
        .expect("the default settings suit the kernel")
        .1
}

impl CudaTrials {
    /// Loads the CUDA driver and NVRTC, opens device 0 and compiles the
    /// kernel of the default settings for it; says which is missing where
    /// one is. Other specialisations are compiled when first flown.
    pub fn open() -> Result<CudaTrials, CudaUnavailable> {
        #[cfg(feature = "cuda")]
        {
            let shape = KernelShape::from_env().map_err(CudaUnavailable::Setting)?;
            gpu::open(&default_specialisation(), shape).map(|loaded| CudaTrials { loaded })
        }
        #[cfg(not(feature = "cuda"))]
        {
            Err(CudaUnavailable::NotBuilt)
        }
    }

    /// The device's name and compute capability.
    pub fn device(&self) -> &str {
        #[cfg(feature = "cuda")]
        {
            &self.loaded.device
        }
        #[cfg(not(feature = "cuda"))]
        {
            match self.never {}
        }
    }

    /// Flies every trial of `batch` on the GPU, one thread each: what
    /// [`super::fly_on_host`] computes, bit for bit.
    pub fn fly(&self, batch: &TrialBatch) -> Result<TrialPoints, PsaError> {
        self.fly_timed(batch).map(|(points, _)| points)
    }

    /// Wall time so far with at least one launch in flight: the GPU
    /// evaluation's share of a grid's time.
    pub fn busy(&self) -> std::time::Duration {
        #[cfg(feature = "cuda")]
        {
            self.loaded.busy()
        }
        #[cfg(not(feature = "cuda"))]
        {
            match self.never {}
        }
    }

    /// [`CudaTrials::fly`], and the kernel's own time in seconds (CUDA
    /// events, without the copies).
    pub fn fly_timed(&self, batch: &TrialBatch) -> Result<(TrialPoints, f64), PsaError> {
        #[cfg(feature = "cuda")]
        {
            self.loaded.fly(batch)
        }
        #[cfg(not(feature = "cuda"))]
        {
            let _ = batch;
            match self.never {}
        }
    }
}

/// NVRTC's PTX for `trial.cu` (NVRTC's default architecture) specialised
/// for the default settings: compiles the kernel without a GPU or driver,
/// to check that NVRTC takes it.
pub fn compile_for_check() -> Result<String, CudaUnavailable> {
    #[cfg(feature = "cuda")]
    {
        let shape = KernelShape::from_env().map_err(CudaUnavailable::Setting)?;
        gpu::compile(&default_specialisation(), shape, None).map(|ptx| ptx.to_src())
    }
    #[cfg(not(feature = "cuda"))]
    {
        Err(CudaUnavailable::NotBuilt)
    }
}

#[cfg(test)]
mod tests {
    use super::{KernelShape, MIN_BLOCKS_PER_SM, THREADS_PER_BLOCK};

    fn shape(pairs: &[(&str, &str)]) -> Result<KernelShape, String> {
        KernelShape::from_values(|name| {
            pairs
                .iter()
                .find(|(key, _)| *key == name)
                .map(|(_, value)| value.to_string())
        })
    }

    #[test]
    fn the_kernel_shape_takes_valid_values_and_names_a_bad_one() {
        let default = shape(&[]).unwrap();
        assert_eq!(
            (default.block, default.min_blocks, default.unroll),
            (THREADS_PER_BLOCK, MIN_BLOCKS_PER_SM, 1)
        );
        let set = shape(&[
            ("PSA_ESP_CUDA_BLOCK", "64"),
            ("PSA_ESP_CUDA_MIN_BLOCKS", "8"),
            ("PSA_ESP_CUDA_UNROLL", "2"),
        ]);
        assert_eq!(
            set.unwrap(),
            KernelShape {
                block: 64,
                min_blocks: 8,
                unroll: 2
            }
        );
        for (name, bad) in [
            ("PSA_ESP_CUDA_BLOCK", "100"),
            ("PSA_ESP_CUDA_BLOCK", "2048"),
            ("PSA_ESP_CUDA_MIN_BLOCKS", "0"),
            ("PSA_ESP_CUDA_UNROLL", "two"),
        ] {
            let error = shape(&[(name, bad)]).unwrap_err();
            assert!(error.contains(name), "{error}");
        }
    }
}
