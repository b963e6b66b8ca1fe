//! A traced ESP run: the same run, bit for bit, driven by ask and tell,
//! with a line per generation on its best network: whether it is a
//! first-pass landing (flown once on the scoring fitness) and how ESP's
//! credit ranks its neurons within their sub-populations; [`summary`]
//! reads traces back and summarises them.

use std::path::Path;

pub mod summary;

use anyhow::{bail, Result};
use esp_neuroevolution::network::{Network, NetworkSet as _};
use esp_neuroevolution::rng::stream;
use esp_neuroevolution::{best_of, AskPurpose, AskTell, Credit, Esp, GenerationRecord, LesionOutcome, RunResult};
use psa_sim::evaluator::PsaEvaluator;
use psa_sim::io::write_atomic;
use psa_sim::psa::{PsaSettings, Task, TrialRecord, TrialRunner};

/// The key of the stream a traced network's trial is flown with (task 2
/// draws nothing from it: no random start, no noise in evolution).
const TRACE_TRIAL: u64 = 0x0074_7261_6365;

/// How a network's trial passes the scoring window (the steps that earn
/// points on the scoring fitness: for task 2's original fitness, in the
/// box and within the heading window).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Landing {
    /// Entries into the window (an entry: a step that earns points after
    /// one that did not, or the first step).
    pub entries: usize,
    /// Steps that earn points.
    pub steps_in: usize,
    /// The first step that earns points, if any.
    pub first_in: Option<usize>,
    /// The trial's steps.
    pub steps: usize,
}

impl Landing {
    /// The window's passes in `points`, the points of each step.
    pub fn of_points(points: &[f64]) -> Landing {
        let mut entries = 0;
        let mut was_in = false;
        for &p in points {
            let is_in = p > 0.0;
            entries += usize::from(is_in && !was_in);
            was_in = is_in;
        }
        Landing {
            entries,
            steps_in: points.iter().filter(|&&p| p > 0.0).count(),
            first_in: points.iter().position(|&p| p > 0.0),
            steps: points.len(),
        }
    }

    /// A first-pass landing: the robot enters the window once and stays in
    /// it from then to the trial's last step.
    pub fn is_first_pass(&self) -> bool {
        self.entries == 1 && self.first_in.is_some_and(|first| self.steps - first == self.steps_in)
    }
}

/// One generation of a traced run.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceLine {
    /// The generation's record, as the run keeps it.
    pub record: GenerationRecord,
    /// How the generation's best network passes the window.
    pub top: Landing,
    /// Whether the best network so far (the champion) is a first-pass landing.
    pub champion_first_pass: bool,
    /// The mean over sub-populations of the rank (0 the best, 1 the worst)
    /// of the best network's neuron under mean credit.
    pub mean_credit_rank: f64,
    /// The same under max credit.
    pub max_credit_rank: f64,
    /// The mean over sub-populations of the best network's neuron's mean
    /// credit less the sub-population's mean of mean credits.
    pub mean_credit_gap: f64,
}

/// The ranks (0 best, 1 worst; ties share the best rank) of neuron
/// `picks[i]` in sub-population i by `credit` (as
/// [`Credit::neuron_credits`] gives it), averaged over sub-populations;
/// and the neuron's credit less its sub-population's mean, averaged.
fn rank_and_gap(credit: &[Option<f64>], picks: &[usize], subpop_size: usize) -> (f64, f64) {
    let (mut rank, mut gap) = (0.0, 0.0);
    for (i, &k) in picks.iter().enumerate() {
        let subpop = &credit[i * subpop_size..(i + 1) * subpop_size];
        let own = subpop[k].expect("a network's neurons joined it");
        let scored: Vec<f64> = subpop.iter().flatten().copied().collect();
        let above = scored.iter().filter(|&&c| c > own).count();
        rank += above as f64 / (subpop_size - 1).max(1) as f64;
        gap += own - scored.iter().sum::<f64>() / scored.len() as f64;
    }
    let n = picks.len() as f64;
    (rank / n, gap / n)
}

/// Flies `network` once on `scoring` and returns its passes of the window.
fn landing(runner: &mut TrialRunner, network: &Network, seed: u64) -> Result<Landing> {
    let mut record = TrialRecord::default();
    runner.run_trial(network, &mut stream(seed, &[TRACE_TRIAL]), Some(&mut record))?;
    Ok(Landing::of_points(&record.points))
}

