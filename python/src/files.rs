//! Network files in the CLI's format (docs/file-formats.md, "Network
//! files"), and `replay`, which flies one as `psa-esp replay` does.

use std::path::PathBuf;

use esp_neuroevolution::math::Exponential;
use esp_neuroevolution::network::Network as Weights;
use esp_neuroevolution::rng::stream;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods};
use psa_experiment::champion::robustness::TrialSummary;
use psa_experiment::RunConfig;
use psa_sim::named::Named;
use psa_sim::psa::settings::limits::{check_as, MAX_TRIALS};
use psa_sim::psa::{NetworkFile, NoiseSettings, PsaSettings, Task, TrialRunner, INPUT_COUNT, THRUSTER_COUNT};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyModule};

use crate::args;
use crate::config::{overlay, run_config, type_name};
use crate::errors;
use crate::evaluate::{task_arg, REPLAY_STREAM};
use crate::weights::{network_arrays, networks_from};

/// A JSON value as the Python value `json.loads` makes of it.
fn to_python<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| PyValueError::new_err(e.to_string()))?;
    PyModule::import(py, "json")?.call_method1("loads", (text,))
}

/// A controller of the PSA with the file it is saved as: its weights, the
/// task and the problem it was evolved under, and its provenance.
///
/// `Network(weights, task=1, config=None, *, lesioned=None,
/// provenance=None, preset="baseline", backend=None)` makes one from a
/// float64 array (hidden, 11) or (hidden * 11,), the problem from the
/// configuration `config` resolves to (see `evaluate`); `load_network`
/// reads one from a file; `save` writes it.
#[pyclass(module = "psa_esp._native", frozen)]
pub struct Network {
    file: NetworkFile,
    network: Weights,
}

impl Network {
    /// The problem the network was evolved under: the file's, or (a file
    /// of an older build) the default model with the file's input scaling.
    fn recorded_problem(&self) -> PsaSettings {
        match &self.file.problem {
            Some(problem) => problem.clone(),
            None => PsaSettings {
                sensors: self.file.input_scaling,
                ..PsaSettings::default()
            },
        }
    }
}

