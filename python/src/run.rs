//! ESP and the hill-climber from Python: runs driven by ask and tell over
//! NumPy arrays with the crate's tickets, by the PSA natively, or by a
//! Python fitness function; saved and resumed through the crate's serde.

use std::path::PathBuf;

use esp_neuroevolution::network::{Network, NetworkSet};
use esp_neuroevolution::{
    AnyRun, AskPurpose, AskTell, Esp, GenerationRecord, HillClimb, RunError, RunResult, StopAt, MAX_NETWORK_SIDE,
};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use psa_experiment::{Algorithm, RunConfig, RunStart};
use psa_sim::evaluator::PsaEvaluator;
use psa_sim::named::Named;
use psa_sim::psa::{NetworkFile, INPUT_COUNT, THRUSTER_COUNT};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::{self, SeedArg};
use crate::config::{run_config, type_name};
use crate::evaluate::{eval_path, in_pieces, pool, task_arg, DEFAULT_SEED};
use crate::files::restorer;
use crate::weights::{arrays_of, float_array, networks_from};
use crate::{errors, records};

/// The `format` of a saved run.
const SAVED_FORMAT: &str = "psa-esp-python-run";
/// The version of a saved run this build writes and reads.
const SAVED_VERSION: u64 = 1;

/// The receipt of an ask: `Run.tell` takes it with the fitness of the
/// networks asked, and refuses one of another run (`ForeignTicketError`)
/// or of an ask told already (`TicketToldError`).
#[pyclass(module = "psa_esp._native", frozen)]
#[derive(Clone, Copy)]
pub struct Ticket {
    inner: esp_neuroevolution::Ticket,
}

impl Ticket {
    /// The ticket's saved form: its run's and its ask's numbers.
    fn saved(&self) -> PyResult<serde_json::Value> {
        serde_json::to_value(self.inner).map_err(|e| errors::restore(e.to_string()))
    }
}

#[pymethods]
impl Ticket {
    /// Pickles (and copies) through the crate's serde: a ticket pickled
    /// with its ask to another process tells the run it came from.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((restorer(py, "_ticket_from_json")?, (self.saved()?.to_string(),)))
    }

    fn __repr__(&self) -> PyResult<String> {
        let saved = self.saved()?;
        Ok(format!("<psa_esp.Ticket ask {} of run {}>", saved["ask"], saved["run"]))
    }
}

/// The ticket of a ticket's saved form: how a `Ticket` unpickles.
#[pyfunction]
pub fn _ticket_from_json(text: &str) -> PyResult<Ticket> {
    let inner = serde_json::from_str(text).map_err(|e| errors::restore(format!("cannot restore the ticket: {e}")))?;
    Ok(Ticket { inner })
}

/// The networks a run asks to have evaluated.
///
/// `weights` is a float64 array (networks, hidden, genes): each hidden
/// neuron's input weights (bias last), then its output weights. A
/// lesioned neuron (`lesioned[j, k]`, in a lesion test) has zero weights,
/// which add exactly nothing to the outputs, so any evaluator of the
/// weights as they are scores the network as the crate does. Network `j`
/// must be scored with the random stream `(seed, key + [j])` where the
/// problem is random; `Run.evaluate_psa` does so for the PSA.
#[pyclass(module = "psa_esp._native", frozen)]
pub struct Asked {
    ticket: esp_neuroevolution::Ticket,
    purpose: AskPurpose,
    seed: u64,
    key: Vec<u64>,
    networks: Vec<Network>,
    weights: Py<PyArray3<f64>>,
    lesioned: Py<PyArray2<bool>>,
}

#[pymethods]
impl Asked {
    /// The ticket to tell the fitness with.
    #[getter]
    fn ticket(&self) -> Ticket {
        Ticket { inner: self.ticket }
    }

    /// The networks' weights, (networks, hidden, genes).
    #[getter]
    fn weights(&self, py: Python<'_>) -> Py<PyArray3<f64>> {
        self.weights.clone_ref(py)
    }

    /// Which hidden neurons are switched off, (networks, hidden).
    #[getter]
    fn lesioned(&self, py: Python<'_>) -> Py<PyArray2<bool>> {
        self.lesioned.clone_ref(py)
    }

