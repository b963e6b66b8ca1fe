//! Arithmetic shared by the scalar and the batched (SIMD) evaluation paths.
//!
//! Everything the PSA computes per step (the logistic sigmoid, the heading's
//! `atan2`, angle wrapping, the rigid-body update, the fitness test) is
//! written once, generic over [`Real`]: a plain `f64` for the scalar path and
//! [`Lanes`] (one value per network evaluated in lockstep) for the batched
//! path. Both instantiate the very same sequence of IEEE-754 operations
//! (additions, multiplications, fused multiply-adds where the code says
//! [`Real::mul_add`], divisions, square roots, comparisons; never a library
//! call whose result could differ), so the two paths give bit-identical
//! results on every CPU, whatever SIMD width [`SimdLevel`] picks at run
//! time. A fused multiply-add rounds once, exactly as IEEE-754 defines it,
//! whether the CPU has the instruction or Rust's `f64::mul_add` computes it
//! in software; the compiler never fuses a multiplication and an addition
//! on its own, so the rigid-body update, which must match ODE's unfused
//! arithmetic, stays unfused.

mod dispatch;
mod lanes;
mod math;

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

pub use dispatch::SimdLevel;
pub use lanes::{LaneMask, Lanes};
pub use math::{atan2, clamp_unit, exp, fmod, sigmoid, wrap_angle};

/// A real number, or a bundle of them computed lane by lane.
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// The result of a comparison: one truth value per lane.
    type Mask: Copy + BitAnd<Output = Self::Mask> + BitOr<Output = Self::Mask> + Not<Output = Self::Mask>;
    /// `v` in every lane.
    fn splat(v: f64) -> Self;
    /// Absolute value (clears the sign bit).
    fn abs(self) -> Self;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// `self * a + b` with one rounding (fused multiply-add).
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// The magnitude of `self` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// `self < other` (false when either is NaN).
    fn lt(self, other: Self) -> Self::Mask;
    /// `self <= other` (false when either is NaN).
    fn le(self, other: Self) -> Self::Mask;
    /// `if_true` where `mask` holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// 2^k for an integral `k` in [-1022, 1023], built from its bits.
    fn exp2_int(k: Self) -> Self;
    /// Whether `mask` holds in every lane.
    fn all(mask: Self::Mask) -> bool;
    /// The remainder `self % m`, lane by lane (C's `fmod`, which is exact).
    fn rem_slow(self, m: f64) -> Self;
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(v: f64) -> f64 {
        v
    }
    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn mul_add(self, a: f64, b: f64) -> f64 {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn copysign(self, sign: f64) -> f64 {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn lt(self, other: f64) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: f64) -> bool {
        self <= other
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
        f64::from_bits(((k as i64 + 1023) as u64) << 52)
    }
    #[inline(always)]
    fn all(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn rem_slow(self, m: f64) -> f64 {
        self % m
    }
}