/// Runs `esp` on `evaluator` by ask and tell, calling `on_generation`
/// after each generation as [`Esp::run`] would, and returns the run's
/// result with one [`TraceLine`] a generation; `scoring` (the settings a
/// champion of `task` is scored with) flies each generation's best network.
pub fn traced_run(
    esp: &Esp,
    evaluator: &PsaEvaluator,
    scoring: &PsaSettings,
    task: Task,
    mut on_generation: impl FnMut(&GenerationRecord),
) -> Result<(RunResult, Vec<TraceLine>)> {
    use esp_neuroevolution::Evaluator as _;
    let mut run = esp.start(evaluator.inputs(), evaluator.outputs())?;
    let mut runner = TrialRunner::new(scoring, task)?;
    let subpop_size = esp.settings().subpop_size;
    let mut lines = Vec::new();
    let mut champion: Option<(f64, bool)> = None;
    let mut pending = None;
    loop {
        let Some(asked) = run.ask()? else { break };
        let ticket = asked.ticket();
        let fitness = asked.evaluate(evaluator)?;
        let observed = match asked.purpose() {
            AskPurpose::Generation(_) => {
                let picks: Vec<&[usize]> = (0..fitness.len()).filter_map(|j| asked.picks(j)).collect();
                let subpops = picks.first().map_or(0, |p| p.len());
                let (top, top_fitness) = best_of(&fitness);
                let network = asked.network(top).into_owned();
                let top_landing = landing(&mut runner, &network, esp.seed())?;
                let mean = Credit::Mean.neuron_credits(subpops, subpop_size, picks.iter().copied(), &fitness);
                let max = Credit::Max.neuron_credits(subpops, subpop_size, picks.iter().copied(), &fitness);
                let (mean_rank, mean_gap) = rank_and_gap(&mean, picks[top], subpop_size);
                let (max_rank, _) = rank_and_gap(&max, picks[top], subpop_size);
                if champion.is_none_or(|(f, _)| top_fitness > f) {
                    champion = Some((top_fitness, top_landing.is_first_pass()));
                }
                Some((top_landing, mean_rank, max_rank, mean_gap))
            }
            AskPurpose::LesionTest(_) | AskPurpose::Base => None,
        };
        if let Some(observed) = observed {
            pending = Some(observed);
        }
        if let Some(record) = run.tell(ticket, &fitness)? {
            let Some((top, mean_credit_rank, max_credit_rank, mean_credit_gap)) = pending.take() else {
                bail!("generation {} told without its networks", record.generation);
            };
            lines.push(TraceLine {
                record: record.clone(),
                top,
                champion_first_pass: champion.is_some_and(|(_, first)| first),
                mean_credit_rank,
                max_credit_rank,
                mean_credit_gap,
            });
            on_generation(record);
        }
    }
    Ok((run.into_result()?, lines))
}

/// The trace as CSV, a line per generation.
pub fn trace_csv(lines: &[TraceLine]) -> String {
    let mut out = String::from(
        "generation,max,champion,subpops,burst,topology,top_first_pass,top_entries,top_steps_in,top_first_in,\
         champion_first_pass,mean_credit_rank,max_credit_rank,mean_credit_gap\n",
    );
    for l in lines {
        let r = &l.record;
        let topology = match r.lesion {
            None => "",
            Some(LesionOutcome::Add) => "add",
            Some(LesionOutcome::Remove { .. }) => "remove",
        };
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{:.4},{:.4},{:.4}\n",
            r.generation,
            r.max,
            r.champion,
            r.subpops,
            u8::from(r.burst),
            topology,
            u8::from(l.top.is_first_pass()),
            l.top.entries,
            l.top.steps_in,
            l.top.first_in.map_or(String::new(), |s| s.to_string()),
            u8::from(l.champion_first_pass),
            l.mean_credit_rank,
            l.max_credit_rank,
            l.mean_credit_gap,
        ));
    }
    out
}

/// Writes the trace to `path` atomically.
pub fn write_trace(path: &Path, lines: &[TraceLine]) -> Result<()> {
    write_atomic(path, trace_csv(lines).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_first_pass_landing_enters_the_window_once_and_stays() {
        let landed = Landing::of_points(&[0.0, 0.0, 1.0, 1.0, 1.0]);
        assert_eq!((landed.entries, landed.steps_in, landed.first_in), (1, 3, Some(2)));
        assert!(landed.is_first_pass());
        // The plateau: a pass through the window, then rest on a later pass.
        let plateau = Landing::of_points(&[0.0, 1.0, 0.0, 0.0, 1.0, 1.0]);
        assert_eq!(plateau.entries, 2);
        assert!(!plateau.is_first_pass());
        // In from the first step and leaving before the end.
        assert!(!Landing::of_points(&[1.0, 1.0, 0.0]).is_first_pass());
        assert!(Landing::of_points(&[1.0, 1.0, 1.0]).is_first_pass());
        assert!(!Landing::of_points(&[0.0, 0.0]).is_first_pass());
    }

    #[test]
    fn ranks_count_the_neurons_credited_above() {
        // Two sub-populations of 3; the network takes neuron 1 of the
        // first (the best: rank 0) and neuron 0 of the second (below two: rank 1).
        let credit = [Some(1.0), Some(5.0), Some(3.0), Some(0.0), Some(2.0), Some(4.0)];
        let (rank, gap) = rank_and_gap(&credit, &[1, 0], 3);
        assert!((rank - 0.5).abs() < 1e-12, "{rank}");
        assert!((gap - ((5.0 - 3.0) + (0.0 - 2.0)) / 2.0).abs() < 1e-12, "{gap}");
        // A neuron that joined no network is not counted.
        let (rank, _) = rank_and_gap(&[Some(1.0), None, Some(0.0)], &[2], 3);
        assert!((rank - 0.5).abs() < 1e-12, "{rank}");
    }
}
