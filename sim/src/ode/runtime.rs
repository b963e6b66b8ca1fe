//! ODE's process-wide initialisation (exactly once) and per-thread data.

use std::cell::Cell;
use std::sync::OnceLock;

use super::{messages, OdeError};

static INIT: OnceLock<Result<(), OdeError>> = OnceLock::new();

thread_local! {
    static THREAD_READY: Cell<bool> = const { Cell::new(false) };
}

fn init_once() -> Result<(), OdeError> {
    INIT.get_or_init(|| {
        messages::install();
        // SAFETY: OnceLock runs this closure exactly once in the process,
        // which is what dInitODE2's non-thread-safe counter requires.
        if unsafe { ode_sys::dInitODE2(0) } == 0 {
            return Err(OdeError::InitFailed);
        }
        // SAFETY: ODE is initialised; the token is a valid C string.
        if unsafe { ode_sys::dCheckConfiguration(c"ODE_double_precision".as_ptr()) } == 0 {
            return Err(OdeError::NotDoublePrecision);
        }
        Ok(())
    })
    .clone()
}

/// Initialises ODE (once per process, thread-safely) and allocates ODE's
/// per-thread data for the calling thread (once per thread). Every ODE
/// object constructor calls this, so worker threads are covered
/// automatically; [`thread_pool`] also does it up front.
pub fn ensure_thread_ready() -> Result<(), OdeError> {
    init_once()?;
    if THREAD_READY.with(Cell::get) {
        return Ok(());
    }
    // SAFETY: ODE is initialised; the mask asks for every kind of data.
    let ok = unsafe { ode_sys::dAllocateODEDataForThread(ode_sys::dAllocateODEDataFlags_dAllocateMaskAll as u32) };
    if ok == 0 {
        return Err(OdeError::ThreadDataFailed);
    }
    THREAD_READY.with(|ready| ready.set(true));
    Ok(())
}

/// The most worker threads a pool may have: far more cores than any one
/// machine has, and few enough that starting them cannot exhaust the
/// process' threads or memory (each has its own stack and ODE data).
pub const MAX_THREADS: usize = 1024;

/// A rayon pool of `threads` workers, each with ODE's per-thread data
/// allocated as it starts (0 = rayon's default count, at most
/// [`MAX_THREADS`]).
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool, OdeError> {
    if threads > MAX_THREADS {
        return Err(OdeError::invalid(
            "thread count",
            threads,
            "at most 1024 (MAX_THREADS) worker threads",
        ));
    }
    init_once()?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(|_| {
            if let Err(err) = ensure_thread_ready() {
                log::error!("ODE per-thread set-up failed: {err}");
            }
        })
        .build()
        .map_err(|_| OdeError::CallFailed {
            call: "rayon::ThreadPoolBuilder::build",
        })
}

/// The libode version the bindings were built against.
pub fn libode_version() -> &'static str {
    ode_sys::LIBODE_VERSION
}
