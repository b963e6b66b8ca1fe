//! An ESP run as a state machine, driven by ask and tell.

use crate::ask::{check_told, AskTell, Asked};
use crate::esp::{Advance, State, Step};
use crate::{Control, Ending, Esp, GenerationRecord, RunError, RunResult, RECORDS_RESERVED};

/// A run of [`Esp`] under way: [`AskTell::ask`] gives the networks to
/// evaluate next (a generation's, then any lesion tests at its end),
/// [`AskTell::tell`] their fitness. Made by [`Esp::start`]; the same run,
/// bit for bit, as [`Esp::run`], whoever evaluates the networks.
pub struct EspRun {
    esp: Esp,
    state: State,
    records: Vec<GenerationRecord>,
    /// The generation under way, or the last one recorded.
    generation: usize,
    phase: Phase,
    /// [`AskTell::stop`] was called.
    stop_requested: bool,
}

/// Where the run stands.
enum Phase {
    /// Generation `generation` is next: its networks are not drawn yet.
    Next,
    /// Networks are asked.
    Asking(Step),
    /// Generation `generation` is recorded; the goal or the budget ended
    /// the run there if this says so.
    Recorded(Option<Ending>),
    /// The run has ended.
    Ended(Ending),
}

impl EspRun {
    /// A run of `esp` from `state` (the initial sub-populations).
    pub(crate) fn new(esp: Esp, state: State) -> EspRun {
        let reserved = esp.settings().generations.min(RECORDS_RESERVED);
        EspRun {
            esp,
            state,
            records: Vec::with_capacity(reserved),
            generation: 1,
            phase: Phase::Next,
            stop_requested: false,
        }
    }

    /// The run's settings, seed and stop conditions.
    pub fn esp(&self) -> &Esp {
        &self.esp
    }

    /// The result of the ended run; [`RunError::NotEnded`] before.
    pub fn into_result(self) -> Result<RunResult, RunError> {
        let ending = self.ending().ok_or(RunError::NotEnded)?;
        Ok(RunResult {
            champion: self.state.champion.expect("every generation has a champion"),
            records: self.records,
            ending,
        })
    }

    /// How the run ends after generation `generation`, recorded with the
    /// goal's or budget's `decision`: those first, then a stop, then the
    /// last generation; `None` goes on.
    fn decide(&self, decision: Option<Ending>) -> Option<Ending> {
        decision
            .or(self.stop_requested.then_some(Ending::Stopped))
            .or((self.generation == self.esp.settings().generations).then_some(Ending::Completed))
    }

    /// Moves on to the next networks to ask for, or to the end.
    fn prepare(&mut self) -> Result<(), RunError> {
        loop {
            match self.phase {
                Phase::Recorded(decision) => {
                    self.phase = match self.decide(decision) {
                        Some(ending) => Phase::Ended(ending),
                        None => {
                            self.generation += 1;
                            Phase::Next
                        }
                    }
                }
                Phase::Next => self.phase = Phase::Asking(self.esp.begin(&self.state, self.generation)?),
                Phase::Asking(_) | Phase::Ended(_) => return Ok(()),
            }
        }
    }
}

impl AskTell for EspRun {
    fn ask(&mut self) -> Result<Option<Asked<'_>>, RunError> {
        self.prepare()?;
        Ok(match &self.phase {
            Phase::Asking(step) => Some(self.esp.asked(&self.state, step, self.generation)),
            _ => None,
        })
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<Option<&GenerationRecord>, RunError> {
        self.prepare()?;
        let expected = match &self.phase {
            Phase::Asking(step) => step.count(),
            _ => return Err(RunError::Ended),
        };
        check_told(fitness, expected)?;
        let Phase::Asking(step) = std::mem::replace(&mut self.phase, Phase::Next) else {
            unreachable!("checked above")
        };
        match self.esp.advance(&mut self.state, step, fitness, self.generation) {
            Advance::Ask(step) => {
                self.phase = Phase::Asking(step);
                Ok(None)
            }
            Advance::Record(record) => {
                self.phase = Phase::Recorded(self.esp.stop().decide(&record, Control::Continue));
                self.records.push(record);
                Ok(self.records.last())
            }
        }
    }

    fn stop(&mut self) {
        self.stop_requested = true;
    }

    fn ending(&self) -> Option<Ending> {
        match self.phase {
            Phase::Ended(ending) => Some(ending),
            Phase::Recorded(decision) => self.decide(decision),
            Phase::Next | Phase::Asking(_) => None,
        }
    }

    fn records(&self) -> &[GenerationRecord] {
        &self.records
    }

    fn result(&self) -> Result<RunResult, RunError> {
        let ending = self.ending().ok_or(RunError::NotEnded)?;
        Ok(RunResult {
            champion: self.state.champion.clone().expect("every generation has a champion"),
            records: self.records.clone(),
            ending,
        })
    }
}
