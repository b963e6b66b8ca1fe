//! The statistics of the paper's tables: mean, sample standard deviation
//! and Welch's two-sample t-test (two-tailed, unequal variances).

use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Mean and sample standard deviation (n - 1 in the denominator).
///
/// An empty slice gives `(NaN, NaN)`; a single value gives `(value, NaN)`,
/// since the sample standard deviation of one value is undefined.
pub fn mean_sd(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    if values.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mean = values.iter().sum::<f64>() / n;
    if values.len() < 2 {
        return (mean, f64::NAN);
    }
    let ss = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
    (mean, (ss / (n - 1.0)).sqrt())
}

/// The outcome of Welch's t-test of `a` against `b`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Welch {
    /// t = (mean a - mean b) / sqrt(var a / n a + var b / n b).
    pub t: f64,
    /// Welch-Satterthwaite degrees of freedom.
    pub df: f64,
    /// Two-tailed p-value.
    pub p: f64,
}

/// Welch's two-sample, two-tailed t-test (unequal variances), as the paper
/// uses against its baseline.
///
/// Degenerate inputs never panic:
/// - fewer than 2 values in either sample: `t`, `df` and `p` are NaN (not testable);
/// - zero variance in both samples: equal means give `t = 0`, `p = 1`;
///   different means give `t = ±inf`, `p = 0` (the limit of the test as
///   the variances go to zero); `df` is NaN.
pub fn welch(a: &[f64], b: &[f64]) -> Welch {
    let nan = Welch {
        t: f64::NAN,
        df: f64::NAN,
        p: f64::NAN,
    };
    if a.len() < 2 || b.len() < 2 {
        return nan;
    }
    let (ma, sa) = mean_sd(a);
    let (mb, sb) = mean_sd(b);
    let (va, vb) = (sa * sa / a.len() as f64, sb * sb / b.len() as f64);
    if !(ma.is_finite() && mb.is_finite() && va.is_finite() && vb.is_finite()) {
        return nan;
    }
    if va + vb == 0.0 {
        return if ma == mb {
            Welch {
                t: 0.0,
                df: f64::NAN,
                p: 1.0,
            }
        } else {
            Welch {
                t: (ma - mb).signum() * f64::INFINITY,
                df: f64::NAN,
                p: 0.0,
            }
        };
    }
    let t = (ma - mb) / (va + vb).sqrt();
    let df = (va + vb).powi(2) / (va * va / (a.len() as f64 - 1.0) + vb * vb / (b.len() as f64 - 1.0));
    let p = match StudentsT::new(0.0, 1.0, df) {
        Ok(dist) => (2.0 * dist.sf(t.abs())).min(1.0),
        Err(_) => f64::NAN,
    };
    Welch { t, df, p }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1.0)
    }

    /// The worked examples of Wikipedia's "Welch's t-test" article
    /// (section "Examples"), which report t = -2.46, df = 25.0, p = 0.021;
    /// t = -1.57, df = 9.9, p = 0.149; t = -2.22, df = 24.5, p = 0.036.
    /// The full-precision values below were computed independently with
    /// SciPy 1.x, `scipy.stats.ttest_ind(a, b, equal_var=False)`, and the
    /// Welch-Satterthwaite formula in NumPy.
    #[test]
    fn wikipedia_examples() {
        let a1 = [
            27.5, 21.0, 19.0, 23.6, 17.0, 17.9, 16.9, 20.1, 21.9, 22.6, 23.1, 19.6, 19.0, 21.7, 21.4,
        ];
        let a2 = [
            27.1, 22.0, 20.8, 23.4, 23.4, 23.5, 25.8, 22.0, 24.8, 20.2, 21.9, 22.1, 22.9, 20.5, 24.4,
        ];
        let b1 = [17.2, 20.9, 22.6, 18.1, 21.7, 21.4, 23.5, 24.2, 14.7, 21.8];
        let b2 = [
            21.5, 22.8, 21.0, 23.0, 21.6, 23.6, 22.5, 20.7, 23.4, 21.8, 20.7, 21.7, 21.5, 22.5, 23.6, 21.5, 22.5, 23.5,
            21.5, 21.8,
        ];
        let c1 = [19.8, 20.4, 19.6, 17.8, 18.5, 18.9, 18.3, 18.9, 19.5, 22.0];
        let c2 = [
            28.2, 26.6, 20.1, 23.3, 25.2, 22.1, 17.7, 27.6, 20.6, 13.7, 23.2, 17.5, 20.6, 18.0, 23.9, 21.6, 24.3, 20.4,
            23.9, 13.3,
        ];
        let expected = [
            (
                &a1[..],
                &a2[..],
                -2.455356398286006,
                24.988529290231416,
                0.021378001462866992,
            ),
            (
                &b1[..],
                &b2[..],
                -1.5654335235985037,
                9.904741248650831,
                0.14884169660532817,
            ),
            (
                &c1[..],
                &c2[..],
                -2.225512039969852,
                24.524634944257343,
                0.035484530830010394,
            ),
        ];
        for (a, b, t, df, p) in expected {
            let w = welch(a, b);
            assert!(close(w.t, t, 1e-10), "t {} vs {t}", w.t);
            assert!(close(w.df, df, 1e-10), "df {} vs {df}", w.df);
            assert!(close(w.p, p, 1e-8), "p {} vs {p}", w.p);
            // Symmetric: swapping the samples flips t and keeps p.
            let r = welch(b, a);
            assert!(close(r.t, -t, 1e-10) && close(r.p, p, 1e-8));
        }
        let (mean, sd) = mean_sd(&a1);
        assert!(close(mean, 20.82, 1e-12) && close(sd, 2.8048936827317665, 1e-12));
    }

    #[test]
    fn mean_sd_small_samples() {
        let (m, s) = mean_sd(&[10.0, 20.0, 30.0]);
        assert_eq!((m, s), (20.0, 10.0));
        let (m, s) = mean_sd(&[7.0]);
        assert_eq!(m, 7.0);
        assert!(s.is_nan());
        let (m, s) = mean_sd(&[]);
        assert!(m.is_nan() && s.is_nan());
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        for (a, b) in [
            (&[][..], &[1.0, 2.0][..]),
            (&[1.0][..], &[1.0, 2.0][..]),
            (&[1.0, 2.0][..], &[3.0][..]),
        ] {
            let w = welch(a, b);
            assert!(w.t.is_nan() && w.df.is_nan() && w.p.is_nan());
        }
        let same = welch(&[5.0, 5.0, 5.0], &[5.0, 5.0]);
        assert_eq!((same.t, same.p), (0.0, 1.0));
        let apart = welch(&[6.0, 6.0], &[5.0, 5.0, 5.0]);
        assert_eq!((apart.t, apart.p), (f64::INFINITY, 0.0));
        // One sample constant: df = n - 1 of the other.
        let one = welch(&[5.0, 5.0, 5.0], &[4.0, 6.0, 5.0, 5.0]);
        assert!(close(one.df, 3.0, 1e-12) && one.t == 0.0 && close(one.p, 1.0, 1e-12));
        let inf = welch(&[f64::INFINITY, 1.0], &[1.0, 2.0]);
        assert!(inf.p.is_nan());
    }
}
