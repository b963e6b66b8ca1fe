//! Integer arguments as NumPy users pass them: Python ints and NumPy
//! integers alike (anything with `__index__`), a negative count or seed a
//! `ValueError` naming the argument, and seeds drawn fresh from the
//! operating system's entropy where `None` asks for one.

use pyo3::exceptions::{PyOverflowError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBool;

use crate::config::type_name;

/// `value` as an integer (a Python int or a NumPy integer), or a
/// `TypeError` naming `name`; a bool is refused.
fn integer(value: &Bound<'_, PyAny>, name: &str) -> PyResult<i128> {
    let refuse = || {
        PyTypeError::new_err(format!(
            "{name} must be an integer (int or a NumPy integer), got {}",
            type_name(value)
        ))
    };
    if value.is_instance_of::<PyBool>() {
        return Err(refuse());
    }
    value.extract::<i128>().map_err(|error| {
        if error.is_instance_of::<PyOverflowError>(value.py()) {
            PyValueError::new_err(format!("{name} is out of range, got {value}"))
        } else {
            refuse()
        }
    })
}

/// `value` as a count (an integer >= 0), or a `ValueError` naming `name`.
pub fn count(value: &Bound<'_, PyAny>, name: &str) -> PyResult<usize> {
    let int = integer(value, name)?;
    usize::try_from(int).map_err(|_| PyValueError::new_err(format!("{name} must be a non-negative integer, got {int}")))
}

/// `value` (None: absent) as a count.
pub fn optional_count(value: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<Option<usize>> {
    value.filter(|v| !v.is_none()).map(|v| count(v, name)).transpose()
}

/// `value` as a seed (an integer in [0, 2**64)), or a `ValueError`.
pub fn seed(value: &Bound<'_, PyAny>, name: &str) -> PyResult<u64> {
    let int = integer(value, name)?;
    u64::try_from(int).map_err(|_| PyValueError::new_err(format!("{name} must be an integer in [0, 2**64), got {int}")))
}

/// Whether `value` is one integer (not a sequence of them).
pub fn is_integer(value: &Bound<'_, PyAny>) -> bool {
    !value.is_instance_of::<PyBool>() && value.extract::<i128>().is_ok()
}

/// A seed drawn from the operating system's entropy (Python's `secrets`),
/// for `seed=None`: callers return or record it, as NumPy's
/// `default_rng(None)` keeps the entropy it drew.
pub fn fresh_seed(py: Python<'_>) -> PyResult<u64> {
    py.import("secrets")?.call_method1("randbits", (64,))?.extract()
}

/// `value` (None: a fresh seed) as a seed.
pub fn seed_or_fresh(py: Python<'_>, value: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<u64> {
    match value.filter(|v| !v.is_none()) {
        Some(value) => seed(value, name),
        None => fresh_seed(py),
    }
}

/// A `seed` argument: left out (the documented default), or given, None
/// included (a fresh seed).
pub enum SeedArg<'py> {
    /// Not passed.
    Default,
    /// Passed, possibly as None.
    Given(Bound<'py, PyAny>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for SeedArg<'py> {
    type Error = PyErr;

    fn extract(value: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        Ok(SeedArg::Given(value.to_owned()))
    }
}