    /// What the networks are for: `"generation"`, `"lesion_test"` or
    /// `"base"` (the hill-climber's first network).
    #[getter]
    fn purpose(&self) -> &'static str {
        match self.purpose {
            AskPurpose::Generation(_) => "generation",
            AskPurpose::LesionTest(_) => "lesion_test",
            AskPurpose::Base => "base",
        }
    }

    /// The generation (cycle) the networks belong to, from 1 (None for
    /// the hill-climber's base).
    #[getter]
    fn generation(&self) -> Option<usize> {
        match self.purpose {
            AskPurpose::Generation(g) | AskPurpose::LesionTest(g) => Some(g),
            AskPurpose::Base => None,
        }
    }

    /// The run's seed: network `j`'s random stream is `(seed, key + [j])`.
    #[getter]
    fn seed(&self) -> u64 {
        self.seed
    }

    /// The key prefix of the networks' random streams.
    #[getter]
    fn key(&self) -> Vec<u64> {
        self.key.clone()
    }

    fn __len__(&self) -> usize {
        self.networks.len()
    }

    /// Pickles (and copies) through its saved form: the ticket, the
    /// purpose, the random streams and the arrays; the networks are the
    /// arrays' again, bit for bit.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Ticket,
            String,
            u64,
            Vec<u64>,
            Py<PyArray3<f64>>,
            Py<PyArray2<bool>>,
            usize,
        ),
    )> {
        let purpose = serde_json::to_string(&self.purpose).map_err(|e| errors::restore(e.to_string()))?;
        let inputs = self.networks.first().map_or(0, |n| n.inputs());
        Ok((
            restorer(py, "_asked_from_state")?,
            (
                self.ticket(),
                purpose,
                self.seed,
                self.key.clone(),
                self.weights(py),
                self.lesioned(py),
                inputs,
            ),
        ))
    }

    fn __repr__(&self) -> String {
        let what = match self.purpose {
            AskPurpose::Generation(g) => format!("generation {g}"),
            AskPurpose::LesionTest(g) => format!("the lesion test of generation {g}"),
            AskPurpose::Base => "the base network".to_string(),
        };
        format!(
            "<psa_esp.Asked {} networks for {what}, seed {}>",
            self.networks.len(),
            self.seed
        )
    }
}

/// The ask of an ask's saved form (`Asked.__reduce__`): how an `Asked`
/// unpickles.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn _asked_from_state(
    ticket: &Bound<'_, Ticket>,
    purpose: &str,
    seed: u64,
    key: Vec<u64>,
    weights: Bound<'_, PyArray3<f64>>,
    lesioned: Bound<'_, PyArray2<bool>>,
    inputs: usize,
) -> PyResult<Asked> {
    let bad = |e: String| errors::restore(format!("cannot restore the ask: {e}"));
    let purpose: AskPurpose = serde_json::from_str(purpose).map_err(|e| bad(e.to_string()))?;
    let genes = weights.shape()[2];
    let outputs = genes
        .checked_sub(inputs)
        .ok_or_else(|| bad(format!("{inputs} inputs of {genes} genes")))?;
    let networks = if weights.shape()[0] == 0 {
        Vec::new()
    } else {
        networks_from(weights.as_any(), inputs, outputs, Some(lesioned.as_any()), false)?
    };
    Ok(Asked {
        ticket: ticket.get().inner,
        purpose,
        seed,
        key,
        networks,
        weights: weights.unbind(),
        lesioned: lesioned.unbind(),
    })
}

/// A run of ESP or of the hill-climber, driven from Python.
///
/// `Run(algorithm=None, *, seed=1, config=None, preset="baseline", ...)`
/// starts the configuration `preset` with `config` (a dict of settings or
/// a TOML file) laid over it, as `psa-esp evolve --preset P --config F
/// --seed S` does; `algorithm` (`"esp"` or `"hill_climb"`) replaces the
/// configuration's, `generations` its generations (cycles), `goal` and
/// `max_evaluations` end it early. `inputs` and `outputs` size the
/// networks (the PSA's 7 and 4 by default; any for a problem of your own).
///
/// Drive it with `ask` and `tell`, or let `run_psa` (the PSA, natively,
/// bit for bit what `psa-esp evolve` gives) or `optimize` (a Python
/// fitness function) do it. `to_json` and `from_json` save and restore it
/// at any point between asks and tells.
#[pyclass(module = "psa_esp._native")]
pub struct Run {
    config: RunConfig,
    label: String,
    seed: u64,
    inputs: usize,
    outputs: usize,
    run: AnyRun,
}

