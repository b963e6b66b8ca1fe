//! Many trials of one task stepped in one call: the native side of the
//! vectorised environment (`psa_esp.env.PsaVectorEnv`). Each trial is a
//! [`Trial`] and each step its step, so a batch flies exactly what its
//! single environments fly; only the Python loop around them is gone.

use numpy::ndarray::{aview1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use psa_sim::psa::{INPUT_COUNT, THRUSTER_COUNT};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::args;
use crate::trial::Trial;

/// What a batch's step gives: observations (N, 7), rewards (N,), which
/// trials are over (N,).
type Stepped<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
);

/// The most trials a batch holds: each has its own physics world.
pub const MAX_TRIALS_IN_BATCH: usize = 100_000;

/// `TrialBatch(count, task, config=None, *, preset="baseline",
/// backend=None, random_init=None)`: `count` trials made as
/// `Trial(task, config, ...)` makes one. Steps on the thread that made it.
#[pyclass(module = "psa_esp._native")]
pub struct TrialBatch {
    trials: Vec<Trial>,
}

impl TrialBatch {
    /// Trial `index`, or a `ValueError` naming the range.
    fn trial(&mut self, index: usize) -> PyResult<&mut Trial> {
        let count = self.trials.len();
        self.trials
            .get_mut(index)
            .ok_or_else(|| PyValueError::new_err(format!("index must be in [0, {count}), got {index}")))
    }
}

#[pymethods]
impl TrialBatch {
    #[new]
    #[pyo3(signature = (count, task, config=None, *, preset="baseline", backend=None, random_init=None))]
    fn new(
        count: &Bound<'_, PyAny>,
        task: &Bound<'_, PyAny>,
        config: Option<&Bound<'_, PyAny>>,
        preset: &str,
        backend: Option<&str>,
        random_init: Option<bool>,
    ) -> PyResult<TrialBatch> {
        let count = args::count(count, "count")?;
        if !(1..=MAX_TRIALS_IN_BATCH).contains(&count) {
            return Err(PyValueError::new_err(format!(
                "count must be in [1, {MAX_TRIALS_IN_BATCH}], got {count}"
            )));
        }
        let trials = (0..count)
            .map(|_| Trial::new(task, config, preset, backend, random_init))
            .collect::<PyResult<Vec<Trial>>>()?;
        Ok(TrialBatch { trials })
    }

    /// Starts trial `index` with the random stream of `seed`, as
    /// `Trial.reset(seed)` does; returns its first observation.
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        index: usize,
        seed: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let seed = args::seed(seed, "seed")?;
        let inputs = self.trial(index)?.start(seed)?;
        Ok(PyArray1::from_slice(py, &inputs))
    }

    /// Steps every trial not in `skip` (a bool array, one per trial) with
    /// its row of `thrust` (an (N, 4) float64 array), as `Trial.step`
    /// does. Returns the observations (N, 7), the rewards (N,) and which
    /// trials are over (N,); a skipped trial gives its last observation,
    /// reward 0 and not over.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        thrust: PyReadonlyArray2<'py, f64>,
        skip: PyReadonlyArray1<'py, bool>,
    ) -> PyResult<Stepped<'py>> {
        let count = self.trials.len();
        let thrust = thrust.as_array();
        let skip = skip.as_array();
        if thrust.shape() != [count, THRUSTER_COUNT] || skip.len() != count {
            return Err(PyValueError::new_err(format!(
                "thrust must have shape ({count}, {THRUSTER_COUNT}) and skip ({count},), got {:?} and {:?}",
                thrust.shape(),
                skip.shape()
            )));
        }
        let mut observations = Array2::zeros((count, INPUT_COUNT));
        let mut rewards = vec![0.0; count];
        let mut over = vec![false; count];
        for (i, trial) in self.trials.iter_mut().enumerate() {
            let inputs = if skip[i] {
                trial.observation()?
            } else {
                let mut outputs = [0.0; THRUSTER_COUNT];
                for (out, value) in outputs.iter_mut().zip(thrust.row(i)) {
                    *out = *value;
                }
                let (inputs, reward) = trial.advance(outputs)?;
                rewards[i] = reward;
                over[i] = trial.is_over();
                inputs
            };
            observations.row_mut(i).assign(&aview1(&inputs));
        }
        Ok((
            observations.into_pyarray(py),
            PyArray1::from_vec(py, rewards),
            PyArray1::from_vec(py, over),
        ))
    }

    /// Each trial's fitness so far, in % of the task's maximum (N,).
    #[getter]
    fn fitness<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_iter(py, self.trials.iter().map(Trial::fitness_so_far))
    }

    /// Each body's state (N, 6): x, y, heading, vx, vy, omega, as
    /// `Trial.state`.
    #[getter]
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let mut states = Array2::zeros((self.trials.len(), 6));
        for (i, trial) in self.trials.iter().enumerate() {
            states.row_mut(i).assign(&aview1(&trial.body_state()?));
        }
        Ok(states.into_pyarray(py))
    }

    fn __len__(&self) -> usize {
        self.trials.len()
    }

    fn __repr__(&self) -> String {
        format!("TrialBatch({} trials)", self.trials.len())
    }
}