#[pymethods]
impl Network {
    #[new]
    #[pyo3(signature = (weights, task=None, config=None, *, lesioned=None, provenance=None, preset="baseline", backend=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        weights: &Bound<'_, PyAny>,
        task: Option<&Bound<'_, PyAny>>,
        config: Option<&Bound<'_, PyAny>>,
        lesioned: Option<&Bound<'_, PyAny>>,
        provenance: Option<&Bound<'_, PyDict>>,
        preset: &str,
        backend: Option<&str>,
    ) -> PyResult<Network> {
        // Task 1 when left out (or None).
        let task = task
            .filter(|task| !task.is_none())
            .map_or(Ok(Task::StopRotation), task_arg)?;
        let network = networks_from(weights, INPUT_COUNT, THRUSTER_COUNT, lesioned, true)?
            .pop()
            .expect("one network");
        let problem = run_config(config, preset, backend)?.problem;
        let extra = match provenance {
            None => serde_json::Map::new(),
            Some(dict) => {
                let text: String = PyModule::import(py, "json")?
                    .call_method1("dumps", (dict,))?
                    .extract()?;
                serde_json::from_str(&text).map_err(|e| PyValueError::new_err(format!("provenance: {e}")))?
            }
        };
        let file = NetworkFile::new(&network, task, &problem, &psa_experiment::build_info(), extra);
        Ok(Network { file, network })
    }

    /// The weights, (hidden, 11): each hidden neuron's 7 input weights
    /// (bias last), then its 4 output weights.
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        network_arrays(py, &self.network).0
    }

    /// Which hidden neurons are switched off, (hidden,).
    #[getter]
    fn lesioned<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        network_arrays(py, &self.network).1
    }

    /// Hidden neurons.
    #[getter]
    fn hidden(&self) -> usize {
        self.network.hidden()
    }

    /// The task the network was evolved for, 1 to 3.
    #[getter]
    fn task(&self) -> u8 {
        self.file.task.number()
    }

    /// The problem settings it was evolved under (the file's `problem`),
    /// as a dict; `{"problem": network.problem}` is a `config`.
    #[getter]
    fn problem<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let value = serde_json::to_value(self.recorded_problem()).map_err(|e| PyValueError::new_err(e.to_string()))?;
        to_python(py, &value)
    }

    /// Where it came from: tool version, git commit, libode version, and
    /// whatever its writer added (seed, configuration, fitness).
    #[getter]
    fn provenance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &serde_json::Value::Object(self.file.provenance.clone()))
    }

    /// The network's outputs (the four thrusters, before noise and
    /// clamping) for `inputs`, with the exponential of the problem it was
    /// evolved under: the bits a trial computes. `inputs` is one
    /// observation (7 floats, as the environment observes them), giving 4
    /// outputs, or a batch of shape (N, 7), giving (N, 4).
    fn activate<'py>(&self, py: Python<'py>, inputs: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let array = py
            .import("numpy")?
            .call_method1("asarray", (inputs, "float64"))
            .and_then(|array| Ok(array.cast_into::<PyArrayDyn<f64>>()?))
            .map_err(|_| {
                PyTypeError::new_err(format!(
                    "inputs must be {INPUT_COUNT} floats or an array of shape (N, {INPUT_COUNT}), got {}",
                    type_name(inputs)
                ))
            })?;
        let readonly = array.try_readonly().map_err(|e| PyValueError::new_err(e.to_string()))?;
        let view = readonly.as_array();
        let exponential: Exponential = self.recorded_problem().exponential;
        let shape = view.shape().to_vec();
        let count = match shape[..] {
            [INPUT_COUNT] => None,
            [count, INPUT_COUNT] => Some(count),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "inputs must be {INPUT_COUNT} floats or an array of shape (N, {INPUT_COUNT}), got shape {shape:?}"
                )))
            }
        };
        let flat: Vec<f64> = view.iter().copied().collect();
        let mut outputs = vec![0.0; flat.len() / INPUT_COUNT * THRUSTER_COUNT];
        for (observation, out) in flat
            .chunks_exact(INPUT_COUNT)
            .zip(outputs.chunks_exact_mut(THRUSTER_COUNT))
        {
            self.network.activate_with(exponential, observation, out);
        }
        Ok(match count {
            None => PyArray1::from_vec(py, outputs).into_any(),
            Some(count) => Array2::from_shape_vec((count, THRUSTER_COUNT), outputs)
                .map_err(|e| PyValueError::new_err(e.to_string()))?
                .into_pyarray(py)
                .into_any(),
        })
    }

    /// The network file as JSON text, as `save` writes it.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.file).map_err(errors::network_file)
    }

    /// Writes the network file (atomically), in the CLI's format.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.file.save(&path).map_err(errors::network_file)
    }

    /// Pickles (and copies) through the network file's JSON.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((restorer(py, "_network_from_json")?, (self.to_json()?,)))
    }

    fn __repr__(&self) -> String {
        format!(
            "<psa_esp.Network {} hidden neurons, task {}>",
            self.network.hidden(),
            self.file.task
        )
    }
}

/// The network of a network file's JSON text (what `Network.to_json`
/// gives): how a `Network` unpickles.
#[pyfunction]
pub fn _network_from_json(text: &str) -> PyResult<Network> {
    let (file, network) =
        NetworkFile::parse(text, std::path::Path::new("<pickled network>")).map_err(errors::network_file)?;
    Ok(Network { file, network })
}

/// The function of `psa_esp._native` named `name`, which restores an
/// object from its saved form (what `__reduce__` gives pickle).
pub fn restorer<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("psa_esp._native")?.getattr(name)
}

/// Reads a network file (`champion.json`, or any file `save` wrote),
/// checking its format, version, sizes and weights; raises
/// `NetworkFileError` naming the file and the problem.
#[pyfunction]
pub fn load_network(path: PathBuf) -> PyResult<Network> {
    let (file, network) = NetworkFile::load(&path).map_err(errors::network_file)?;
    Ok(Network { file, network })
}

