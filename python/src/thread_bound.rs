//! A trial's physics engine, kept on the thread that made it.
//!
//! An ODE world lives and dies on its thread (`psa_sim::ode`'s rule), so a
//! Python object that owns one cannot move between threads. The object
//! holds a key instead; the engine stays in its thread's table, and a call
//! from any other thread is refused with a `RuntimeError` naming the rule,
//! not a panic.

use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::thread::{self, ThreadId};

use psa_sim::physics::PhysicsBackend;
use pyo3::exceptions::PyRuntimeError;
use pyo3::PyResult;

thread_local! {
    /// The engines made on this thread, by key.
    static ENGINES: RefCell<HashMap<u64, Box<dyn PhysicsBackend>>> = RefCell::new(HashMap::new());
}

/// The next key: unique in the process.
static NEXT_KEY: AtomicU64 = AtomicU64::new(0);

/// A physics engine owned by the thread that made it.
pub struct ThreadBound {
    owner: ThreadId,
    key: u64,
}

impl ThreadBound {
    /// Puts `engine` in this thread's table.
    pub fn new(engine: Box<dyn PhysicsBackend>) -> ThreadBound {
        let key = NEXT_KEY.fetch_add(1, Ordering::Relaxed);
        ENGINES.with_borrow_mut(|engines| engines.insert(key, engine));
        ThreadBound {
            owner: thread::current().id(),
            key,
        }
    }

    /// Runs `f` on the engine; refused on any thread but its own.
    pub fn with<R>(&self, f: impl FnOnce(&mut dyn PhysicsBackend) -> R) -> PyResult<R> {
        if thread::current().id() != self.owner {
            return Err(PyRuntimeError::new_err(
                "a Trial (and the environment over it) steps only on the thread that made it (its \
                 physics world may be an ODE world, which lives on one thread): make one in each \
                 thread that steps it",
            ));
        }
        ENGINES.with_borrow_mut(|engines| match engines.get_mut(&self.key) {
            Some(engine) => Ok(f(engine.as_mut())),
            None => Err(PyRuntimeError::new_err(
                "this Trial's physics engine is gone (its thread's table was dropped)",
            )),
        })
    }
}

impl Drop for ThreadBound {
    /// Frees the engine when dropped on its own thread; dropped on another
    /// one (the last reference released there), the engine goes with its
    /// thread's table when that thread ends.
    fn drop(&mut self) {
        if thread::current().id() == self.owner {
            // The table may already be gone while the thread ends.
            let _ = ENGINES.try_with(|engines| {
                if let Ok(mut engines) = engines.try_borrow_mut() {
                    engines.remove(&self.key);
                }
            });
        }
    }
}
