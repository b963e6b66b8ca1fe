//! One trial flown step by step from Python: what the Gymnasium
//! environment (`psa_esp.env.PsaEnv`) steps. Each step is the scalar
//! trial's step (`psa_sim::psa::trial`), operation for operation, so a
//! network flown through it scores what `evaluate` gives.

use esp_neuroevolution::rng::stream;
use std::f64::consts::{PI, TAU};

use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray1, PyArray3, PyArrayMethods};
use psa_experiment::plots::{ensure_font, trial_frame, use_packaged_font, TrialPicture, FIGURE_HEIGHT, FIGURE_WIDTH};
use psa_sim::named::Named;
use psa_sim::numeric::{clamp_unit, NoiseSource};
use psa_sim::physics::{create_backend, BodyState, PlanarState};
use psa_sim::psa::step::{score, sense, Reading};
use psa_sim::psa::{HeadingWrap, PsaSettings, Task, INPUT_COUNT, THRUSTER_COUNT};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;

use crate::args;
use crate::config::{run_config, type_name};
use crate::errors;
use crate::evaluate::{task_arg, REPLAY_STREAM};
use crate::thread_bound::ThreadBound;

/// The heading input's place among the inputs (x, y, vx, vy, heading,
/// omega, bias).
const HEADING_INPUT: usize = 4;

/// A trial under way.
struct Flight {
    target: [f64; 3],
    noise: NoiseSource<u64>,
    state: PlanarState<f64>,
    reading: Reading<f64>,
    points: f64,
    steps: usize,
    /// The states flown so far, the start first (for `frame`).
    states: Vec<BodyState>,
    /// The thrusters' commands applied so far, after noise and clamping.
    outputs: Vec<[f64; THRUSTER_COUNT]>,
}

/// One trial of a task, flown a control step at a time.
///
/// `Trial(task, config=None, *, preset="baseline", backend=None,
/// random_init=None)`: the problem `config` resolves to (see `evaluate`),
/// for `task`. `reset(seed)` starts a trial as `psa-esp replay --seed
/// seed` starts its first (the paper's start, or a random one under
/// `random_init`), `step(thrust)` applies four thruster commands for one
/// step. Steps only on the thread that made it (its physics world may be
/// an ODE world): `reset` and `step` from another thread raise
/// `RuntimeError`; its other attributes read from any thread.
#[pyclass(module = "psa_esp._native")]
pub struct Trial {
    settings: PsaSettings,
    task: Task,
    physics: ThreadBound,
    maximum: f64,
    flight: Option<Flight>,
}

impl Trial {
    /// Starts a trial with the random stream of `seed`: the first
    /// observation (what `reset` returns).
    pub fn start(&mut self, seed: u64) -> PyResult<[f64; INPUT_COUNT]> {
        let s = &self.settings;
        let mut rng = stream(seed, &[REPLAY_STREAM]);
        let (start, target) = s.tasks.start_and_target(self.task, s.random_init, &mut rng);
        let (state, body) = self
            .physics
            .with(|engine| engine.reset(&start).map(|()| (engine.planar_state(), engine.state())))?
            .map_err(errors::simulation)?;
        let mut noise = NoiseSource::new(s.noise.draw_seed(&mut rng));
        let target = [target.x, target.y, target.heading];
        let reading = Trial::read(s, &state, target, &mut noise);
        let inputs = reading.inputs;
        self.flight = Some(Flight {
            target,
            noise,
            state,
            reading,
            points: 0.0,
            steps: 0,
            states: vec![body],
            outputs: Vec::new(),
        });
        Ok(inputs)
    }

    /// Applies `outputs` for one step (what `step` does once its argument
    /// is read): the next observation and the step's reward.
    pub fn advance(&mut self, mut outputs: [f64; THRUSTER_COUNT]) -> PyResult<([f64; INPUT_COUNT], f64)> {
        if let Some(bad) = outputs.iter().find(|u| !u.is_finite()) {
            return Err(PyValueError::new_err(format!("thrust must be finite, got {bad}")));
        }
        let steps = self.settings.steps;
        let maximum = self.maximum;
        let flight = self.flight.as_mut().ok_or_else(not_started)?;
        if flight.steps >= steps {
            return Err(PyRuntimeError::new_err(format!(
                "the trial is over after {steps} steps: call reset(seed) to start another"
            )));
        }
        let s = &self.settings;
        if s.noise.is_active() {
            s.noise.perturb_outputs(&mut outputs, &mut flight.noise);
        }
        for u in &mut outputs {
            *u = clamp_unit(*u);
        }
        let (state, body) = self
            .physics
            .with(|engine| engine.step(&outputs).map(|()| (engine.planar_state(), engine.state())))?
            .map_err(errors::simulation)?;
        let previous_omega = flight.state.omega;
        flight.state = state;
        let next = Trial::read(s, &flight.state, flight.target, &mut flight.noise);
        let points = score(
            s.step(),
            &next,
            &flight.reading,
            flight.state.position,
            flight.state.omega,
            previous_omega,
            flight.target,
        );
        flight.reading = next;
        flight.points += points;
        flight.steps += 1;
        flight.states.push(body);
        flight.outputs.push(outputs);
        Ok((flight.reading.inputs, 100.0 * points / maximum))
    }

