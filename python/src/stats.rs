//! The statistics of the replication's tables, as `psa-esp report`
//! computes them, for comparisons made in Python.

use pyo3::prelude::*;

/// Welch's two-sample, two-tailed t-test of `a` against `b` (unequal
/// variances), as `psa-esp report` tests a configuration against the
/// baseline: `(t, df, p)`. Fewer than 2 values in either sample give NaN
/// for all three.
#[pyfunction]
pub fn welch(a: Vec<f64>, b: Vec<f64>) -> (f64, f64, f64) {
    let w = psa_experiment::results::stats::welch(&a, &b);
    (w.t, w.df, w.p)
}
