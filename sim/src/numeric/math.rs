//! The elementary functions of the PSA's per-step arithmetic, generic over
//! [`Real`] so that scalar and batched code share every rounding.
//!
//! `exp` and `atan2` are our own polynomial approximations (coefficients
//! fitted by Chebyshev interpolation in 50-digit arithmetic), accurate to a
//! few units in the last place (the logistic unit's exponential is a
//! setting, [`Exponential`](esp_neuroevolution::math::Exponential), whose
//! default is shorter): they are the definition of the logistic unit and
//! the heading for every backend, so that results never depend on the C
//! library's implementation of these functions. `ln` (fdlibm's) and the
//! sine and cosine of quarter turns (Taylor series) serve the noise
//! generator's Box-Muller transform.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, SQRT_2, TAU};

pub use esp_neuroevolution::math::{exp, sigmoid, sigmoid_with};
use esp_neuroevolution::math::{horner, LN2_HI, LN2_LO};

use super::Real;

/// atan(t) = t + t z s(z), z = t^2 <= tan^2(pi/8): s's coefficients, highest
/// first (error of the fit 5.4e-18).
const ATAN_S: [f64; 11] = [
    -1.917_688_711_906_226e-2,
    3.923_165_829_558_719e-2,
    -5.085_449_737_940_26e-2,
    5.858_148_912_802_21e-2,
    -6.664_511_447_381_948e-2,
    7.692_183_190_826_087e-2,
    -9.090_904_578_123_903e-2,
    1.111_111_101_525_636_1e-1,
    -1.428_571_428_466_654_2e-1,
    1.999_999_999_999_552e-1,
    -3.333_333_333_333_333e-1,
];
/// tan(pi/8).
const TAN_PI_8: f64 = 0.414_213_562_373_095_03;
/// ln(1 + f) = f - f^2/2 + s (f^2/2 + z r(z)), s = f / (2 + f), z = s^2:
/// r's coefficients, highest first (fdlibm's `Lg7` .. `Lg1`, error < 2^-58).
const LN_R: [f64; 7] = [
    1.479_819_860_511_658_6e-1,
    1.531_383_769_920_937_3e-1,
    1.818_357_216_161_805e-1,
    2.222_219_843_214_978_4e-1,
    2.857_142_874_366_239e-1,
    3.999_999_999_940_942e-1,
    6.666_666_666_666_735e-1,
];
/// sin(pi f / 2) = f s(f^2) for |f| <= 1/2: s's Taylor coefficients,
/// highest first (remainder below 1e-19).
const SIN_QUARTER: [f64; 9] = [
    6.066_935_731_106_195_5e-12,
    -6.688_035_109_811_468e-10,
    5.692_172_921_967_927e-8,
    -3.598_843_235_212_085e-6,
    1.604_411_847_873_598_3e-4,
    -4.681_754_135_318_688e-3,
    7.969_262_624_616_705e-2,
    -6.459_640_975_062_463e-1,
    FRAC_PI_2,
];
/// cos(pi f / 2) = c(f^2) for |f| <= 1/2: c's Taylor coefficients, highest
/// first (remainder below 3e-18).
const COS_QUARTER: [f64; 9] = [
    6.565_963_114_979_473e-11,
    -6.386_603_083_791_852e-9,
    4.710_874_778_818_172e-7,
    -2.520_204_237_306_060_7e-5,
    9.192_602_748_394_266e-4,
    -2.086_348_076_335_296e-2,
    2.536_695_079_010_480_3e-1,
    -1.233_700_550_136_169_7,
    1.0,
];

/// The natural logarithm of a positive normal number (fdlibm's algorithm:
/// x = m 2^e with m in [sqrt(1/2), sqrt(2)), then a polynomial in
/// s = (m - 1) / (m + 1)); within one unit in the last place.
#[inline(always)]
pub fn ln<R: Real>(x: R) -> R {
    let (mantissa, exponent) = x.split_exponent();
    let high = R::splat(SQRT_2).lt(mantissa);
    let m = R::select(high, mantissa * R::splat(0.5), mantissa);
    let e = R::select(high, exponent + R::splat(1.0), exponent);
    // Exact by Sterbenz's lemma: m is within a factor 2 of 1.
    let f = m - R::splat(1.0);
    let s = f / (R::splat(2.0) + f);
    let z = s * s;
    let r = z * horner(z, &LN_R);
    let half_f_squared = R::splat(0.5) * f * f;
    e * R::splat(LN2_HI) - ((half_f_squared - (s * (half_f_squared + r) + e * R::splat(LN2_LO))) - f)
}

