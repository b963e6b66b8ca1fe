//! Runs as state machines: ask for the networks to evaluate next, tell
//! their fitness, repeat (the interface of evosax or EvoTorch).
//!
//! [`Esp::start`](crate::Esp::start) and
//! [`HillClimb::start`](crate::HillClimb::start) make a run that
//! [`AskTell::ask`] asks for a batch of networks (a generation's, a lesion
//! test's, the hill-climber's base) with the random streams each must be
//! evaluated with, and that [`AskTell::tell`] advances by their fitness.
//! Whoever evaluates them (one thread, a cluster, a GPU, or one batch for
//! many runs, as [`run_together`](crate::together::run_together) does) gets the same run, bit
//! for bit, as [`Esp::run`](crate::Esp::run), which is itself a loop over
//! ask, evaluate and tell.

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use crate::evaluator::{check_fitness, evaluate_all};
use crate::network::{Network, NetworkSet};
use crate::rng::StreamFamily;
use crate::subpop::Assembled;
use crate::{Champion, Ending, Evaluator, GenerationRecord, RunError, RunResult};

/// What a batch of asked networks is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum AskPurpose {
    /// The networks of ESP's generation (or the hill-climber's cycle) `n`.
    Generation(usize),
    /// ESP's lesion test at the end of generation `n`: the search's best
    /// network whole, then with each hidden neuron lesioned in turn.
    LesionTest(usize),
    /// The hill-climber's initial base network, evaluated for elitist
    /// acceptance before the first cycle.
    Base,
}

/// The networks a run asks to have evaluated, and the streams to evaluate
/// them with: network `j` of the batch must be scored with
/// `streams().stream(j)` (that is, `rng::stream(seed(), [key().., j])`),
/// which [`Asked::evaluate`] does. It reads the networks in place from
/// the run (ESP's sub-populations and picks, say) as a [`NetworkSet`].
/// Its [`Ticket`] is what [`AskTell::tell`] takes with their fitness.
pub struct Asked<'a> {
    networks: Networks<'a>,
    purpose: AskPurpose,
    seed: u64,
    key: [u64; 2],
    ticket: Ticket,
}

/// The receipt of an ask: which run asked, and which of its asks this is.
/// [`AskTell::tell`] takes it with the fitness, and refuses one of another
/// run or of an ask told already, so that fitness is never applied to
/// networks it was not computed for. A restored run (serde) issues new
/// tickets: those of the run it was saved from are foreign to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ticket {
    run: u64,
    ask: u64,
}

impl Ticket {
    /// The ticket of run `run`'s ask after `told` tells.
    pub(crate) fn new(run: u64, told: u64) -> Ticket {
        Ticket { run, ask: told }
    }

    /// Checks that this ticket is the one run `run` issues after `told`
    /// tells.
    pub(crate) fn check(self, run: u64, told: u64) -> Result<(), RunError> {
        if self.run != run {
            Err(RunError::ForeignTicket)
        } else if self.ask != told {
            Err(RunError::TicketTold { ticket: self.ask, told })
        } else {
            Ok(())
        }
    }
}

/// Where an ask's networks live.
pub(crate) enum Networks<'a> {
    /// Whole networks.
    List(&'a [Network]),
    /// ESP's generation, read from its sub-populations.
    Set(Assembled<'a>),
}

impl<'a> Asked<'a> {
    /// The networks of `purpose`, with the streams of `seed` and `key`;
    /// their ticket is made by the run driver ([`Asked::with_ticket`]).
    pub(crate) fn new(networks: Networks<'a>, purpose: AskPurpose, seed: u64, key: [u64; 2]) -> Asked<'a> {
        Asked {
            networks,
            purpose,
            seed,
            key,
            ticket: Ticket::new(0, 0),
        }
    }

    /// These networks under `ticket`.
    pub(crate) fn with_ticket(self, ticket: Ticket) -> Asked<'a> {
        Asked { ticket, ..self }
    }

    /// The ticket to tell their fitness with.
    pub fn ticket(&self) -> Ticket {
        self.ticket
    }

    /// What the networks are for.
    pub fn purpose(&self) -> AskPurpose {
        self.purpose
    }

    /// The run's seed: network `j` is evaluated with
    /// `rng::stream(seed(), [key().., j])`.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The key prefix of the networks' streams (purpose and generation).
    pub fn key(&self) -> &[u64] {
        &self.key
    }

    /// Which neuron of each sub-population network `j` takes (its index in
    /// the sub-population as the generation's credit sees it), for ESP's
    /// generation networks; `None` for whole networks (lesion tests, the
    /// hill-climber) and for `j` out of range. With the networks' fitness,
    /// [`Credit::neuron_credits`](crate::Credit::neuron_credits) gives the
    /// credit ESP ranks the neurons by: an observer of a run can follow
    /// each neuron without changing the run.
    pub fn picks(&self, j: usize) -> Option<&[usize]> {
        match &self.networks {
            Networks::Set(set) if j < set.picks.count() => set.picks.networks().nth(j),
            _ => None,
        }
    }

    /// The networks' streams: network `j` takes `streams().stream(j)`.
    pub fn streams(&self) -> StreamFamily {
        StreamFamily::new(self.seed, &self.key)
    }

    /// Evaluates the networks with `evaluator` on the current rayon pool,
    /// each with its stream ([`evaluate_all`]): the fitness to tell.
    pub fn evaluate<E: Evaluator>(&self, evaluator: &E) -> Result<Vec<f64>, RunError> {
        evaluate_all(evaluator, self, self.seed, &self.key)
    }
}

impl NetworkSet for Asked<'_> {
    fn len(&self) -> usize {
        match self.networks {
            Networks::List(list) => list.len(),
            Networks::Set(ref set) => set.len(),
        }
    }
    fn shape(&self, j: usize) -> (usize, usize) {
        match self.networks {
            Networks::List(list) => NetworkSet::shape(list, j),
            Networks::Set(ref set) => set.shape(j),
        }
    }
    fn hidden(&self, j: usize) -> usize {
        match self.networks {
            Networks::List(list) => list[j].hidden(),
            Networks::Set(ref set) => set.hidden(j),
        }
    }
    fn neuron(&self, j: usize, k: usize) -> &[f64] {
        match self.networks {
            Networks::List(list) => list[j].neuron(k),
            Networks::Set(ref set) => set.neuron(j, k),
        }
    }
    fn is_lesioned(&self, j: usize, k: usize) -> bool {
        match self.networks {
            Networks::List(list) => list[j].is_lesioned(k),
            Networks::Set(ref set) => set.is_lesioned(j, k),
        }
    }
    fn network(&self, j: usize) -> Cow<'_, Network> {
        match self.networks {
            Networks::List(list) => Cow::Borrowed(&list[j]),
            Networks::Set(ref set) => set.network(j),
        }
    }
}