    /// The last observation (the network's inputs now).
    pub fn observation(&self) -> PyResult<[f64; INPUT_COUNT]> {
        Ok(self.flight.as_ref().ok_or_else(not_started)?.reading.inputs)
    }

    /// Whether the trial has flown all its steps.
    pub fn is_over(&self) -> bool {
        self.flight.as_ref().is_some_and(|f| f.steps >= self.settings.steps)
    }

    /// The fitness so far, in % of the task's maximum.
    pub fn fitness_so_far(&self) -> f64 {
        self.flight.as_ref().map_or(0.0, |f| 100.0 * f.points / self.maximum)
    }

    /// The body's state: x, y, heading, vx, vy, omega.
    pub fn body_state(&self) -> PyResult<[f64; 6]> {
        let s = &self.flight.as_ref().ok_or_else(not_started)?.state;
        Ok([
            s.position[0],
            s.position[1],
            s.heading(),
            s.velocity[0],
            s.velocity[1],
            s.omega,
        ])
    }

    /// What the controller reads of the state now.
    fn read(
        settings: &PsaSettings,
        state: &PlanarState<f64>,
        target: [f64; 3],
        noise: &mut NoiseSource<u64>,
    ) -> Reading<f64> {
        let read = if settings.noise.is_active() {
            sense::<f64, true>
        } else {
            sense::<f64, false>
        };
        read(
            settings.step(),
            state.position,
            state.velocity,
            state.heading(),
            state.omega,
            target,
            noise,
        )
    }
}

/// The error of a step or a reading before `reset`.
fn not_started() -> PyErr {
    PyRuntimeError::new_err("the trial has not started: call reset(seed) first")
}

#[pymethods]
impl Trial {
    #[new]
    #[pyo3(signature = (task, config=None, *, preset="baseline", backend=None, random_init=None))]
    pub(crate) fn new(
        task: &Bound<'_, PyAny>,
        config: Option<&Bound<'_, PyAny>>,
        preset: &str,
        backend: Option<&str>,
        random_init: Option<bool>,
    ) -> PyResult<Trial> {
        let task = task_arg(task)?;
        let mut problem = run_config(config, preset, backend)?.problem;
        if let Some(random_init) = random_init {
            problem.random_init = random_init;
        }
        let settings = problem.for_task(task).map_err(|e| errors::config(e.to_string()))?;
        let model = settings.body.model().map_err(|e| errors::config(e.to_string()))?;
        let backend = create_backend(settings.backend, &model, &settings.physics).map_err(errors::simulation)?;
        Ok(Trial {
            maximum: settings.fitness.maximum(settings.steps),
            settings,
            task,
            physics: ThreadBound::new(backend),
            flight: None,
        })
    }

