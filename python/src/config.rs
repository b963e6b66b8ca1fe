//! Run configurations from Python: a preset, with a dict or a TOML file
//! laid over it, read by `psa-experiment` as `psa-esp evolve --config`
//! reads a file (an unknown key or an out-of-range value is an error
//! naming it).

use std::path::PathBuf;

use psa_experiment::{Preset, RunConfig};
use psa_sim::physics::BackendKind;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::errors;

/// The backend of the package's base configuration: `native`, the same
/// bits as `ode`, per network-step on AVX-512 17.7 times faster than
/// ODE in lockstep and 19.7 times faster than ODE with a world a network
/// (docs/performance.md, "The evaluation paths"). A
/// configuration that names a backend (a run's `config.toml` does) keeps it.
pub const DEFAULT_BACKEND: BackendKind = BackendKind::Native;

/// `preset`'s configuration on the package's default backend, `config` (a
/// dict of settings or the path of a TOML file, as `--config` takes) laid
/// over it, then `backend` if given.
pub fn run_config(config: Option<&Bound<'_, PyAny>>, preset: &str, backend: Option<&str>) -> PyResult<RunConfig> {
    // Presets are named with hyphens ("hill-climb"); the underscores of
    // the algorithms' names ("hill_climb") are taken as well.
    let preset: Preset = preset.replace('_', "-").parse().map_err(errors::config)?;
    let mut base = preset.config();
    base.problem.backend = DEFAULT_BACKEND;
    let mut resolved = overlay(base, config)?;
    if let Some(backend) = backend {
        resolved.problem.backend = backend.parse().map_err(errors::config)?;
    }
    resolved.validate().map_err(errors::config_chain)?;
    Ok(resolved)
}

/// `base` with `config` (None, a dict of settings or the path of a TOML
/// file) laid over it, checked.
pub fn overlay(base: RunConfig, config: Option<&Bound<'_, PyAny>>) -> PyResult<RunConfig> {
    match config {
        None => Ok(base),
        Some(config) if config.is_none() => Ok(base),
        Some(config) if config.cast::<PyDict>().is_ok() => {
            let text = match to_toml(config, "config")? {
                toml::Value::Table(table) => toml::to_string(&table).map_err(|e| errors::config(e.to_string()))?,
                _ => unreachable!("a dict converts to a table"),
            };
            base.with_overrides(&text).map_err(errors::config_chain)
        }
        Some(config) => {
            let path: PathBuf = config.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "config must be a dict of settings or the path of a TOML file, got {}",
                    type_name(config)
                ))
            })?;
            base.with_overrides_from(&path).map_err(errors::config_chain)
        }
    }
}

/// The Python type's name of `value`, for messages.
pub fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map_or_else(|_| "an unknown type".into(), |n| n.to_string())
}

/// A Python value of a settings dict as TOML: bool, int, float, str, and
/// lists and dicts of them; `key` names it in an error.
fn to_toml(value: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    if value.cast::<PyBool>().is_ok() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if value.cast::<PyInt>().is_ok() {
        let n: i64 = value
            .extract()
            .map_err(|_| errors::config(format!("{key}: {value} does not fit a 64-bit integer")))?;
        return Ok(toml::Value::Integer(n));
    }
    if value.cast::<PyFloat>().is_ok() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if let Ok(text) = value.cast::<PyString>() {
        return Ok(toml::Value::String(text.to_cow()?.into_owned()));
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in dict.iter() {
            let name: String = k
                .extract()
                .map_err(|_| errors::config(format!("{key}: keys must be strings, got {}", type_name(&k))))?;
            let path = if key == "config" {
                name.clone()
            } else {
                format!("{key}.{name}")
            };
            table.insert(name, to_toml(&v, &path)?);
        }
        return Ok(toml::Value::Table(table));
    }
    if value.cast::<PyList>().is_ok() || value.cast::<PyTuple>().is_ok() {
        let items: Vec<Bound<'_, PyAny>> = value.try_iter()?.collect::<PyResult<_>>()?;
        return items
            .iter()
            .map(|item| to_toml(item, key))
            .collect::<PyResult<Vec<_>>>()
            .map(toml::Value::Array);
    }
    Err(errors::config(format!(
        "{key}: a setting must be a bool, int, float, str, list or dict, got {}",
        type_name(value)
    )))
}

/// The whole configuration `config` resolves to, as TOML: the text of the
/// `config.toml` a run writes, which `psa-esp evolve --config` and every
/// function here taking `config` accept back. `config` is a dict of
/// settings (`{"problem": {"trials": 3}}`) or the path of a TOML file,
/// laid over `preset` on the `native` backend. Raises `ConfigError` on an
/// unknown key or an out-of-range value, naming it.
#[pyfunction]
#[pyo3(signature = (config=None, *, preset="baseline", backend=None))]
pub fn resolve_config(config: Option<&Bound<'_, PyAny>>, preset: &str, backend: Option<&str>) -> PyResult<String> {
    run_config(config, preset, backend)?
        .to_toml()
        .map_err(errors::config_chain)
}
