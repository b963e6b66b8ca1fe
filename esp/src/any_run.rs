//! A run of either search behind one type: what an executor that drives
//! (and saves) runs of both kinds holds.

use serde::{Deserialize, Serialize};

use crate::{AskTell, Asked, Champion, Ending, EspRun, GenerationRecord, HillClimbRun, RunError, RunResult, Ticket};

/// An ESP run or a hill-climbing run, driven by ask and tell like either,
/// and saved and restored by serde like either (tagged with its kind).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AnyRun {
    /// An ESP run.
    Esp(EspRun),
    /// A hill-climbing run.
    HillClimb(HillClimbRun),
}

impl From<EspRun> for AnyRun {
    fn from(run: EspRun) -> AnyRun {
        AnyRun::Esp(run)
    }
}

impl From<HillClimbRun> for AnyRun {
    fn from(run: HillClimbRun) -> AnyRun {
        AnyRun::HillClimb(run)
    }
}

impl AnyRun {
    /// The run, whichever it is.
    fn inner(&self) -> &dyn AskTell {
        match self {
            AnyRun::Esp(run) => run,
            AnyRun::HillClimb(run) => run,
        }
    }

    /// The run, whichever it is, to change.
    fn inner_mut(&mut self) -> &mut dyn AskTell {
        match self {
            AnyRun::Esp(run) => run,
            AnyRun::HillClimb(run) => run,
        }
    }

    /// Whether `other` is a run of the same search (kind, settings, seed
    /// and stop conditions): what a restored run is checked against before
    /// it stands in for a new one.
    pub fn same_search(&self, other: &AnyRun) -> bool {
        match (self, other) {
            (AnyRun::Esp(a), AnyRun::Esp(b)) => a.esp() == b.esp(),
            (AnyRun::HillClimb(a), AnyRun::HillClimb(b)) => a.hill_climb() == b.hill_climb(),
            _ => false,
        }
    }

    /// The result of the ended run; [`RunError::NotEnded`] before.
    pub fn into_result(self) -> Result<RunResult, RunError> {
        match self {
            AnyRun::Esp(run) => run.into_result(),
            AnyRun::HillClimb(run) => run.into_result(),
        }
    }
}

impl AskTell for AnyRun {
    fn ask(&mut self) -> Result<Option<Asked<'_>>, RunError> {
        self.inner_mut().ask()
    }
    fn tell(&mut self, ticket: Ticket, fitness: &[f64]) -> Result<Option<&GenerationRecord>, RunError> {
        self.inner_mut().tell(ticket, fitness)
    }
    fn stop(&mut self) {
        self.inner_mut().stop()
    }
    fn ending(&self) -> Option<Ending> {
        self.inner().ending()
    }
    fn records(&self) -> &[GenerationRecord] {
        self.inner().records()
    }
    fn result(&self) -> Result<RunResult, RunError> {
        self.inner().result()
    }
    fn champion(&self) -> Option<&Champion> {
        self.inner().champion()
    }
}
