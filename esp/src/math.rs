//! The network's activation arithmetic, defined once for every CPU: our own
//! `exp` (a polynomial, never the C library's) and the logistic sigmoid,
//! generic over [`Float`] so that an evaluator that runs several networks in
//! lockstep (one SIMD lane per network) computes the very bits that
//! [`Network::activate`](crate::network::Network::activate) computes.
//!
//! `exp`'s coefficients were fitted by Chebyshev interpolation in 50-digit
//! arithmetic, to two degrees ([`Exponential`]): the accurate one is within
//! a few units in the last place, the fast one (the default) within 2.2e-10
//! relative. The polynomial chosen is the definition of the logistic unit,
//! so that results never depend on the platform's maths library.

use std::f64::consts::LOG2_E;

use serde::{Deserialize, Serialize};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// A real number, or a bundle of them computed lane by lane: what the
/// activation arithmetic needs. `f64` implements it; a batched evaluator
/// implements it for its lane type.
pub trait Float:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// The result of a comparison: one truth value per lane.
    type Mask: Copy + BitAnd<Output = Self::Mask> + BitOr<Output = Self::Mask> + Not<Output = Self::Mask>;
    /// `v` in every lane.
    fn splat(v: f64) -> Self;
    /// `self * a + b` with one rounding (fused multiply-add).
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// `self < other` (false when either is NaN).
    fn lt(self, other: Self) -> Self::Mask;
    /// `if_true` where `mask` holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// 2^k for an integral `k` in [-1022, 1023], built from its bits
    /// ([`exp2_int_of`] lane by lane).
    fn exp2_int(k: Self) -> Self;
}

/// 2^52: a value in [2^52, 2^53) holds an integer in its mantissa bits.
pub const TWO_52: f64 = 4_503_599_627_370_496.0;

/// [`Float::exp2_int`] of one integral `k` in [-1022, 1023]: the exact sum
/// `k + 1023 + 2^52` holds k + 1023 in its low mantissa bits, which become
/// the exponent field (one addition and integer operations, so it
/// vectorises on every level, and the scalar path needs no float-to-integer
/// conversion). Outside that range (a NaN from `exp`'s argument) the bits
/// wrap and the result is meaningless, never a panic.
#[inline(always)]
pub fn exp2_int_of(k: f64) -> f64 {
    let shifted = (k + (TWO_52 + 1023.0)).to_bits();
    f64::from_bits(shifted.wrapping_sub(TWO_52.to_bits()) << 52)
}

impl Float for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(v: f64) -> f64 {
        v
    }
    #[inline(always)]
    fn mul_add(self, a: f64, b: f64) -> f64 {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn lt(self, other: f64) -> bool {
        self < other
    }
    #[inline(always)]
    fn select(mask: bool, if_true: f64, if_false: f64) -> f64 {
        if mask {
            if_true
        } else {
            if_false
        }
    }
    #[inline(always)]
    fn exp2_int(k: f64) -> f64 {
        exp2_int_of(k)
    }
}

/// 1.5 * 2^52: adding and subtracting it rounds to the nearest integer.
const ROUNDER: f64 = 6755399441055744.0;
/// ln 2 split so that k * LN2_HI is exact for |k| < 2^11 (fdlibm's split):
/// the high part.
pub const LN2_HI: f64 = 6.931_471_803_691_238e-1;
/// The low part of ln 2's split (see [`LN2_HI`]).
pub const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// Arguments beyond these give 2^k outside the normal range.
const EXP_ARGUMENT_LIMIT: f64 = 708.0;
/// e^r = 1 + r + r^2 q(r) on |r| <= ln2/2: q's coefficients, highest first
/// (relative error of the fit 1.8e-17): [`Exponential::Accurate`].
const EXP_Q: [f64; 10] = [
    2.510_037_583_256_123_4e-8,
    2.762_007_587_998_336_7e-7,
    2.755_726_848_031_002_4e-6,
    2.480_152_132_236_869_2e-5,
    1.984_126_986_304_054_5e-4,
    1.388_888_891_719_671_9e-3,
    8.333_333_333_330_065e-3,
    4.166_666_666_662_416_4e-2,
    1.666_666_666_666_666_9e-1,
    5.000_000_000_000_001e-1,
];
/// The same fit with four terms fewer (relative error 2.2e-10):
/// [`Exponential::Fast`].
const EXP_Q_FAST: [f64; 6] = [
    1.989_098_096_929_460_6e-4,
    1.393_364_112_162_546_2e-3,
    8.333_310_934_359_203e-3,
    4.166_646_500_523_263e-2,
    1.666_666_668_161_434_5e-1,
    5.000_000_013_457_808e-1,
];

/// The polynomial behind the logistic units' exponential, a setting of the
/// model: both are fitted the same way and differ only in degree, and in
/// every result's bits (statistically the runs are alike).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Exponential {
    /// Degree 7, relative error below 2.3e-10: five fused multiply-adds
    /// fewer per unit than `Accurate` (see [`Exponential::ln2_parts`]),
    /// about a tenth of a batched evaluation's time.
    #[default]
    Fast,
    /// Degree 11, within two units in the last place of the C library's
    /// `exp`: the definition of builds before 2026-11-26, which repeats
    /// their results bit for bit.
    Accurate,
}

