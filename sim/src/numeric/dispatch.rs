//! Which SIMD instruction set the batched path is compiled for, picked at
//! run time so that one portable binary uses AVX-512 or AVX2 where the CPU
//! has them and plain x86-64 (SSE2) or the target's baseline elsewhere.

use std::fmt;
use std::str::FromStr;

/// An instruction-set level for the batched path. Every level computes
/// bit-identical results; only the speed differs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
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
    /// Every level, slowest first.
    pub const ALL: [SimdLevel; 3] = [SimdLevel::Portable, SimdLevel::Avx2, SimdLevel::Avx512];

    /// The best level this CPU supports.
    pub fn detect() -> SimdLevel {
        SimdLevel::ALL
            .into_iter()
            .rev()
            .find(|l| l.is_supported())
            .unwrap_or(SimdLevel::Portable)
    }

    /// Whether this CPU can run the level.
    pub fn is_supported(self) -> bool {
        match self {
            SimdLevel::Portable => true,
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("avx512dq")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The level's name as the command line spells it.
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::Portable => "portable",
            SimdLevel::Avx2 => "avx2",
            SimdLevel::Avx512 => "avx512",
        }
    }
}

impl fmt::Display for SimdLevel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SimdLevel {
    type Err = String;
    fn from_str(s: &str) -> Result<SimdLevel, String> {
        SimdLevel::ALL
            .into_iter()
            .find(|l| l.name() == s)
            .ok_or_else(|| format!("SIMD level must be portable, avx2 or avx512, got {s:?}"))
    }
}