/// `fitness` as told: a float64 (or float32) array of one dimension, or
/// a sequence of numbers.
fn fitness_values(fitness: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if fitness.cast::<PyUntypedArray>().is_ok() {
        let typed = float_array(fitness, "fitness")?;
        let readonly = typed.try_readonly().map_err(|e| PyValueError::new_err(e.to_string()))?;
        let view = readonly.as_array();
        if view.ndim() != 1 {
            return Err(PyValueError::new_err(format!(
                "fitness must have one dimension (one value per network), got shape {:?}",
                view.shape()
            )));
        }
        return Ok(view.iter().copied().collect());
    }
    fitness.extract::<Vec<f64>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "fitness must be a float64 array or a sequence of numbers, got {}",
            type_name(fitness)
        ))
    })
}

/// The algorithm named `name` ([`Algorithm`]'s names; the hill-climber
/// also as `"hill-climb"`, as its preset is spelt).
fn algorithm_named(name: &str) -> PyResult<Algorithm> {
    name.parse()
        .map_err(|e: String| PyValueError::new_err(format!("algorithm: {e}")))
}

impl Run {
    /// The run of `config` with `seed` on networks of `inputs` and `outputs`.
    fn start(config: &RunConfig, seed: u64, stop: StopAt, inputs: usize, outputs: usize) -> PyResult<AnyRun> {
        Ok(match config.algorithm {
            Algorithm::Esp => Esp::new(config.esp.clone(), seed)
                .map_err(errors::settings)?
                .stop_at(stop)
                .start(inputs, outputs)
                .map_err(errors::run)?
                .into(),
            Algorithm::HillClimb => HillClimb::new(config.hill_climb.clone(), seed)
                .map_err(errors::settings)?
                .stop_at(stop)
                .start(inputs, outputs)
                .map_err(errors::run)?
                .into(),
        })
    }

    /// Tells `fitness` and calls `callback` with the record of a completed
    /// generation, stopping the run when it returns True.
    fn tell_and_report(
        &mut self,
        py: Python<'_>,
        ticket: esp_neuroevolution::Ticket,
        fitness: &[f64],
        callback: Option<&Bound<'_, PyAny>>,
        files: Option<&mut RunStart>,
    ) -> PyResult<()> {
        let record: Option<GenerationRecord> = self.run.tell(ticket, fitness).map_err(errors::run)?.cloned();
        if let Some(record) = record {
            if let Some(files) = files {
                files.record(&record);
            }
            if let Some(callback) = callback {
                if callback.call1((records::record(py, &record)?,))?.is_truthy()? {
                    self.run.stop();
                }
            }
        }
        Ok(())
    }

    /// The ended run's result.
    fn ended(&self) -> PyResult<RunResult> {
        self.run.result().map_err(errors::run)
    }
}

#[pymethods]
impl Run {
    #[new]
    #[pyo3(signature = (algorithm=None, *, seed=SeedArg::Default, config=None, preset="baseline", backend=None, inputs=None, outputs=None, generations=None, goal=None, max_evaluations=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        algorithm: Option<&str>,
        seed: SeedArg<'_>,
        config: Option<&Bound<'_, PyAny>>,
        preset: &str,
        backend: Option<&str>,
        inputs: Option<&Bound<'_, PyAny>>,
        outputs: Option<&Bound<'_, PyAny>>,
        generations: Option<&Bound<'_, PyAny>>,
        goal: Option<f64>,
        max_evaluations: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Run> {
        let seed = match seed {
            SeedArg::Default => DEFAULT_SEED,
            SeedArg::Given(seed) => args::seed_or_fresh(py, Some(&seed), "seed")?,
        };
        let side = |value, name: &str, default| -> PyResult<usize> {
            let n = args::optional_count(value, name)?.unwrap_or(default);
            if !(1..=MAX_NETWORK_SIDE).contains(&n) {
                return Err(PyValueError::new_err(format!(
                    "{name} must be in [1, {MAX_NETWORK_SIDE}], got {n}"
                )));
            }
            Ok(n)
        };
        let inputs = side(inputs, "inputs", INPUT_COUNT)?;
        let outputs = side(outputs, "outputs", THRUSTER_COUNT)?;
        let generations = args::optional_count(generations, "generations")?;
        let max_evaluations = args::optional_count(max_evaluations, "max_evaluations")?;
        if max_evaluations == Some(0) {
            return Err(PyValueError::new_err(
                "max_evaluations must be at least 1 (a run evaluates a whole generation before it can stop), got 0",
            ));
        }
        let max_evaluations = max_evaluations.map(|n| n as u64);
        let mut config = run_config(config, preset, backend)?;
        if let Some(algorithm) = algorithm {
            config.algorithm = algorithm_named(algorithm)?;
        }
        if let Some(generations) = generations {
            config.set_generations(generations).map_err(errors::config_chain)?;
        }
        let stop = StopAt {
            goal,
            evaluations: max_evaluations,
        };
        let run = Run::start(&config, seed, stop, inputs, outputs)?;
        Ok(Run {
            config,
            label: preset.to_string(),
            seed,
            inputs,
            outputs,
            run,
        })
    }

