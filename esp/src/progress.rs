//! A ready-made per-generation callback that reports a run's progress.

use crate::GenerationRecord;

/// A per-generation callback for [`Esp::run`](crate::Esp::run) or
/// [`HillClimb::run`](crate::HillClimb::run) that prints a line to standard
/// error every `every` generations (every generation for 0 or 1): the
/// generation, its best fitness, the champion's, the evaluations spent, the
/// sub-populations and the burst mutations so far.
///
/// ```no_run
/// # use esp_neuroevolution::{Esp, EspSettings, FnEvaluator, progress};
/// # let evaluator = FnEvaluator::new(2, 1, |_: &esp_neuroevolution::network::Network, _: &mut esp_neuroevolution::rng::Stream| Ok(0.0));
/// let result = Esp::new(EspSettings::default(), 1)?.run(&evaluator, progress(50))?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn progress(every: usize) -> impl FnMut(&GenerationRecord) {
    let every = every.max(1);
    move |record| {
        if record.generation % every == 0 {
            eprintln!("{}", progress_line(record));
        }
    }
}

/// The line [`progress`] prints for `record`.
fn progress_line(record: &GenerationRecord) -> String {
    format!(
        "generation {}: best {} (champion {}), {} evaluations, {} sub-populations, {} bursts",
        record.generation, record.max, record.champion, record.evaluations, record.subpops, record.bursts
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_names_the_generation_fitness_and_budget() {
        let record = GenerationRecord {
            generation: 7,
            min: 0.0,
            mean: 1.0,
            max: 2.5,
            best: Some(2.5),
            champion: 3.0,
            evaluations: 2800,
            subpops: 6,
            burst: false,
            bursts: 2,
            lesion: None,
        };
        assert_eq!(
            progress_line(&record),
            "generation 7: best 2.5 (champion 3), 2800 evaluations, 6 sub-populations, 2 bursts"
        );
    }
}
