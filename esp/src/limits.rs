//! The bounds of every setting, and the checks that enforce them.

use crate::SettingsError;

/// Checks a probability setting.
pub(crate) fn check_probability(name: &'static str, value: f64) -> Result<(), SettingsError> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(SettingsError::NotAProbability { name, value })
    }
}

/// The largest initial weight range, Cauchy scale, Cauchy limit or
/// annealing constant: the paper's are 0.3-10. Weights stay within
/// [`MAX_REAL_SETTING`] times the generations of a run, so that a network's
/// sums stay finite.
pub const MAX_REAL_SETTING: f64 = 1e6;

/// The most generations (ESP) or cycles (hill-climber) of a run (the paper:
/// 2000); a run keeps one record per generation.
pub const MAX_GENERATIONS: usize = 1_000_000;

/// The fewest neurons per sub-population: recombination breeds the top
/// quarter, so a sub-population needs at least one breeder.
pub const MIN_SUBPOP_SIZE: usize = 4;

/// The most neurons per sub-population (the paper: 40).
pub const MAX_SUBPOP_SIZE: usize = 10_000;

/// The most evaluations per neuron and generation (the paper: 10).
pub const MAX_TRIALS_PER_NEURON: usize = 1_000;

/// The most hidden neurons a run starts with (the paper: 5).
pub const MAX_HIDDEN: usize = 100;

/// The most networks evaluated per generation (ESP: `trials_per_neuron`
/// x `subpop_size`; the hill-climber: `candidates`; the paper: 400). A
/// generation holds them all: at [`MAX_HIDDEN`] neurons of a 7-input,
/// 4-output network that is about 1 GB.
pub const MAX_NETWORKS_PER_GENERATION: usize = 100_000;

/// The most inputs or outputs of a network an ask-and-tell run evolves
/// (the PSA's: 7 and 4). A generation holds every network's weights: at
/// this size, [`MAX_HIDDEN`] neurons and the paper's 400 networks, about
/// 0.6 GB.
pub const MAX_NETWORK_SIDE: usize = 1_000;

/// The smallest Cauchy limit, as a multiple of the largest Cauchy scale of
/// a run. A draw `alpha tan(pi u)` is accepted with probability
/// `(2 / pi) atan(limit / alpha)`: at least 6.3 % at this ratio, so the
/// rejection loop ends (the paper's 10 / 0.3 accepts 98 %).
pub const MIN_CAUCHY_LIMIT_PER_SCALE: f64 = 0.1;

/// Checks a setting in (0, [`MAX_REAL_SETTING`]].
pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), SettingsError> {
    if !(value.is_finite() && value > 0.0) {
        Err(SettingsError::NotPositive { name, value })
    } else if value > MAX_REAL_SETTING {
        Err(SettingsError::TooLarge {
            name,
            value,
            max: MAX_REAL_SETTING,
        })
    } else {
        Ok(())
    }
}

/// Checks a setting that must be finite and >= 0.
pub(crate) fn check_non_negative(name: &'static str, value: f64) -> Result<(), SettingsError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(SettingsError::Negative { name, value })
    }
}

/// Checks a setting that must be finite.
pub(crate) fn check_finite(name: &'static str, value: f64) -> Result<(), SettingsError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(SettingsError::NotFinite { name, value })
    }
}

/// Checks a count setting in [min, max].
pub(crate) fn check_count(name: &'static str, value: usize, min: usize, max: usize) -> Result<(), SettingsError> {
    if value < min {
        Err(SettingsError::TooFew { name, value, min })
    } else if value > max {
        Err(SettingsError::TooMany { name, value, max })
    } else {
        Ok(())
    }
}

/// Checks that `limit_name` (a Cauchy limit) is at least
/// [`MIN_CAUCHY_LIMIT_PER_SCALE`] times `largest_scale`, the largest Cauchy
/// scale the run draws with (described by `scale_name`).
pub(crate) fn check_cauchy_limit(
    limit_name: &'static str,
    limit: f64,
    scale_name: &'static str,
    largest_scale: f64,
) -> Result<(), SettingsError> {
    if limit >= MIN_CAUCHY_LIMIT_PER_SCALE * largest_scale {
        Ok(())
    } else {
        Err(SettingsError::CauchyLimitTooSmall {
            limit_name,
            limit,
            scale_name,
            scale: largest_scale,
            ratio: MIN_CAUCHY_LIMIT_PER_SCALE,
        })
    }
}
