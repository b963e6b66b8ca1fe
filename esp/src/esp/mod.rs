//! Enforced Sub-Populations (Gomez & Miikkulainen), with Høverstad's
//! modifications (his Tables 1 and 4-6) as switches.
//!
//! By phase: [`settings`](self::settings) (every switch and number),
//! `population` (sub-populations, sampling, credit and breeding),
//! `generation` (a generation's networks, champion and stagnation count),
//! `stagnation` (burst mutation and lesion tests); the run driver
//! (`crate::run`) steps them by ask and tell.

mod generation;
mod population;
mod settings;
mod stagnation;
#[cfg(test)]
mod tests;

pub use settings::{BurstMode, Credit, EraseAt, EspSettings, Relesion, Sampling, StagnationRule, TopologyMode};

/// An ESP run: settings, seed and when to stop early.
use serde::{Deserialize, Serialize};

use self::population::State;
use crate::network::check_sizes;
use crate::purpose;
use crate::rng::stream;
use crate::run::{drive, public_run, Driver};
use crate::subpop::Subpop;
use crate::{Control, Evaluator, GenerationRecord, RunError, RunResult, SettingsError, StopAt};

/// An ESP run: settings, seed and when to stop early. Read from JSON (or
/// any serde format) it is checked as [`Esp::new`] checks it; the seed is
/// written as a string, so that JSON tools reading numbers as doubles keep
/// every digit (a number is read too).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Unchecked")]
pub struct Esp {
    settings: EspSettings,
    #[serde(with = "crate::rng::u64_string")]
    seed: u64,
    stop: StopAt,
}

/// An [`Esp`] as read, before its settings are checked.
#[derive(Deserialize)]
struct Unchecked {
    settings: EspSettings,
    #[serde(with = "crate::rng::u64_string")]
    seed: u64,
    stop: StopAt,
}

impl TryFrom<Unchecked> for Esp {
    type Error = SettingsError;
    fn try_from(raw: Unchecked) -> Result<Esp, SettingsError> {
        Ok(Esp::new(raw.settings, raw.seed)?.stop_at(raw.stop))
    }
}

impl Esp {
    /// An ESP run with `settings` and `seed`; fails on invalid settings.
    pub fn new(settings: EspSettings, seed: u64) -> Result<Esp, SettingsError> {
        settings.validate()?;
        Ok(Esp {
            settings,
            seed,
            stop: StopAt::NEVER,
        })
    }

    /// This run, ending early when `stop` says so (checked when the run
    /// starts: [`StopAt::validate`]).
    pub fn stop_at(self, stop: StopAt) -> Esp {
        Esp { stop, ..self }
    }

    /// The settings.
    pub fn settings(&self) -> &EspSettings {
        &self.settings
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// When the run ends early.
    pub fn stop(&self) -> StopAt {
        self.stop
    }

    /// Starts the run on networks of `inputs` inputs (the bias included)
    /// and `outputs` outputs, to be driven by ask and tell ([`AskTell`](crate::AskTell)).
    /// Fails on a size of 0 and on stop conditions out of range.
    pub fn start(&self, inputs: usize, outputs: usize) -> Result<EspRun, RunError> {
        check_sizes(inputs, outputs)?;
        self.stop.validate()?;
        let s = &self.settings;
        let mut rng = stream(self.seed, &[purpose::INIT]);
        let subpops = (0..s.initial_hidden)
            .map(|_| Subpop::random(&mut rng, s.subpop_size, inputs + outputs, s.init_range))
            .collect();
        Ok(EspRun(Driver::new(self.clone(), State::new(inputs, outputs, subpops))))
    }

    /// Runs the generations on the current rayon pool, calling
    /// `on_generation` after each, until the last, or until the stop
    /// conditions ([`Esp::stop_at`]) or `on_generation` (returning
    /// [`Control::Stop`]) end the run. A loop over [`Esp::start`]'s ask,
    /// evaluate and tell.
    pub fn run<E: Evaluator, C: Into<Control>>(
        &self,
        evaluator: &E,
        on_generation: impl FnMut(&GenerationRecord) -> C,
    ) -> Result<RunResult, RunError> {
        let mut run = self.start(evaluator.inputs(), evaluator.outputs())?;
        drive(&mut run, evaluator, on_generation)?;
        run.into_result()
    }
}

/// A run of [`Esp`] under way: [`AskTell::ask`](crate::AskTell::ask) gives
/// the networks to evaluate next (a generation's, then any lesion tests at
/// its end), [`AskTell::tell`](crate::AskTell::tell) their fitness. Made by
/// [`Esp::start`]; the same run, bit for bit, as [`Esp::run`], whoever
/// evaluates the networks.
///
/// Its whole state is serde: a run saved at any point (between any ask and
/// tell) and restored goes on exactly as the saved one would have. A
/// restored run checks its state against its settings
/// ([`RunError::Restore`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(transparent)]
pub struct EspRun(Driver<Esp>);

public_run!(EspRun);

impl EspRun {
    /// The run's settings, seed and stop conditions.
    pub fn esp(&self) -> &Esp {
        self.0.search()
    }
}
