//! `psa_esp._native`: the PyO3 binding under the Python package `psa_esp`.
//!
//! A thin layer over the workspace's crates, beside the `psa-esp` command
//! line: `psa-sim` flies the networks (batched, on the crate's threads,
//! with the GIL released), `esp-neuroevolution` searches (ESP and the
//! hill-climber, driven by ask and tell over NumPy arrays), and
//! `psa-experiment` owns what the command line reads and writes (run
//! configurations and presets, the run folder's files). Nothing here
//! changes a result: every number is the one the command line gives for
//! the same network, configuration and seed.
//!
//! The Python side (`python/psa_esp/`) adds the exception classes (raised
//! from here by name), the Gymnasium environment and the type stubs.

use pyo3::prelude::*;

mod args;
mod config;
mod errors;
mod evaluate;
mod files;
mod records;
mod run;
mod stats;
mod thread_bound;
mod trial;
mod trial_batch;
mod weights;

/// The native half of `psa_esp`; import `psa_esp`, not this module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::reference_evaluations_per_second, m)?)?;
    m.add_function(wrap_pyfunction!(config::resolve_config, m)?)?;
    m.add_function(wrap_pyfunction!(files::load_network, m)?)?;
    m.add_function(wrap_pyfunction!(files::replay, m)?)?;
    m.add_function(wrap_pyfunction!(stats::welch, m)?)?;
    m.add_function(wrap_pyfunction!(files::_network_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(run::_run_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(run::_asked_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(run::_ticket_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(trial::_use_packaged_font, m)?)?;
    m.add_class::<files::Network>()?;
    m.add_class::<run::Run>()?;
    m.add_class::<run::Asked>()?;
    m.add_class::<run::Ticket>()?;
    m.add_class::<trial::Trial>()?;
    m.add_class::<trial_batch::TrialBatch>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("build", psa_experiment::version())?;
    m.add("INPUTS", psa_sim::psa::INPUT_COUNT)?;
    m.add("OUTPUTS", psa_sim::psa::THRUSTER_COUNT)?;
    m.add(
        "GENES_PER_NEURON",
        psa_sim::psa::INPUT_COUNT + psa_sim::psa::THRUSTER_COUNT,
    )?;
    Ok(())
}
