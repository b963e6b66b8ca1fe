//! The trial kernel on an NVIDIA GPU (the `cuda` cargo feature): NVRTC
//! compiles `trial.cu` at run time with `--fmad=false`, and [`CudaTrials`]
//! flies a [`TrialBatch`] with one thread per trial.
//!
//! The CUDA libraries are loaded when first asked for (`cudarc`'s dynamic
//! loading), so a build with the feature runs on machines without them;
//! `cudarc` panics when a library it calls is absent, so [`CudaTrials::open`]
//! probes for the driver and NVRTC first and says which is missing. Those
//! two probes and the kernel launch are this module's `unsafe` calls, the
//! only `unsafe` of the project outside `ode-sys` and the ODE wrapper.

use std::fmt;

use super::{TrialBatch, TrialPoints};
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
        }
    }
}

impl std::error::Error for CudaUnavailable {}

/// The kernel's source, compiled by NVRTC at run time.
pub const KERNEL_SOURCE: &str = include_str!("trial.cu");
/// The kernel's entry point in [`KERNEL_SOURCE`].
pub const KERNEL_NAME: &str = "psa_trials";
/// Threads per block: fp64 with the whole trial in registers needs many
/// registers a thread, which 1024-thread blocks may not get.
pub const THREADS_PER_BLOCK: u32 = 128;

#[cfg(feature = "cuda")]
mod gpu {
    use std::sync::{Arc, Mutex};

    use cudarc::driver::{CudaContext, CudaFunction, CudaStream, LaunchConfig, PushKernelArg};
    use cudarc::nvrtc::{compile_ptx_with_opts, CompileOptions, Ptx};
    use zerocopy::IntoBytes;

    use super::{CudaUnavailable, TrialBatch, TrialPoints, KERNEL_NAME, KERNEL_SOURCE, THREADS_PER_BLOCK};
    use crate::psa::PsaError;

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

    /// `trial.cu` compiled to PTX with `--fmad=false` (no contraction into
    /// fused multiply-adds: the kernel's `fma` calls are its only ones), for
    /// `architecture` (`compute_90`, say) or NVRTC's default.
    pub fn compile(architecture: Option<String>) -> Result<Ptx, CudaUnavailable> {
        if !nvrtc_present() {
            return Err(CudaUnavailable::NoNvrtc);
        }
        let options = CompileOptions {
            fmad: Some(false),
            ftz: Some(false),
            prec_div: Some(true),
            prec_sqrt: Some(true),
            use_fast_math: Some(false),
            options: architecture
                .map(|a| format!("--gpu-architecture={a}"))
                .into_iter()
                .collect(),
            name: Some("trial.cu".into()),
            ..Default::default()
        };
        compile_ptx_with_opts(KERNEL_SOURCE, options).map_err(|e| CudaUnavailable::Compile(e.to_string()))
    }

    /// The kernel loaded on one device, ready to fly batches.
    pub struct Loaded {
        pub device: String,
        stream: Arc<CudaStream>,
        function: CudaFunction,
        /// One launch at a time: the threads of a grid share the device.
        launch: Mutex<()>,
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

    /// Device 0 with the kernel compiled for it.
    pub fn open() -> Result<Loaded, CudaUnavailable> {
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
        let ptx = compile(Some(format!("compute_{major}{minor}")))?;
        let module = context.load_module(ptx).map_err(driver)?;
        let function = module.load_function(KERNEL_NAME).map_err(driver)?;
        let device = format!(
            "{} (compute capability {major}.{minor})",
            context.name().map_err(driver)?
        );
        Ok(Loaded {
            device,
            stream: context.default_stream(),
            function,
            launch: Mutex::new(()),
        })
    }

    impl Loaded {
        /// Flies every trial of `batch`, one thread each.
        pub fn fly(&self, batch: &TrialBatch) -> Result<TrialPoints, PsaError> {
            let failed = |e: cudarc::driver::DriverError| PsaError::Setting(format!("the cuda kernel: {e}"));
            let count = batch.trials.len();
            if count == 0 {
                return Ok(TrialPoints {
                    points: Vec::new(),
                    finite: Vec::new(),
                });
            }
            let too_many = |_| PsaError::Setting(format!("{count} trials are too many for one launch"));
            let count_arg = i32::try_from(count).map_err(too_many)?;
            let blocks = u32::try_from(count.div_ceil(THREADS_PER_BLOCK as usize)).map_err(too_many)?;
            let _one_at_a_time = self
                .launch
                .lock()
                .map_err(|_| PsaError::Setting("a launch panicked".into()))?;
            let s = &self.stream;
            let params = s.clone_htod(batch.params.as_bytes()).map_err(failed)?;
            // A batch of networks without active hidden neurons has no weights: keep the buffer non-empty.
            let weights = if batch.weights.is_empty() {
                s.alloc_zeros::<f64>(1)
            } else {
                s.clone_htod(&batch.weights)
            }
            .map_err(failed)?;
            let trials = s.clone_htod(batch.trials.as_bytes()).map_err(failed)?;
            let mut points = s.alloc_zeros::<f64>(count).map_err(failed)?;
            let mut finite = s.alloc_zeros::<i32>(count).map_err(failed)?;
            let config = LaunchConfig {
                grid_dim: (blocks, 1, 1),
                block_dim: (THREADS_PER_BLOCK, 1, 1),
                shared_mem_bytes: 0,
            };
            let mut launch = s.launch_builder(&self.function);
            launch
                .arg(&params)
                .arg(&weights)
                .arg(&trials)
                .arg(&count_arg)
                .arg(&mut points)
                .arg(&mut finite);
            // SAFETY: the arguments are, in order, what `psa_trials` in
            // trial.cu takes: a PsaParams, the weights (f64), `count`
            // PsaTrials (the `#[repr(C)]` mirrors' bytes, checked against
            // the C layout by the host build's tests), the count (i32), and
            // `count` f64 and i32 outputs; every buffer lives until the
            // copies below, which the stream orders after the kernel, and
            // each thread reads only inside them (thread i < count touches
            // trial i, output i and the weights that trial i names).
            unsafe { launch.launch(config) }.map_err(failed)?;
            Ok(TrialPoints {
                points: s.clone_dtoh(&points).map_err(failed)?,
                finite: s.clone_dtoh(&finite).map_err(failed)?,
            })
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

impl CudaTrials {
    /// Loads the CUDA driver and NVRTC, opens device 0 and compiles the
    /// kernel for it; says which is missing where one is.
    pub fn open() -> Result<CudaTrials, CudaUnavailable> {
        #[cfg(feature = "cuda")]
        {
            gpu::open().map(|loaded| CudaTrials { loaded })
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

/// NVRTC's PTX for `trial.cu` (NVRTC's default architecture): compiles the
/// kernel without a GPU or driver, to check that NVRTC takes it.
pub fn compile_for_check() -> Result<String, CudaUnavailable> {
    #[cfg(feature = "cuda")]
    {
        gpu::compile(None).map(|ptx| ptx.to_src())
    }
    #[cfg(not(feature = "cuda"))]
    {
        Err(CudaUnavailable::NotBuilt)
    }
}
