use thiserror::Error;

/// Everything the safe ODE wrapper can refuse or fail at.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OdeError {
    /// `dInitODE2` reported failure.
    #[error("ODE could not be initialised (dInitODE2 failed)")]
    InitFailed,
    /// The linked libode is not the double-precision build.
    #[error("the linked libode is not built in double precision (dCheckConfiguration(\"ODE_double_precision\") is false); install Debian's libode-dev")]
    NotDoublePrecision,
    /// `dAllocateODEDataForThread` reported failure.
    #[error("ODE could not allocate its per-thread data for this thread")]
    ThreadDataFailed,
    /// ODE returned a null handle or a failure code.
    #[error("ODE call {call} failed")]
    CallFailed {
        /// The ODE function that failed.
        call: &'static str,
    },
    /// An argument that ODE would abort on, or silently turn into NaN.
    #[error("invalid {what}: {value} ({reason})")]
    InvalidArgument {
        /// The argument, e.g. "time step dt".
        what: &'static str,
        /// The offending value as written by the caller.
        value: String,
        /// What it must be instead.
        reason: &'static str,
    },
}

impl OdeError {
    pub(crate) fn invalid(what: &'static str, value: impl std::fmt::Debug, reason: &'static str) -> Self {
        OdeError::InvalidArgument {
            what,
            value: format!("{value:?}"),
            reason,
        }
    }
}

/// Checks that every component is finite.
pub(crate) fn check_finite<const N: usize>(what: &'static str, values: [f64; N]) -> Result<[f64; N], OdeError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(values)
    } else {
        Err(OdeError::invalid(what, values, "every component must be finite"))
    }
}

/// Checks that a value is finite and strictly positive.
pub(crate) fn check_positive(what: &'static str, value: f64) -> Result<f64, OdeError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(OdeError::invalid(what, value, "must be finite and > 0"))
    }
}