impl Exponential {
    /// The coefficients of q, highest first (e^r = 1 + r + r^2 q(r)).
    #[inline(always)]
    pub fn coefficients(self) -> &'static [f64] {
        match self {
            Exponential::Fast => &EXP_Q_FAST,
            Exponential::Accurate => &EXP_Q,
        }
    }

    /// ln 2 in the parts the argument reduction subtracts, k times each,
    /// in order: `Accurate` splits it ([`LN2_HI`], [`LN2_LO`]); `Fast`
    /// subtracts it rounded, one fused multiply-add fewer (an error below
    /// 2.4e-14, far within its fit's).
    #[inline(always)]
    pub fn ln2_parts(self) -> &'static [f64] {
        match self {
            Exponential::Fast => &[std::f64::consts::LN_2],
            Exponential::Accurate => &[LN2_HI, LN2_LO],
        }
    }
}

/// Horner's scheme, highest coefficient first.
#[inline(always)]
pub fn horner<R: Float>(x: R, coefficients: &[f64]) -> R {
    let mut acc = R::splat(coefficients[0]);
    for &c in &coefficients[1..] {
        acc = acc.mul_add(x, R::splat(c));
    }
    acc
}

/// e^x, within two units in the last place ([`Exponential::Accurate`]).
/// Arguments are clamped to [-708, 708] first, so the result is always
/// finite and positive (e^-708 is about 3e-308).
#[inline(always)]
pub fn exp<R: Float>(x: R) -> R {
    exp_with(x, Exponential::Accurate)
}

/// e^x with the polynomial `exponential`, clamped as [`exp`].
#[inline(always)]
pub fn exp_with<R: Float>(x: R, exponential: Exponential) -> R {
    let limit = R::splat(EXP_ARGUMENT_LIMIT);
    let x = R::select(x.lt(-limit), -limit, x);
    let x = R::select(limit.lt(x), limit, x);
    let rounder = R::splat(ROUNDER);
    let k = x.mul_add(R::splat(LOG2_E), rounder) - rounder;
    let mut r = x;
    for &part in exponential.ln2_parts() {
        r = k.mul_add(R::splat(-part), r);
    }
    let e_r = R::splat(1.0) + (r * r).mul_add(horner(r, exponential.coefficients()), r);
    e_r * R::exp2_int(k)
}

/// The logistic function 1 / (1 + e^-x), with the default [`Exponential`].
#[inline(always)]
pub fn sigmoid<R: Float>(x: R) -> R {
    sigmoid_with(x, Exponential::default())
}

/// The logistic function 1 / (1 + e^-x), with the exponential `exponential`.
#[inline(always)]
pub fn sigmoid_with<R: Float>(x: R, exponential: Exponential) -> R {
    R::splat(1.0) / (R::splat(1.0) + exp_with(-x, exponential))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64).abs_diff(b.to_bits() as i64)
    }

    /// Evenly spread and random-looking test points in [lo, hi].
    fn points(lo: f64, hi: f64, n: usize) -> impl Iterator<Item = f64> {
        (0..n).map(move |i| lo + (hi - lo) * ((i as f64 * 0.618_033_988_749_894_9) % 1.0))
    }

    #[test]
    fn exp_is_within_two_ulps_of_the_c_library() {
        for x in points(-700.0, 700.0, 200_000).chain(points(-1.0, 1.0, 100_000)) {
            assert!(ulps(exp(x), x.exp()) <= 2, "exp({x}) = {} vs {}", exp(x), x.exp());
        }
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-0.0), 1.0);
        assert_eq!(exp(f64::INFINITY), exp(EXP_ARGUMENT_LIMIT));
        assert!(exp(-1e6) > 0.0 && exp(1e6).is_finite());
    }

    #[test]
    fn the_fast_exp_is_within_its_fit_of_the_c_library() {
        for x in points(-700.0, 700.0, 200_000).chain(points(-1.0, 1.0, 100_000)) {
            let (ours, libm) = (exp_with(x, Exponential::Fast), x.exp());
            assert!((ours - libm).abs() <= 2.3e-10 * libm, "exp({x}) = {ours} vs {libm}");
        }
        assert_eq!(exp_with(0.0, Exponential::Fast), 1.0);
        assert_eq!(
            exp_with(f64::INFINITY, Exponential::Fast),
            exp_with(708.0, Exponential::Fast)
        );
        assert!(exp_with(-1e6, Exponential::Fast) > 0.0);
    }

    #[test]
    fn sigmoid_saturates_and_is_symmetric() {
        for (exponential, tolerance) in [
            (Exponential::Accurate, 4.0 * f64::EPSILON),
            (Exponential::Fast, 2.3e-10),
        ] {
            let sigmoid = |x: f64| sigmoid_with(x, exponential);
            assert_eq!(sigmoid(0.0), 0.5);
            assert_eq!(sigmoid(40.0), 1.0);
            assert!(sigmoid(-40.0) > 0.0 && sigmoid(-40.0) < 1e-17);
            for x in points(-30.0, 30.0, 10_000) {
                let exact = 1.0 / (1.0 + (-x).exp());
                assert!((sigmoid(x) - exact).abs() <= tolerance * exact, "sigmoid({x})");
                assert!((sigmoid(x) + sigmoid(-x) - 1.0).abs() <= tolerance);
            }
        }
        assert_eq!(sigmoid(1.5), sigmoid_with(1.5, Exponential::Fast));
    }
}
