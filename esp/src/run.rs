//! The run driver that ESP and the hill-climber share: where a run stands
//! between its asks and tells, how a generation (cycle) is begun, stepped
//! and recorded, how the run ends, and its result. Each search says only
//! what its generation does ([`Search`]).

use std::sync::atomic::{AtomicU64, Ordering};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::ask::{check_told, AskTell, Asked, Ticket};
use crate::network::NetworkSet;
use crate::{Champion, Control, Ending, Evaluator, GenerationRecord, RunError, RunResult, StopAt, RECORDS_RESERVED};

/// A search the driver can run: its generation (cycle) as steps that each
/// ask for networks and are advanced by their fitness.
pub(crate) trait Search: Clone + std::fmt::Debug {
    /// The search's state between steps.
    type State: Serialize + DeserializeOwned + Clone + std::fmt::Debug;
    /// A step whose networks are out for evaluation.
    type Step: Serialize + DeserializeOwned + Clone + std::fmt::Debug;

    /// The last generation.
    fn generations(&self) -> usize;
    /// When the run ends early.
    fn stop_at(&self) -> StopAt;
    /// Checks a restored state (and step) against the settings.
    fn check(&self, state: &Self::State, step: Option<&Self::Step>) -> Result<(), RunError>;
    /// Generation `generation`'s first step.
    fn begin(&self, state: &Self::State, generation: usize) -> Result<Self::Step, RunError>;
    /// The networks `step` asks for, with their streams.
    fn asked<'a>(&self, state: &'a Self::State, step: &'a Self::Step, generation: usize) -> Asked<'a>;
    /// The generation after `step`'s networks scored `fitness` (as many,
    /// all finite).
    fn advance(
        &self,
        state: &mut Self::State,
        step: Self::Step,
        fitness: &[f64],
        generation: usize,
    ) -> Advance<Self::Step>;
    /// The best network evaluated so far.
    fn champion(state: &Self::State) -> Option<&Champion>;
    /// The best network evaluated so far, taken.
    fn into_champion(state: Self::State) -> Option<Champion>;
}

/// What a generation needs after a step.
pub(crate) enum Advance<S> {
    /// More networks evaluated.
    Ask(S),
    /// Its first step again ([`Search::begin`]), the state having changed.
    Begin,
    /// Nothing: it is complete, with this record.
    Record(GenerationRecord),
}

/// Where a run stands.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
enum Phase<S> {
    /// The generation's networks are not drawn yet.
    Next,
    /// Networks are asked.
    Asking(S),
    /// The generation is recorded; the goal or the budget ended the run
    /// there if this says so.
    Recorded(Option<Ending>),
    /// The run has ended.
    Ended(Ending),
}

/// The next run's identity, for its tickets.
static NEXT_RUN: AtomicU64 = AtomicU64::new(1);

/// A new run identity (never 0, which the tickets of [`Asked::new`] carry
/// before the driver sets them).
fn new_run_id() -> u64 {
    NEXT_RUN.fetch_add(1, Ordering::Relaxed)
}

/// A run of search `A` under way, as a state machine driven by ask and
/// tell: its whole state ([`Saved`]), which serde saves and restores (a
/// restored run goes on as the saved one would have, bit for bit), and its
/// identity in its tickets (a restored run, and a clone, has a new one).
#[derive(Debug)]
pub(crate) struct Driver<A: Search> {
    saved: Saved<A>,
    id: u64,
}

/// A clone is a run of its own: it may diverge from the original, so the
/// tickets of one are foreign to the other.
impl<A: Search> Clone for Driver<A> {
    fn clone(&self) -> Driver<A> {
        Driver {
            saved: self.saved.clone(),
            id: new_run_id(),
        }
    }
}

/// What a run's save holds: all of it but its identity.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(bound(
    serialize = "A: Serialize, A::State: Serialize, A::Step: Serialize",
    deserialize = "A: Deserialize<'de>, A::State: Deserialize<'de>, A::Step: Deserialize<'de>"
))]
#[serde(deny_unknown_fields)]
struct Saved<A: Search> {
    search: A,
    state: A::State,
    records: Vec<GenerationRecord>,
    /// The generation under way, or the last one recorded.
    generation: usize,
    phase: Phase<A::Step>,
    /// [`AskTell::stop`] was called.
    stop_requested: bool,
    /// Tells taken: the number of the next ask's ticket.
    told: u64,
}

