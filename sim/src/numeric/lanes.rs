//! [`Lanes`]: N numbers computed in lockstep, written as plain loops over
//! fixed-size arrays that the compiler turns into SIMD instructions of
//! whatever width the enclosing function was compiled for (see
//! [`super::SimdLevel`]).

use std::ops::{Add, BitAnd, BitOr, Div, Index, IndexMut, Mul, Neg, Not, Sub};

use esp_neuroevolution::math::exp2_int_of;

use super::{exponent_of, mantissa_of, unit_from_bits, Float, Real};

/// N `f64` values, one per lane.
///
/// Aligned to 64 bytes, a cache line, like the other lane types: a SIMD
/// load or store of eight lanes then never straddles two lines, wherever
/// the stack or the heap puts the value. Without it the batched kernels,
/// which keep much of their state in memory, ran at a speed that depended
/// on the call path and on the allocator: the bench's AVX-512 row measured
/// 26.4-27.5 ns per network-step before, 17.8-23.1 ns after (see the
/// README's Performance section).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
pub struct Lanes<const N: usize>(pub [f64; N]);

/// N truth values, one per lane: all bits set for true, clear for false
/// (64-byte aligned, as [`Lanes`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(C, align(64))]
pub struct LaneMask<const N: usize>(pub [u64; N]);

/// N unsigned 64-bit words, one per lane (64-byte aligned, as [`Lanes`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(C, align(64))]
pub struct Words<const N: usize>(pub [u64; N]);

/// `[f(0), f(1), ..]`: a plain loop, which (unlike `std::array::from_fn`)
/// is always inlined into the SIMD-compiled caller.
#[inline(always)]
fn from_fn<T: Copy + Default, const N: usize>(f: impl Fn(usize) -> T) -> [T; N] {
    let mut out = [T::default(); N];
    for (i, o) in out.iter_mut().enumerate() {
        *o = f(i);
    }
    out
}

impl<const N: usize> Lanes<N> {
    /// The lanes' bit patterns.
    #[inline(always)]
    fn bits(self) -> [u64; N] {
        from_fn(|i| self.0[i].to_bits())
    }

    /// Lanes from bit patterns.
    #[inline(always)]
    fn from_bits(bits: [u64; N]) -> Self {
        Lanes(from_fn(|i| f64::from_bits(bits[i])))
    }

    /// `f` applied to the two operands lane by lane.
    #[inline(always)]
    fn map2(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        Lanes(from_fn(|i| f(self.0[i], other.0[i])))
    }
}

impl<const N: usize> Index<usize> for Lanes<N> {
    type Output = f64;
    #[inline(always)]
    fn index(&self, i: usize) -> &f64 {
        &self.0[i]
    }
}

impl<const N: usize> IndexMut<usize> for Lanes<N> {
    #[inline(always)]
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        &mut self.0[i]
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl<const N: usize> $trait for Lanes<N> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                self.map2(other, |a, b| a $op b)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl<const N: usize> Neg for Lanes<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Lanes(from_fn(|i| -self.0[i]))
    }
}

impl<const N: usize> BitAnd for LaneMask<N> {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, other: Self) -> Self {
        LaneMask(from_fn(|i| self.0[i] & other.0[i]))
    }
}

impl<const N: usize> BitOr for LaneMask<N> {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, other: Self) -> Self {
        LaneMask(from_fn(|i| self.0[i] | other.0[i]))
    }
}

impl<const N: usize> Not for LaneMask<N> {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        LaneMask(from_fn(|i| !self.0[i]))
    }
}

const SIGN_BIT: u64 = 1 << 63;

#[inline(always)]
fn truth(b: bool) -> u64 {
    if b {
        u64::MAX
    } else {
        0
    }
}

impl<const N: usize> Float for Lanes<N> {
    type Mask = LaneMask<N>;
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Lanes([v; N])
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Lanes(from_fn(|i| self.0[i].mul_add(a.0[i], b.0[i])))
    }
    #[inline(always)]
    fn lt(self, other: Self) -> LaneMask<N> {
        LaneMask(from_fn(|i| truth(self.0[i] < other.0[i])))
    }
    #[inline(always)]
    fn select(mask: LaneMask<N>, if_true: Self, if_false: Self) -> Self {
        let (t, f) = (if_true.bits(), if_false.bits());
        Self::from_bits(from_fn(|i| (t[i] & mask.0[i]) | (f[i] & !mask.0[i])))
    }
    #[inline(always)]
    fn exp2_int(k: Self) -> Self {
        Lanes(from_fn(|i| exp2_int_of(k.0[i])))
    }
}

impl<const N: usize> Real for Lanes<N> {
    #[inline(always)]
    fn abs(self) -> Self {
        let b = self.bits();
        Self::from_bits(from_fn(|i| b[i] & !SIGN_BIT))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Lanes(from_fn(|i| self.0[i].sqrt()))
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        let (m, s) = (self.bits(), sign.bits());
        Self::from_bits(from_fn(|i| (m[i] & !SIGN_BIT) | (s[i] & SIGN_BIT)))
    }
    #[inline(always)]
    fn le(self, other: Self) -> LaneMask<N> {
        LaneMask(from_fn(|i| truth(self.0[i] <= other.0[i])))
    }
    #[inline(always)]
    fn all(mask: LaneMask<N>) -> bool {
        mask.0.iter().fold(u64::MAX, |acc, &m| acc & m) != 0
    }
    #[inline(always)]
    fn rem_slow(self, m: f64) -> Self {
        Lanes(from_fn(|i| self.0[i] % m))
    }
    type Word = Words<N>;
    #[inline(always)]
    fn unit_from_word(w: Words<N>) -> Self {
        Lanes(from_fn(|i| unit_from_bits(w.0[i])))
    }
    #[inline(always)]
    fn mask_from_bit(w: Words<N>, bit: u32) -> LaneMask<N> {
        LaneMask(from_fn(|i| truth((w.0[i] >> bit) & 1 != 0)))
    }
    #[inline(always)]
    fn split_exponent(self) -> (Self, Self) {
        (
            Lanes(from_fn(|i| mantissa_of(self.0[i]))),
            Lanes(from_fn(|i| exponent_of(self.0[i]))),
        )
    }
}