/// `(sin(pi f / 2), cos(pi f / 2))` for |f| <= 1/2: the sine and cosine of
/// `f` quarter turns, within a few units in the last place.
#[inline(always)]
pub fn sin_cos_quarter_turns<R: Real>(f: R) -> (R, R) {
    let z = f * f;
    (f * horner(z, &SIN_QUARTER), horner(z, &COS_QUARTER))
}

/// atan2(y, x) in [-pi, pi], with C's conventions for signed zeros in `y`
/// (atan2(0, 0) is 0 with the sign of `y`).
#[inline(always)]
pub fn atan2<R: Real>(y: R, x: R) -> R {
    let zero = R::splat(0.0);
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ax.lt(ay);
    let (small, large) = (R::select(steep, ax, ay), R::select(steep, ay, ax));
    // atan(small/large) in [0, pi/4]; above tan(pi/8), use
    // atan(t) = pi/4 + atan((t - 1) / (t + 1)).
    let shifted = (large * R::splat(TAN_PI_8)).lt(small);
    let numerator = R::select(shifted, small - large, small);
    let denominator = R::select(shifted, small + large, large);
    let t = R::select(denominator.le(zero), zero, numerator / denominator);
    let z = t * t;
    let base = R::select(shifted, R::splat(FRAC_PI_4), zero);
    let angle = base + (t * z).mul_add(horner(z, &ATAN_S), t);
    let angle = R::select(steep, R::splat(FRAC_PI_2) - angle, angle);
    let angle = R::select(x.lt(zero), R::splat(PI) - angle, angle);
    angle.copysign(y)
}

/// `a % m` (C's `fmod`, exact), for m > 0: exact shortcuts for |a| < 2m
/// (`|a| - m` is exact there by Sterbenz's lemma), C's `fmod` otherwise.
#[inline(always)]
pub fn fmod<R: Real>(a: R, m: f64) -> R {
    let (abs, modulus) = (a.abs(), R::splat(m));
    if !R::all(abs.lt(R::splat(2.0 * m))) {
        return a.rem_slow(m);
    }
    R::select(abs.lt(modulus), a, (abs - modulus).copysign(a))
}

/// An angle wrapped to (-pi, pi].
#[inline(always)]
pub fn wrap_angle<R: Real>(angle: R) -> R {
    let a = fmod(angle, TAU);
    let a = R::select(R::splat(PI).lt(a), a - R::splat(TAU), a);
    R::select(a.le(R::splat(-PI)), a + R::splat(TAU), a)
}

/// `u` clamped to [0, 1] as `f64::clamp` does (NaN stays NaN).
#[inline(always)]
pub fn clamp_unit<R: Real>(u: R) -> R {
    let u = R::select(u.lt(R::splat(0.0)), R::splat(0.0), u);
    R::select(R::splat(1.0).lt(u), R::splat(1.0), u)
}