impl<A: Search> Saved<A> {
    /// Checks a restored run against its own settings.
    fn check(&self) -> Result<(), RunError> {
        let step = match &self.phase {
            Phase::Asking(step) => Some(step),
            _ => None,
        };
        self.search.check(&self.state, step)?;
        let recorded = matches!(self.phase, Phase::Recorded(_) | Phase::Ended(_));
        let complete = self.generation.saturating_sub(usize::from(!recorded));
        if self.generation == 0 || self.generation > self.search.generations() || self.records.len() != complete {
            return Err(RunError::Restore(format!(
                "generation {} with {} records does not fit a run of {} generations",
                self.generation,
                self.records.len(),
                self.search.generations()
            )));
        }
        Ok(())
    }
}

impl<A: Search> Serialize for Driver<A>
where
    Saved<A>: Serialize,
{
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.saved.serialize(serializer)
    }
}

impl<'de, A: Search> Deserialize<'de> for Driver<A>
where
    Saved<A>: Deserialize<'de>,
{
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Driver<A>, D::Error> {
        let saved = Saved::deserialize(deserializer)?;
        saved.check().map_err(serde::de::Error::custom)?;
        Ok(Driver {
            saved,
            id: new_run_id(),
        })
    }
}

impl<A: Search> Driver<A> {
    /// A run of `search` from `state`, before its first generation.
    pub(crate) fn new(search: A, state: A::State) -> Driver<A> {
        let reserved = search.generations().min(RECORDS_RESERVED);
        Driver {
            saved: Saved {
                search,
                state,
                records: Vec::with_capacity(reserved),
                generation: 1,
                phase: Phase::Next,
                stop_requested: false,
                told: 0,
            },
            id: new_run_id(),
        }
    }

    /// The search (its settings, seed and stop conditions).
    pub(crate) fn search(&self) -> &A {
        &self.saved.search
    }

    /// The result of the ended run; [`RunError::NotEnded`] before.
    pub(crate) fn into_result(self) -> Result<RunResult, RunError> {
        let ending = self.ending().ok_or(RunError::NotEnded)?;
        Ok(RunResult {
            champion: A::into_champion(self.saved.state).expect("every generation has a champion"),
            records: self.saved.records,
            ending,
        })
    }

    /// How the run ends after the current generation, recorded with the
    /// goal's or budget's `decision`: those first, then a stop, then the
    /// last generation; `None` goes on.
    fn decide(&self, decision: Option<Ending>) -> Option<Ending> {
        decision
            .or(self.saved.stop_requested.then_some(Ending::Stopped))
            .or((self.saved.generation == self.saved.search.generations()).then_some(Ending::Completed))
    }

    /// Moves on to the next networks to ask for, or to the end.
    fn prepare(&mut self) -> Result<(), RunError> {
        loop {
            match self.saved.phase {
                Phase::Recorded(decision) => {
                    self.saved.phase = match self.decide(decision) {
                        Some(ending) => Phase::Ended(ending),
                        None => {
                            self.saved.generation += 1;
                            Phase::Next
                        }
                    }
                }
                Phase::Next => {
                    self.saved.phase = Phase::Asking(self.saved.search.begin(&self.saved.state, self.saved.generation)?)
                }
                Phase::Asking(_) | Phase::Ended(_) => return Ok(()),
            }
        }
    }
}