/// A run driven from outside: [`AskTell::ask`] for networks,
/// [`AskTell::tell`] their fitness with the ask's [`Ticket`], until `ask`
/// answers `None`. ESP's [`EspRun`](crate::EspRun) and the hill-climber's
/// [`HillClimbRun`](crate::HillClimbRun) are ones, and [`AnyRun`](crate::AnyRun)
/// either.
///
/// ```
/// use esp_neuroevolution::network::Network;
/// use esp_neuroevolution::{AskTell, Esp, EspSettings, FnEvaluator};
///
/// let evaluator = FnEvaluator::new(2, 1, |net: &Network, _: &mut esp_neuroevolution::rng::Stream| {
///     let mut out = [0.0];
///     net.activate(&[0.5, 1.0], &mut out);
///     Ok(-(out[0] - 0.25).abs())
/// });
/// let esp = Esp::new(EspSettings { subpop_size: 8, generations: 20, ..EspSettings::default() }, 3)?;
/// let mut run = esp.start(2, 1)?;
/// while let Some(asked) = run.ask()? {
///     // Evaluate anywhere, any way, as long as network j uses asked.streams().stream(j).
///     let (ticket, fitness) = (asked.ticket(), asked.evaluate(&evaluator)?);
///     if let Some(record) = run.tell(ticket, &fitness)? {
///         println!("generation {}: best {}", record.generation, record.max);
///     }
/// }
/// let result = run.into_result()?;
/// // The same run, bit for bit, as Esp::run.
/// assert_eq!(result.records, esp.run(&evaluator, |_| {})?.records);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait AskTell {
    /// The networks to evaluate next, or `None` once the run has ended.
    /// Asking again before telling asks for the same networks, under the
    /// same ticket. Fails when the search's weights overflowed.
    fn ask(&mut self) -> Result<Option<Asked<'_>>, RunError>;

    /// Advances the run by the fitness of the networks that the ask of
    /// `ticket` asked for, in order (higher is better; any sign).
    /// Returns the record of the generation (cycle) this completes, if it
    /// completes one. Fails, leaving the run as it was, once the run has
    /// ended ([`RunError::Ended`]), on another run's ticket
    /// ([`RunError::ForeignTicket`]), on the ticket of an ask told already
    /// ([`RunError::TicketTold`]: a repeated tell, or no ask since the
    /// last tell), on a count of fitnesses other than the ask's
    /// ([`RunError::FitnessCount`]), on a NaN ([`RunError::NanFitness`]) or
    /// an infinity ([`RunError::InfiniteFitness`]).
    fn tell(&mut self, ticket: Ticket, fitness: &[f64]) -> Result<Option<&GenerationRecord>, RunError>;

    /// Ends the run once its current generation (cycle) is complete, as a
    /// per-generation callback of `run` returning [`Control::Stop`](crate::Control::Stop) does;
    /// the run's [`Ending`] is then [`Ending::Stopped`] unless its goal or
    /// budget ended it there first.
    fn stop(&mut self);

    /// Why the run ended, once it has (after the last `tell`, `ask`
    /// answers `None`).
    fn ending(&self) -> Option<Ending>;

    /// The records of the generations (cycles) completed so far.
    fn records(&self) -> &[GenerationRecord];

    /// The result of the ended run (a copy); [`RunError::NotEnded`] before.
    fn result(&self) -> Result<RunResult, RunError>;

    /// The best network found so far (the champion of the generations
    /// completed so far), while the run goes on as after it has ended;
    /// `None` before the first generation (cycle) is complete.
    fn champion(&self) -> Option<&Champion>;
}

impl<T: AskTell + ?Sized> AskTell for Box<T> {
    fn ask(&mut self) -> Result<Option<Asked<'_>>, RunError> {
        (**self).ask()
    }
    fn tell(&mut self, ticket: Ticket, fitness: &[f64]) -> Result<Option<&GenerationRecord>, RunError> {
        (**self).tell(ticket, fitness)
    }
    fn stop(&mut self) {
        (**self).stop()
    }
    fn ending(&self) -> Option<Ending> {
        (**self).ending()
    }
    fn records(&self) -> &[GenerationRecord] {
        (**self).records()
    }
    fn result(&self) -> Result<RunResult, RunError> {
        (**self).result()
    }
    fn champion(&self) -> Option<&Champion> {
        (**self).champion()
    }
}

/// Checks told fitness against the ask: its count, then NaN and infinity.
pub(crate) fn check_told(fitness: &[f64], expected: usize) -> Result<(), RunError> {
    if fitness.len() != expected {
        return Err(RunError::FitnessCount {
            expected,
            got: fitness.len(),
        });
    }
    check_fitness(fitness, 0)
}