    /// The networks to evaluate next, or None once the run has ended.
    /// Asking again before telling asks for the same networks under the
    /// same ticket.
    fn ask(&mut self, py: Python<'_>) -> PyResult<Option<Asked>> {
        let Some(asked) = self.run.ask().map_err(errors::run)? else {
            return Ok(None);
        };
        let (weights, lesioned) = arrays_of(py, &asked);
        Ok(Some(Asked {
            ticket: asked.ticket(),
            purpose: asked.purpose(),
            seed: asked.seed(),
            key: asked.key().to_vec(),
            networks: (0..asked.len()).map(|j| asked.network(j).into_owned()).collect(),
            weights: weights.unbind(),
            lesioned: lesioned.unbind(),
        }))
    }

    /// Advances the run by the fitness of the networks the ask of `ticket`
    /// asked for, in order (higher is better, any sign, finite). Returns
    /// the record of the generation (cycle) this completes, if it
    /// completes one. Raises, leaving the run as it was: `EndedError`,
    /// `ForeignTicketError`, `TicketToldError`, `FitnessCountError`,
    /// `NanFitnessError`, `InfiniteFitnessError`.
    fn tell<'py>(
        &mut self,
        py: Python<'py>,
        ticket: &Bound<'py, PyAny>,
        fitness: &Bound<'py, PyAny>,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let ticket = ticket.cast::<Ticket>().map_err(|_| {
            PyTypeError::new_err(format!(
                "ticket must be the Ticket of an ask (asked.ticket), got {}",
                type_name(ticket)
            ))
        })?;
        let fitness = fitness_values(fitness)?;
        let record = self.run.tell(ticket.get().inner, &fitness).map_err(errors::run)?;
        record.map(|r| records::record(py, r)).transpose()
    }

    /// Ends the run once its current generation (cycle) is complete.
    fn stop(&mut self) {
        self.run.stop();
    }

    /// Why the run ended (`"completed"`, `"goal"`, `"budget"`,
    /// `"stopped"`), or None while it goes on.
    #[getter]
    fn ending(&self) -> Option<&'static str> {
        self.run.ending().map(records::ending)
    }

    /// The records of the generations (cycles) completed so far.
    #[getter]
    fn records<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.run.records().iter().map(|r| records::record(py, r)).collect()
    }

    /// The run's seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.seed
    }

    /// `"esp"` or `"hill_climb"`.
    #[getter]
    fn algorithm(&self) -> &'static str {
        self.config.algorithm.name()
    }

    /// The run's whole configuration as TOML (a run folder's `config.toml`).
    #[getter]
    fn config(&self) -> PyResult<String> {
        self.config.to_toml().map_err(errors::config_chain)
    }

    /// The run's result: `champion` (`weights`, `lesioned`, `fitness`,
    /// `generation`, `evaluation`), `records` and `ending`. While the run
    /// goes on, the best network so far (as pycma's `result`), with
    /// `ending` None; raises `NotEndedError` before any network has been
    /// told.
    fn result<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        if self.run.ending().is_some() {
            return records::result(py, &self.ended()?);
        }
        let champion = self.run.champion().ok_or_else(|| errors::run(RunError::NotEnded))?;
        records::so_far(py, champion, self.run.records())
    }

    /// The fitness of `asked`'s networks on `task` under the run's
    /// problem settings, each with its own random stream: what `psa-esp
    /// evolve` gives them, bit for bit. The GIL is released.
    #[pyo3(signature = (asked, task, *, eval_path="fastest", threads=None))]
    fn evaluate_psa<'py>(
        &self,
        py: Python<'py>,
        asked: &Bound<'py, Asked>,
        task: &Bound<'py, PyAny>,
        eval_path: &str,
        threads: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let asked = asked.get();
        let evaluator = PsaEvaluator::new(
            self.config.problem.clone(),
            task_arg(task)?,
            &self::eval_path(eval_path)?,
        )
        .map_err(errors::config_chain)?;
        let pool = pool(args::optional_count(threads, "threads")?)?;
        // Each network keeps the stream it has in the whole generation.
        let networks = &asked.networks[..];
        let fitness = in_pieces(
            py,
            &pool,
            &evaluator,
            networks.len(),
            |range| esp_neuroevolution::evaluate_range(&evaluator, networks, asked.seed, &asked.key, range),
            errors::run,
        )?;
        Ok(PyArray1::from_vec(py, fitness))
    }

    /// Runs to the end on the PSA's `task`, natively, evaluating each
    /// generation with the GIL released: the run `psa-esp evolve` makes,
    /// bit for bit. `callback(record)` is called after every generation
    /// (cycle) with its record; returning True stops the run. With `out`
    /// (an empty or new folder), writes the run folder `evolve --out`
    /// writes: `config.toml`, `records.csv`, `champion.json`, `run.json`.
    /// Returns the result.
    #[pyo3(signature = (task, callback=None, *, eval_path="fastest", threads=None, out=None))]
    fn run_psa<'py>(
        &mut self,
        py: Python<'py>,
        task: &Bound<'py, PyAny>,
        callback: Option<&Bound<'py, PyAny>>,
        eval_path: &str,
        threads: Option<&Bound<'py, PyAny>>,
        out: Option<PathBuf>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let task = task_arg(task)?;
        let evaluator = PsaEvaluator::new(self.config.problem.clone(), task, &self::eval_path(eval_path)?)
            .map_err(errors::config_chain)?;
        let pool = pool(args::optional_count(threads, "threads")?)?;
        let mut files = match &out {
            None => None,
            Some(dir) => {
                if dir.read_dir().is_ok_and(|mut entries| entries.next().is_some()) {
                    return Err(PyValueError::new_err(format!(
                        "output directory {} is not empty: results already written are never overwritten",
                        dir.display()
                    )));
                }
                Some(RunStart::new(&self.config, dir).map_err(errors::config_chain)?)
            }
        };
        loop {
            py.check_signals()?;
            let (ticket, fitness) = {
                let Some(asked) = self.run.ask().map_err(errors::run)? else {
                    break;
                };
                let ticket = asked.ticket();
                let fitness = py
                    .detach(|| pool.install(|| asked.evaluate(&evaluator)))
                    .map_err(errors::run)?;
                (ticket, fitness)
            };
            self.tell_and_report(py, ticket, &fitness, callback, files.as_mut())?;
        }
        let result = self.ended()?;
        if let Some(files) = files {
            files
                .finish(&self.config, &self.label, task, self.seed, &result)
                .map_err(errors::config_chain)?;
        }
        records::result(py, &result)
    }

    /// Runs to the end on a fitness function of your own:
    /// `fitness(weights)` takes the asked networks' weights (networks,
    /// hidden, genes) and returns one finite number per network (higher is
    /// better). `callback(record)` as for `run_psa`. Returns the result.
    #[pyo3(signature = (fitness, callback=None))]
    fn optimize<'py>(
        &mut self,
        py: Python<'py>,
        fitness: &Bound<'py, PyAny>,
        callback: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        loop {
            py.check_signals()?;
            let (ticket, weights) = {
                let Some(asked) = self.run.ask().map_err(errors::run)? else {
                    break;
                };
                (asked.ticket(), arrays_of(py, &asked).0)
            };
            let values = fitness_values(&fitness.call1((weights,))?)?;
            self.tell_and_report(py, ticket, &values, callback, None)?;
        }
        records::result(py, &self.ended()?)
    }

    /// The run as JSON (its configuration, seed and whole state, through
    /// the crate's serde): `Run.from_json` restores it, to end exactly as
    /// the run never stopped would have. Tickets of asks made before are
    /// foreign to the restored run: ask again.
    fn to_json(&self) -> PyResult<String> {
        let state = serde_json::to_value(&self.run).map_err(|e| errors::restore(e.to_string()))?;
        let saved = serde_json::json!({
            "format": SAVED_FORMAT,
            "version": SAVED_VERSION,
            "label": self.label,
            "seed": self.seed.to_string(),
            "inputs": self.inputs,
            "outputs": self.outputs,
            "config": self.config.to_toml().map_err(errors::config_chain)?,
            "run": state,
        });
        serde_json::to_string(&saved).map_err(|e| errors::restore(e.to_string()))
    }

    /// A run saved by `to_json`; raises `RestoreError` on anything else.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Run> {
        let bad = |problem: String| errors::restore(format!("cannot restore the run: {problem}"));
        let saved: serde_json::Value = serde_json::from_str(text).map_err(|e| bad(format!("not valid JSON: {e}")))?;
        if saved.get("format").and_then(|f| f.as_str()) != Some(SAVED_FORMAT) {
            return Err(bad(format!("no \"format\": {SAVED_FORMAT:?}; not a saved run")));
        }
        if saved.get("version").and_then(|v| v.as_u64()) != Some(SAVED_VERSION) {
            return Err(bad(format!("this build reads version {SAVED_VERSION}")));
        }
        let text_of = |key: &str| {
            saved
                .get(key)
                .and_then(|v| v.as_str())
                .ok_or_else(|| bad(format!("no {key:?}")))
        };
        let count_of = |key: &str| {
            saved
                .get(key)
                .and_then(|v| v.as_u64())
                .map(|v| v as usize)
                .ok_or_else(|| bad(format!("no {key:?}")))
        };
        let config = RunConfig::baseline_with(text_of("config")?).map_err(|e| bad(format!("configuration: {e:#}")))?;
        let seed: u64 = text_of("seed")?.parse().map_err(|e| bad(format!("seed: {e}")))?;
        let run: AnyRun = serde_json::from_value(saved.get("run").cloned().unwrap_or_default())
            .map_err(|e| bad(format!("state: {e}")))?;
        let fits = match (&run, config.algorithm) {
            (AnyRun::Esp(r), Algorithm::Esp) => r.esp().settings() == &config.esp && r.esp().seed() == seed,
            (AnyRun::HillClimb(r), Algorithm::HillClimb) => r.hill_climb().settings() == &config.hill_climb,
            _ => false,
        };
        if !fits {
            return Err(bad("the state is not a run of its configuration and seed".into()));
        }
        Ok(Run {
            label: text_of("label")?.to_string(),
            inputs: count_of("inputs")?,
            outputs: count_of("outputs")?,
            config,
            seed,
            run,
        })
    }

    /// The ended run's champion as a network file in the CLI's format, as
    /// `psa-esp evolve` writes `champion.json` (with the configuration's
    /// name, the seed, the fitness, the generation and the backend in its
    /// provenance), for `task`. `psa-esp replay` flies it.
    fn save_champion(&self, path: PathBuf, task: &Bound<'_, PyAny>) -> PyResult<()> {
        let task = task_arg(task)?;
        let result = self.ended()?;
        let champion = &result.champion;
        let mut extra = serde_json::Map::new();
        extra.insert("configuration".into(), self.label.clone().into());
        extra.insert("seed".into(), self.seed.to_string().into());
        extra.insert("fitness_percent".into(), champion.fitness.into());
        extra.insert("generation".into(), champion.generation.into());
        extra.insert("backend".into(), self.config.problem.backend.name().into());
        NetworkFile::new(
            &champion.network,
            task,
            &self.config.problem,
            &psa_experiment::build_info(),
            extra,
        )
        .save(&path)
        .map_err(errors::network_file)
    }

    /// Pickles (and copies) through `to_json`: the copy ends as the run
    /// would, bit for bit (asks made before are to be asked again).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((restorer(py, "_run_from_json")?, (self.to_json()?,)))
    }

    fn __repr__(&self) -> String {
        format!(
            "<psa_esp.Run {} seed {}: {} generations done{}>",
            self.algorithm(),
            self.seed,
            self.run.records().len(),
            self.ending().map_or(String::new(), |e| format!(", {e}"))
        )
    }
}

/// The run of `Run.to_json`'s text: how a `Run` unpickles.
#[pyfunction]
pub fn _run_from_json(text: &str) -> PyResult<Run> {
    Run::from_json(text)
}