impl<A: Search> AskTell for Driver<A> {
    fn ask(&mut self) -> Result<Option<Asked<'_>>, RunError> {
        self.prepare()?;
        let ticket = Ticket::new(self.id, self.saved.told);
        Ok(match &self.saved.phase {
            Phase::Asking(step) => Some(
                self.saved
                    .search
                    .asked(&self.saved.state, step, self.saved.generation)
                    .with_ticket(ticket),
            ),
            _ => None,
        })
    }

    fn tell(&mut self, ticket: Ticket, fitness: &[f64]) -> Result<Option<&GenerationRecord>, RunError> {
        if self.ending().is_some() {
            return Err(RunError::Ended);
        }
        ticket.check(self.id, self.saved.told)?;
        let expected = match &self.saved.phase {
            Phase::Asking(step) => self
                .saved
                .search
                .asked(&self.saved.state, step, self.saved.generation)
                .len(),
            _ => {
                return Err(RunError::TicketTold {
                    ticket: self.saved.told,
                    told: self.saved.told,
                })
            }
        };
        check_told(fitness, expected)?;
        let Phase::Asking(step) = std::mem::replace(&mut self.saved.phase, Phase::Next) else {
            unreachable!("checked above")
        };
        self.saved.told += 1;
        match self
            .saved
            .search
            .advance(&mut self.saved.state, step, fitness, self.saved.generation)
        {
            Advance::Ask(step) => {
                self.saved.phase = Phase::Asking(step);
                Ok(None)
            }
            Advance::Begin => Ok(None),
            Advance::Record(record) => {
                self.saved.phase = Phase::Recorded(self.saved.search.stop_at().decide(&record, Control::Continue));
                self.saved.records.push(record);
                Ok(self.saved.records.last())
            }
        }
    }

    fn stop(&mut self) {
        self.saved.stop_requested = true;
    }

    fn ending(&self) -> Option<Ending> {
        match self.saved.phase {
            Phase::Ended(ending) => Some(ending),
            Phase::Recorded(decision) => self.decide(decision),
            Phase::Next | Phase::Asking(_) => None,
        }
    }

    fn records(&self) -> &[GenerationRecord] {
        &self.saved.records
    }

    fn result(&self) -> Result<RunResult, RunError> {
        let ending = self.ending().ok_or(RunError::NotEnded)?;
        Ok(RunResult {
            champion: A::champion(&self.saved.state)
                .cloned()
                .expect("every generation has a champion"),
            records: self.saved.records.clone(),
            ending,
        })
    }

    fn champion(&self) -> Option<&Champion> {
        A::champion(&self.saved.state)
    }
}

/// Drives `run` to its end on the current rayon pool: ask, evaluate with
/// `evaluator`, tell, and call `on_generation` with every record (its
/// [`Control::Stop`] stops the run).
pub(crate) fn drive<R: AskTell + ?Sized, E: Evaluator, C: Into<Control>>(
    run: &mut R,
    evaluator: &E,
    mut on_generation: impl FnMut(&GenerationRecord) -> C,
) -> Result<(), RunError> {
    while let Some(asked) = run.ask()? {
        let (ticket, fitness) = (asked.ticket(), asked.evaluate(evaluator)?);
        if let Some(record) = run.tell(ticket, &fitness)? {
            if on_generation(record).into() == Control::Stop {
                run.stop();
            }
        }
    }
    Ok(())
}

/// A public run type around a [`Driver`]: serde as the driver (saving and
/// restoring the whole run), [`AskTell`] and `into_result` passed through.
macro_rules! public_run {
    ($run:ident) => {
        impl $crate::AskTell for $run {
            fn ask(&mut self) -> Result<Option<$crate::Asked<'_>>, $crate::RunError> {
                self.0.ask()
            }
            fn tell(
                &mut self,
                ticket: $crate::Ticket,
                fitness: &[f64],
            ) -> Result<Option<&$crate::GenerationRecord>, $crate::RunError> {
                self.0.tell(ticket, fitness)
            }
            fn stop(&mut self) {
                self.0.stop()
            }
            fn ending(&self) -> Option<$crate::Ending> {
                self.0.ending()
            }
            fn records(&self) -> &[$crate::GenerationRecord] {
                self.0.records()
            }
            fn result(&self) -> Result<$crate::RunResult, $crate::RunError> {
                self.0.result()
            }
            fn champion(&self) -> Option<&$crate::Champion> {
                self.0.champion()
            }
        }

        impl $run {
            /// The result of the ended run; [`RunError::NotEnded`](crate::RunError::NotEnded) before.
            pub fn into_result(self) -> Result<$crate::RunResult, $crate::RunError> {
                self.0.into_result()
            }
        }
    };
}
pub(crate) use public_run;