#[cfg(test)]
mod tests {
    use super::super::Lanes;
    use super::*;
    use esp_neuroevolution::math::Float;

    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64).abs_diff(b.to_bits() as i64)
    }

    /// Evenly spread and random-looking test points in [lo, hi].
    fn points(lo: f64, hi: f64, n: usize) -> impl Iterator<Item = f64> {
        (0..n).map(move |i| lo + (hi - lo) * ((i as f64 * 0.618_033_988_749_894_9) % 1.0))
    }

    #[test]
    fn atan2_is_within_two_ulps_of_the_c_library_in_every_quadrant() {
        for (i, angle) in points(-PI, PI, 200_000).enumerate() {
            let radius = [1.0, 1e-3, 7.5, 1e5][i % 4];
            let (y, x) = (radius * angle.sin(), radius * angle.cos());
            assert!(ulps(atan2(y, x), y.atan2(x)) <= 2, "atan2({y}, {x})");
        }
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, 0.0),
        ] {
            assert_eq!(atan2(y, x).to_bits(), y.atan2(x).to_bits(), "atan2({y}, {x})");
        }
        assert_eq!(atan2(1.0, 1.0), FRAC_PI_4);
    }

    #[test]
    fn ln_is_within_one_ulp_of_the_c_library() {
        let tiny = f64::MIN_POSITIVE;
        for x in points(0.0, 1.0, 200_000)
            .chain(points(0.5, 2.0, 100_000))
            .chain(points(1.0, 1e300, 100_000))
            .chain(points(-1000.0, 0.0, 10_000).map(f64::exp))
            .filter(|&x| x >= tiny)
            .chain([tiny, 1.0, 2.0, SQRT_2, 1.0 - f64::EPSILON / 2.0, f64::EPSILON, f64::MAX])
        {
            assert!(ulps(ln(x), x.ln()) <= 1, "ln({x}) = {} vs {}", ln(x), x.ln());
        }
        assert_eq!(ln(1.0).to_bits(), 0.0f64.to_bits());
    }

    #[test]
    fn sine_and_cosine_of_quarter_turns_are_within_two_ulps_of_the_c_library() {
        for f in points(-0.5, 0.5, 200_000).chain([-0.5, 0.5, 0.0, -0.0, 1e-300, 0.25]) {
            let (sin, cos) = sin_cos_quarter_turns(f);
            let angle = f * FRAC_PI_2;
            // The reference's argument is rounded; allow for that too.
            let slack = |exact: f64| 2.0 * f64::EPSILON * exact.abs() + f64::EPSILON * angle.abs();
            assert!(
                (sin - angle.sin()).abs() <= slack(angle.sin()),
                "sin of {f} quarter turns"
            );
            assert!(
                (cos - angle.cos()).abs() <= slack(angle.cos()),
                "cos of {f} quarter turns"
            );
        }
        assert_eq!(sin_cos_quarter_turns(0.0), (0.0, 1.0));
    }

    #[test]
    fn fmod_and_wrap_angle_are_exact() {
        for a in points(-50.0, 50.0, 100_000).chain([TAU, -TAU, 2.0 * TAU, PI, -PI, 0.0, -0.0, 1e300]) {
            assert_eq!(fmod(a, TAU).to_bits(), (a % TAU).to_bits(), "{a}");
            let w = wrap_angle(a);
            assert!(w > -PI && w <= PI, "{a} -> {w}");
        }
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert!(wrap_angle(f64::NAN).is_nan());
    }

    #[test]
    fn lanes_compute_exactly_what_the_scalar_code_computes() {
        let xs: Vec<f64> = points(-40.0, 40.0, 4096)
            .chain([0.0, -0.0, 1e300, -1e300, f64::NAN, f64::INFINITY, PI, -TAU])
            .collect();
        for chunk in xs.chunks_exact(8) {
            let lanes = Lanes::<8>(chunk.try_into().unwrap());
            let rotated = Lanes::<8>(std::array::from_fn(|i| chunk[(i + 3) % 8]));
            let results = [
                (sigmoid(lanes), sigmoid as fn(f64) -> f64),
                (wrap_angle(lanes), wrap_angle as fn(f64) -> f64),
                (clamp_unit(lanes), clamp_unit as fn(f64) -> f64),
            ];
            for (batched, scalar) in results {
                for (i, &x) in chunk.iter().enumerate() {
                    assert_eq!(batched[i].to_bits(), scalar(x).to_bits(), "lane {i} of {chunk:?}");
                }
            }
            let angles = atan2(lanes, rotated);
            let logarithms = ln(lanes.abs());
            let (sines, cosines) = sin_cos_quarter_turns(lanes * Lanes::splat(1.0 / 80.0));
            for i in 0..8 {
                assert_eq!(angles[i].to_bits(), atan2(chunk[i], rotated[i]).to_bits());
                assert_eq!(logarithms[i].to_bits(), ln(chunk[i].abs()).to_bits());
                let (sin, cos) = sin_cos_quarter_turns(chunk[i] * (1.0 / 80.0));
                assert_eq!(
                    (sines[i].to_bits(), cosines[i].to_bits()),
                    (sin.to_bits(), cos.to_bits())
                );
            }
        }
    }
}
