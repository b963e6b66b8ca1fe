//! A run's records and result as Python dicts.

use esp_neuroevolution::{Champion, Ending, GenerationRecord, LesionOutcome, RunResult};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::weights::network_arrays;

/// A generation's (cycle's) record, with the keys of `records.csv`'s
/// columns: `lesion` is None, `"add"` or `"remove K"`.
pub fn record<'py>(py: Python<'py>, r: &GenerationRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("generation", r.generation)?;
    d.set_item("min", r.min)?;
    d.set_item("mean", r.mean)?;
    d.set_item("max", r.max)?;
    d.set_item("best", r.best)?;
    d.set_item("champion", r.champion)?;
    d.set_item("evaluations", r.evaluations)?;
    d.set_item("subpops", r.subpops)?;
    d.set_item("burst", r.burst)?;
    d.set_item("bursts", r.bursts)?;
    d.set_item(
        "lesion",
        r.lesion.map(|lesion| match lesion {
            LesionOutcome::Add => "add".to_string(),
            LesionOutcome::Remove { neuron } => format!("remove {neuron}"),
        }),
    )?;
    Ok(d)
}

/// Why a run ended, by name.
pub fn ending(ending: Ending) -> &'static str {
    match ending {
        Ending::Completed => "completed",
        Ending::Goal => "goal",
        Ending::Budget => "budget",
        Ending::Stopped => "stopped",
    }
}

/// The champion: `weights` (hidden, genes), `lesioned`, `fitness`,
/// `generation` and `evaluation`.
pub fn champion<'py>(py: Python<'py>, c: &Champion) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let (weights, lesioned) = network_arrays(py, &c.network);
    d.set_item("weights", weights)?;
    d.set_item("lesioned", lesioned)?;
    d.set_item("fitness", c.fitness)?;
    d.set_item("generation", c.generation)?;
    d.set_item("evaluation", c.evaluation)?;
    Ok(d)
}

/// A run's result: `champion`, `records` and `ending`.
pub fn result<'py>(py: Python<'py>, r: &RunResult) -> PyResult<Bound<'py, PyDict>> {
    let d = so_far(py, &r.champion, &r.records)?;
    d.set_item("ending", ending(r.ending))?;
    Ok(d)
}

/// A run's result while it goes on: the best network so far, the records
/// so far, and `ending` None.
pub fn so_far<'py>(py: Python<'py>, best: &Champion, records: &[GenerationRecord]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("champion", champion(py, best)?)?;
    let records = records.iter().map(|x| record(py, x)).collect::<PyResult<Vec<_>>>()?;
    d.set_item("records", records)?;
    d.set_item("ending", py.None())?;
    Ok(d)
}
