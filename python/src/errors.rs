//! Errors raised as the Python exceptions of `psa_esp.errors`, each with
//! the crate's message.

use esp_neuroevolution::{RunError, SettingsError};
use pyo3::prelude::*;

/// An exception of `psa_esp.errors`, by class name, with `message`.
pub fn raise(py: Python<'_>, class: &str, message: impl Into<String>) -> PyErr {
    let message = message.into();
    let made = py
        .import("psa_esp.errors")
        .and_then(|module| module.getattr(class))
        .and_then(|class| class.call1((message.clone(),)));
    match made {
        Ok(exception) => PyErr::from_value(exception),
        Err(error) => error,
    }
}

/// A configuration that cannot be read or is out of range.
pub fn config(message: impl Into<String>) -> PyErr {
    Python::attach(|py| raise(py, "ConfigError", message))
}

/// An `anyhow` error of reading a configuration, with its chain.
pub fn config_chain(error: anyhow::Error) -> PyErr {
    config(format!("{error:#}"))
}

/// The simulator failed (a physics error, an impossible state).
pub fn simulation(error: impl std::fmt::Display) -> PyErr {
    Python::attach(|py| raise(py, "SimulationError", format!("{error:#}")))
}

/// A search setting out of its range.
pub fn settings(error: SettingsError) -> PyErr {
    Python::attach(|py| raise(py, "SettingsError", error.to_string()))
}

/// A run's error, as the exception class of its kind.
pub fn run(error: RunError) -> PyErr {
    let class = match &error {
        RunError::Worker(_) | RunError::Evaluation(_) => "EvaluationError",
        RunError::NanFitness { .. } => "NanFitnessError",
        RunError::InfiniteFitness { .. } => "InfiniteFitnessError",
        RunError::Settings(_) => "SettingsError",
        RunError::NonFiniteWeight { .. } | RunError::Network(_) => "NonFiniteWeightError",
        RunError::FitnessCount { .. } => "FitnessCountError",
        RunError::ForeignTicket => "ForeignTicketError",
        RunError::TicketTold { .. } => "TicketToldError",
        RunError::Ended => "EndedError",
        RunError::Restore(_) => "RestoreError",
        RunError::NotEnded => "NotEndedError",
    };
    Python::attach(|py| raise(py, class, error.to_string()))
}

/// A network file that cannot be read or written.
pub fn network_file(error: impl std::fmt::Display) -> PyErr {
    Python::attach(|py| raise(py, "NetworkFileError", error.to_string()))
}

/// A saved run that cannot be restored.
pub fn restore(message: impl Into<String>) -> PyErr {
    Python::attach(|py| raise(py, "RestoreError", message))
}