    /// Starts a trial with the random stream of `seed` (the start, under
    /// random initialisation, and the noise are drawn from it); returns
    /// the first observation, the network's 7 inputs.
    fn reset<'py>(&mut self, py: Python<'py>, seed: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let inputs = self.start(args::seed(seed, "seed")?)?;
        Ok(PyArray1::from_slice(py, &inputs))
    }

    /// Applies `thrust` (4 commands, clamped to [0, 1] after the output
    /// noise, if any) for one step. Returns the next observation and the
    /// step's increment of the trial's fitness, in % of the maximum.
    fn step<'py>(&mut self, py: Python<'py>, thrust: &Bound<'py, PyAny>) -> PyResult<(Bound<'py, PyArray1<f64>>, f64)> {
        let commands: Vec<f64> = match thrust.cast::<PyArray1<f64>>() {
            Ok(array) => array.to_vec().map_err(|e| PyValueError::new_err(e.to_string()))?,
            Err(_) => thrust.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "thrust must be {THRUSTER_COUNT} floats, got {}",
                    type_name(thrust)
                ))
            })?,
        };
        if commands.len() != THRUSTER_COUNT {
            return Err(PyValueError::new_err(format!(
                "thrust must be {THRUSTER_COUNT} floats, got {}",
                commands.len()
            )));
        }
        let mut outputs = [0.0; THRUSTER_COUNT];
        outputs.copy_from_slice(&commands);
        let (inputs, reward) = self.advance(outputs)?;
        Ok((PyArray1::from_slice(py, &inputs), reward))
    }

    /// The trial's fitness so far, in % of the task's theoretical
    /// maximum: after the last step, the bits `evaluate` gives (one trial).
    #[getter]
    fn fitness(&self) -> f64 {
        self.fitness_so_far()
    }

    /// Steps flown in this trial.
    #[getter]
    fn steps_done(&self) -> usize {
        self.flight.as_ref().map_or(0, |f| f.steps)
    }

    /// Steps a trial lasts.
    #[getter]
    fn steps(&self) -> usize {
        self.settings.steps
    }

    /// Seconds a step lasts.
    #[getter]
    fn dt(&self) -> f64 {
        self.settings.physics.dt
    }

    /// Whether the trial has flown all its steps.
    #[getter]
    fn done(&self) -> bool {
        self.is_over()
    }

    /// The body's state: x, y (m, world frame), heading (rad), vx, vy
    /// (m/s), omega (rad/s).
    #[getter]
    fn state(&self) -> PyResult<[f64; 6]> {
        self.body_state()
    }

    /// The target: x, y (m), heading (rad).
    #[getter]
    fn target(&self) -> PyResult<[f64; 3]> {
        Ok(self.flight.as_ref().ok_or_else(not_started)?.target)
    }

    /// The bounds of the observation, (low, high), 7 each: the heading
    /// input lies in its wrap range times its scale and the bias is its
    /// constant, unless input noise reaches them; the rest are unbounded.
    #[getter]
    fn observation_bounds(&self) -> ([f64; INPUT_COUNT], [f64; INPUT_COUNT]) {
        let mut low = [f64::NEG_INFINITY; INPUT_COUNT];
        let mut high = [f64::INFINITY; INPUT_COUNT];
        let s = &self.settings;
        let noisy = s.noise.input_sd > 0.0;
        if !noisy {
            let (from, to) = match s.sensors.heading_wrap {
                HeadingWrap::Symmetric => (-PI, PI),
                HeadingWrap::Positive => (0.0, TAU),
            };
            let ends = [from * s.sensors.heading_scale, to * s.sensors.heading_scale];
            low[HEADING_INPUT] = ends[0].min(ends[1]);
            high[HEADING_INPUT] = ends[0].max(ends[1]);
        }
        if !(noisy && s.noise.on_bias) {
            low[INPUT_COUNT - 1] = s.sensors.bias;
            high[INPUT_COUNT - 1] = s.sensors.bias;
        }
        (low, high)
    }

    /// `Trial(task=1, backend='native', step 120 of 500, fitness 12.3 %)`,
    /// or `not started` before the first `reset`.
    fn __repr__(&self) -> String {
        let progress = match &self.flight {
            None => "not started".to_string(),
            Some(f) => format!(
                "step {} of {}, fitness {:.1} %",
                f.steps,
                self.settings.steps,
                100.0 * f.points / self.maximum
            ),
        };
        format!(
            "Trial(task={}, backend='{}', {progress})",
            self.task.number(),
            self.settings.backend.name()
        )
    }

    /// The trial so far drawn as `psa-esp replay` draws its picture
    /// (`trial.png`: the path with the target box, the thrusters'
    /// commands, the heading error and spin over time), as an (H, W, 3)
    /// uint8 array. Before the first step it shows the start, held for one
    /// step without thrust.
    fn frame<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let f = self.flight.as_ref().ok_or_else(not_started)?;
        let s = &self.settings;
        let held;
        let (states, outputs): (&[BodyState], &[[f64; THRUSTER_COUNT]]) = if f.outputs.is_empty() {
            held = ([f.states[0], f.states[0]], [[0.0; THRUSTER_COUNT]]);
            (&held.0, &held.1)
        } else {
            (&f.states, &f.outputs)
        };
        let picture = TrialPicture {
            title: format!(
                "task {}, {} backend, step {} of {}, fitness {:.1} %",
                u8::from(self.task),
                s.backend.name(),
                f.steps,
                s.steps,
                100.0 * f.points / self.maximum
            ),
            dt: s.physics.dt,
            states,
            outputs,
            target: f.target,
            box_half_width: s.fitness.box_half_width,
            heading_window: s.fitness.heading_window,
            hull_radius: s.body.hull_radius,
        };
        // No font is the machine's, not the trial's: a RuntimeError that
        // names the package and PSA_ESP_FONT.
        ensure_font().map_err(|e| PyRuntimeError::new_err(format!("render: {e:#}")))?;
        let pixels = trial_frame(&picture).map_err(|e| errors::simulation(format!("{e:#}")))?;
        let shape = (FIGURE_HEIGHT as usize, FIGURE_WIDTH as usize, 3);
        let array = Array3::from_shape_vec(shape, pixels).map_err(|e| errors::simulation(e.to_string()))?;
        Ok(array.into_pyarray(py))
    }

    /// The number of inputs (observations).
    #[classattr]
    fn inputs() -> usize {
        INPUT_COUNT
    }
}

/// Names the font the portable wheel carries (`psa_esp/fonts/`), tried for
/// rendering after `PSA_ESP_FONT` and before the system's fonts; the
/// package calls it on import when the file is there.
#[pyfunction]
pub fn _use_packaged_font(path: std::path::PathBuf) {
    use_packaged_font(path);
}
