//! Which SIMD instruction set the batched path is compiled for, picked at
//! run time so that one portable binary uses AVX-512 or AVX2 where the CPU
//! has them and plain x86-64 (SSE2) or the target's baseline elsewhere.

use strum::VariantArray;

use crate::named::Named;

/// Calls the macro `$callback!` with its arguments followed by the
/// `multiversion` targets of
/// [`SimdLevel::Avx512`](crate::numeric::SimdLevel::Avx512) and
/// [`SimdLevel::Avx2`](crate::numeric::SimdLevel::Avx2),
/// as string literals: `with_simd_targets!(m!(a,))` is
/// `m!(a, "x86_64+avx512f+...", "x86_64+avx2+fma")`. The one place the
/// targets are spelled: `multiversion`'s attributes take literals, not
/// constants, so every kernel compiled for a level is written inside a
/// macro called through this one
/// ([`AVX512_TARGET`](crate::numeric::AVX512_TARGET) and
/// [`AVX2_TARGET`](crate::numeric::AVX2_TARGET) are the same strings as
/// constants).
#[macro_export]
macro_rules! with_simd_targets {
    ($callback:ident ! ($($args:tt)*)) => {
        $callback! { $($args)* "x86_64+avx512f+avx512bw+avx512cd+avx512dq+avx512vl", "x86_64+avx2+fma" }
    };
}

/// The constants of the targets and their detection, from the one spelling.
macro_rules! targets {
    ($avx512:tt, $avx2:tt) => {
        /// The `multiversion` target of [`SimdLevel::Avx512`]'s kernels
        /// (x86-64-v4's AVX-512 F/BW/CD/DQ/VL).
        pub const AVX512_TARGET: &str = $avx512;
        /// The `multiversion` target of [`SimdLevel::Avx2`]'s kernels (AVX2
        /// and FMA, x86-64-v3).
        pub const AVX2_TARGET: &str = $avx2;

        /// Whether this processor has every feature of [`AVX512_TARGET`].
        #[multiversion::multiversion(targets($avx512))]
        fn has_avx512() -> bool {
            multiversion::target::match_target! {
                $avx512 => true,
                _ => false,
            }
        }

        /// Whether this processor has every feature of [`AVX2_TARGET`].
        #[multiversion::multiversion(targets($avx2))]
        fn has_avx2() -> bool {
            multiversion::target::match_target! {
                $avx2 => true,
                _ => false,
            }
        }
    };
}
crate::with_simd_targets!(targets!());

/// An instruction-set level for the batched path. Every level computes
/// bit-identical results; only the speed differs.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    serde::Serialize,
    strum::VariantArray,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum SimdLevel {
    /// The target's baseline (SSE2 on x86-64): runs on any CPU, slowly,
    /// as every fused multiply-add is a function call.
    Portable,
    /// AVX2 and FMA (x86-64-v3): 4 lanes per register.
    Avx2,
    /// AVX-512 F/DQ (x86-64-v4): 8 lanes per register.
    Avx512,
}

impl SimdLevel {
    /// The best level this CPU supports.
    pub fn detect() -> SimdLevel {
        SimdLevel::VARIANTS
            .iter()
            .copied()
            .rev()
            .find(|l| l.is_supported())
            .unwrap_or(SimdLevel::Portable)
    }

    /// Whether this CPU can run the level: whether it has every feature of
    /// the level's [`target`](SimdLevel::target), as `multiversion`
    /// detects them for the kernels compiled for it.
    pub fn is_supported(self) -> bool {
        match self {
            SimdLevel::Portable => true,
            SimdLevel::Avx2 => has_avx2(),
            SimdLevel::Avx512 => has_avx512(),
        }
    }

    /// The `multiversion` target the level's kernels are compiled for
    /// ([`AVX512_TARGET`], [`AVX2_TARGET`]); `None` for the portable build.
    pub fn target(self) -> Option<&'static str> {
        match self {
            SimdLevel::Portable => None,
            SimdLevel::Avx2 => Some(AVX2_TARGET),
            SimdLevel::Avx512 => Some(AVX512_TARGET),
        }
    }
}

impl Named for SimdLevel {
    const WHAT: &'static str = "SIMD level";
}
