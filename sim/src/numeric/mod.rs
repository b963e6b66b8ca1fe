//! Arithmetic shared by the scalar and the batched (SIMD) evaluation paths.
//!
//! Everything the PSA computes per step (the logistic sigmoid, the heading's
//! `atan2`, angle wrapping, the rigid-body update, the fitness test) is
//! written once, generic over [`Real`]: a plain `f64` for the scalar path and
//! [`Lanes`] (one value per network evaluated in lockstep) for the batched
//! path. Both instantiate the very same sequence of IEEE-754 operations
//! (additions, multiplications, fused multiply-adds where the code says
//! [`mul_add`](esp_neuroevolution::math::Float::mul_add), divisions, square roots, comparisons; never a library
//! call whose result could differ), so the two paths give bit-identical
//! results on every CPU, whatever SIMD width [`SimdLevel`] picks at run
//! time. A fused multiply-add rounds once, exactly as IEEE-754 defines it,
//! whether the CPU has the instruction or Rust's `f64::mul_add` computes it
//! in software; the compiler never fuses a multiplication and an addition
//! on its own, so the rigid-body update, which must match ODE's unfused
//! arithmetic, stays unfused.
//!
//! The Gaussian noise on sensors and thrusters is generated the same way
//! ([`NoiseSource`]): a random generator over [`Word`]s (one `u64` per lane)
//! and a Box-Muller transform over [`Real`], so noisy trials too are
//! bit-identical on both paths and every lane draws its own numbers.

mod dispatch;
mod lanes;
mod math;
mod normal;

pub use dispatch::{SimdLevel, AVX2_TARGET, AVX512_TARGET};
use esp_neuroevolution::math::TWO_52;
pub use esp_neuroevolution::math::{Exponential, Float};
pub use lanes::{LaneMask, Lanes, Words};
pub use math::{atan2, clamp_unit, exp, fmod, ln, sigmoid, sigmoid_with, sin_cos_quarter_turns, wrap_angle};
pub use normal::{NoiseSource, Normals, OutOfLine, Word};

/// A real number, or a bundle of them computed lane by lane: the search
/// crate's [`Float`] (what the network's activation needs) and the rest of
/// the PSA's per-step arithmetic.
pub trait Real: Float {
    /// Absolute value (clears the sign bit).
    fn abs(self) -> Self;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// The magnitude of `self` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// `self <= other` (false when either is NaN).
    fn le(self, other: Self) -> Self::Mask;
    /// Whether `mask` holds in every lane.
    fn all(mask: Self::Mask) -> bool;
    /// The remainder `self % m`, lane by lane (C's `fmod`, which is exact).
    fn rem_slow(self, m: f64) -> Self;
    /// The 64-bit words of a random generator, one per lane.
    type Word: Word;
    /// `1 + (w >> 12) / 2^52`: uniform in [1, 2) when `w` is uniform.
    fn unit_from_word(w: Self::Word) -> Self;
    /// Where bit `bit` of `w` is set.
    fn mask_from_bit(w: Self::Word, bit: u32) -> Self::Mask;
    /// `(m, e)` with `self = m * 2^e`, `m` in [1, 2) and `e` integral, for a
    /// positive normal number (anything else gives a meaningless pair).
    fn split_exponent(self) -> (Self, Self);
}

/// The bits of 1.0: a zero mantissa under the exponent bias.
const ONE_BITS: u64 = 0x3FF0_0000_0000_0000;
/// The mantissa field of an `f64`.
const MANTISSA_BITS: u64 = (1 << 52) - 1;

/// [`Real::unit_from_word`] of one word.
#[inline(always)]
fn unit_from_bits(w: u64) -> f64 {
    f64::from_bits((w >> 12) | ONE_BITS)
}

/// The mantissa of [`Real::split_exponent`]: `x`'s mantissa bits under the
/// exponent of 1.
#[inline(always)]
fn mantissa_of(x: f64) -> f64 {
    f64::from_bits((x.to_bits() & MANTISSA_BITS) | ONE_BITS)
}

/// The exponent of [`Real::split_exponent`], with integer operations and one
/// exact subtraction only (no conversion instruction, so it vectorises on
/// every level).
#[inline(always)]
fn exponent_of(x: f64) -> f64 {
    let biased = f64::from_bits((x.to_bits() >> 52) | TWO_52.to_bits());
    biased - (TWO_52 + 1023.0)
}

impl Real for f64 {
    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn copysign(self, sign: f64) -> f64 {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn le(self, other: f64) -> bool {
        self <= other
    }
    #[inline(always)]
    fn all(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn rem_slow(self, m: f64) -> f64 {
        self % m
    }
    type Word = u64;
    #[inline(always)]
    fn unit_from_word(w: u64) -> f64 {
        unit_from_bits(w)
    }
    #[inline(always)]
    fn mask_from_bit(w: u64, bit: u32) -> bool {
        (w >> bit) & 1 != 0
    }
    #[inline(always)]
    fn split_exponent(self) -> (f64, f64) {
        (mantissa_of(self), exponent_of(self))
    }
}