/// Flies a network as `psa-esp replay` does, with its options and
/// defaults, and returns what `replay --json` prints but the files:
/// `task`, `backend`, `trials`, `seed`, `input_noise`, `output_noise`,
/// `random_init`, `fitness_percent_mean`, `fitness_percent_sd` and
/// `fitness_percent_per_trial`, the same bits. `network` is a `Network`
/// or the path of a network file. It flies on the model the file records
/// (`default_model=True`: this build's default model), with `config`
/// laid over it; the noise and random starts are the arguments'.
#[pyfunction]
#[pyo3(signature = (network, task=None, *, backend="ode", input_noise=0.0, output_noise=0.0, random_init=false, trials=None, seed=None, config=None, default_model=false))]
#[allow(clippy::too_many_arguments)]
pub fn replay<'py>(
    py: Python<'py>,
    network: &Bound<'py, PyAny>,
    task: Option<&Bound<'py, PyAny>>,
    backend: &str,
    input_noise: f64,
    output_noise: f64,
    random_init: bool,
    trials: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    config: Option<&Bound<'py, PyAny>>,
    default_model: bool,
) -> PyResult<Bound<'py, PyDict>> {
    check_as("noise.input_sd", "input_noise", input_noise).map_err(PyValueError::new_err)?;
    check_as("noise.output_sd", "output_noise", output_noise).map_err(PyValueError::new_err)?;
    // trials and seed: 1 when left out (or None), as `psa-esp replay`'s.
    let trials = args::optional_count(trials, "trials")?.unwrap_or(1) as u64;
    let seed = match seed.filter(|seed| !seed.is_none()) {
        Some(seed) => args::seed(seed, "seed")?,
        None => 1,
    };
    if !(1..=MAX_TRIALS).contains(&trials) {
        return Err(PyValueError::new_err(format!(
            "trials must be in [1, {MAX_TRIALS}], got {trials}"
        )));
    }
    let loaded;
    let network: &Network = match network.cast::<Network>() {
        Ok(network) => network.get(),
        Err(_) => {
            let path: PathBuf = network.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "network must be a Network or the path of a network file, got {}",
                    type_name(network)
                ))
            })?;
            loaded = load_network(path)?;
            &loaded
        }
    };
    let task = match task {
        Some(task) if !task.is_none() => task_arg(task)?,
        _ => network.file.task,
    };
    if random_init && !task.has_random_init() {
        return Err(PyValueError::new_err(format!(
            "random_init: task {task} has no random-initialisation variant (tasks 1 and 3 have)"
        )));
    }
    let recorded = if default_model {
        PsaSettings::default()
    } else {
        network.recorded_problem()
    };
    let base = RunConfig {
        problem: recorded,
        ..RunConfig::default()
    };
    let model = overlay(base, config)?.problem;
    let settings = PsaSettings {
        backend: backend.parse().map_err(errors::config)?,
        trials: trials as usize,
        random_init,
        noise: NoiseSettings {
            input_sd: input_noise,
            output_sd: output_noise,
            ..model.noise
        },
        ..model
    };
    let weights = &network.network;
    let per_trial = py
        .detach(|| -> Result<Vec<f64>, psa_sim::psa::PsaError> {
            let mut runner = TrialRunner::new(&settings, task)?;
            let mut rng = stream(seed, &[REPLAY_STREAM]);
            let maximum = runner.maximum_points();
            (0..settings.trials)
                .map(|_| Ok(100.0 * runner.run_trial(weights, &mut rng, None)? / maximum))
                .collect()
        })
        .map_err(errors::simulation)?;
    let TrialSummary { mean, sd } = TrialSummary::of(&per_trial);
    let d = PyDict::new(py);
    d.set_item("task", task.number())?;
    d.set_item("backend", settings.backend.name())?;
    d.set_item("trials", trials)?;
    d.set_item("seed", seed)?;
    d.set_item("input_noise", input_noise)?;
    d.set_item("output_noise", output_noise)?;
    d.set_item("random_init", random_init)?;
    d.set_item("fitness_percent_mean", mean)?;
    d.set_item("fitness_percent_sd", sd)?;
    d.set_item("fitness_percent_per_trial", per_trial)?;
    Ok(d)
}
