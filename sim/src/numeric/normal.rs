//! Gaussian noise that the scalar and the batched paths draw identically:
//! every lane runs its own generator, and the arithmetic is shared.

use super::{ln, sin_cos_quarter_turns, Lanes, Real, Words};
use esp_neuroevolution::rng::expand;

/// Unsigned 64-bit words, or a bundle of them (one per lane): the state and
/// output of the noise generator.
pub trait Word: Copy {
    /// One step of xoshiro256++ (Blackman & Vigna) on `state`, lane by
    /// lane: the next word.
    fn xoshiro256_plus_plus(state: &mut [Self; 4]) -> Self;
}

impl Word for u64 {
    #[inline(always)]
    fn xoshiro256_plus_plus(state: &mut [u64; 4]) -> u64 {
        let [s0, s1, s2, s3] = *state;
        let word = s0.wrapping_add(s3).rotate_left(23).wrapping_add(s0);
        let t = s1 << 17;
        let s2 = s2 ^ s0;
        let s3 = s3 ^ s1;
        let s1 = s1 ^ s2;
        let s0 = s0 ^ s3;
        *state = [s0, s1, s2 ^ t, s3.rotate_left(45)];
        word
    }
}

impl<const N: usize> Word for Words<N> {
    /// One loop over the lanes, which the compiler vectorises.
    #[inline(always)]
    fn xoshiro256_plus_plus(state: &mut [Words<N>; 4]) -> Words<N> {
        let mut words = [0; N];
        let [s0, s1, s2, s3] = state;
        for (lane, word) in words.iter_mut().enumerate() {
            let mut lane_state = [s0.0[lane], s1.0[lane], s2.0[lane], s3.0[lane]];
            *word = u64::xoshiro256_plus_plus(&mut lane_state);
            [s0.0[lane], s1.0[lane], s2.0[lane], s3.0[lane]] = lane_state;
        }
        Words(words)
    }
}

/// A stream of standard normal numbers: xoshiro256++ (Blackman & Vigna)
/// makes 64-bit words, and the Box-Muller transform turns each two words
/// into two independent N(0, 1) numbers. `W` is `u64` for one stream, or
/// [`Words`] for one stream per lane.
///
/// The uniform numbers have 52 random bits, so the normal numbers reach
/// +-8.49 at most (probability 2^-52 beyond); within that the distribution
/// is exact up to the rounding of `ln`, `sqrt`, sine and cosine.
#[derive(Debug, Clone)]
pub struct NoiseSource<W> {
    state: [W; 4],
}

impl NoiseSource<u64> {
    /// The stream for `seed`.
    pub fn new(seed: u64) -> NoiseSource<u64> {
        NoiseSource { state: expand(seed) }
    }
}

impl<const N: usize> NoiseSource<Words<N>> {
    /// One stream per lane: lane `l` draws what `NoiseSource::new(seeds[l])` draws.
    pub fn from_seeds(seeds: &[u64; N]) -> NoiseSource<Words<N>> {
        let states = seeds.map(expand);
        NoiseSource {
            state: std::array::from_fn(|j| Words(std::array::from_fn(|lane| states[lane][j]))),
        }
    }
}

impl<W: Word> NoiseSource<W> {
    /// The next 64-bit word of xoshiro256++.
    #[inline(always)]
    fn next_word(&mut self) -> W {
        W::xoshiro256_plus_plus(&mut self.state)
    }

    /// Two independent standard normal numbers (Box-Muller): radius
    /// sqrt(-2 ln u) for u uniform in (0, 1], angle uniform over the circle
    /// as a quarter turn picked by two random bits plus f quarter turns,
    /// f uniform in [-1/2, 1/2).
    #[inline(always)]
    pub fn normal_pair<R: Real<Word = W>>(&mut self) -> (R, R) {
        let (radial, angular) = (self.next_word(), self.next_word());
        // 2 - [1, 2) is exact and lies in (0, 1].
        let u = R::splat(2.0) - R::unit_from_word(radial);
        let radius = (R::splat(-2.0) * ln(u)).sqrt();
        // [1, 2) - 1.5 is exact.
        let f = R::unit_from_word(angular) - R::splat(1.5);
        let (sin, cos) = sin_cos_quarter_turns(f);
        // Bit 0: a half turn; bit 1: a quarter turn, (cos, sin) -> (-sin, cos).
        let radius = R::select(R::mask_from_bit(angular, 0), -radius, radius);
        let quarter = R::mask_from_bit(angular, 1);
        let (x, y) = (R::select(quarter, -sin, cos), R::select(quarter, cos, sin));
        (radius * x, radius * y)
    }
}

/// Pairs of standard normal numbers, in a stream's order, and the noise
/// added from them: a [`NoiseSource`] drawing inline, or one whose pairs
/// come from a function of their own ([`OutOfLine`]).
pub trait Normals<R: Real> {
    /// The stream's next two independent standard normal numbers.
    fn normal_pair(&mut self) -> (R, R);

    /// Adds `sd` times a standard normal number to each value, in order, a
    /// pair at a time (an odd count leaves the last pair's second unused).
    #[inline(always)]
    fn add_scaled(&mut self, values: &mut [R], sd: f64) {
        let sd = R::splat(sd);
        for pair in values.chunks_mut(2) {
            let (a, b) = self.normal_pair();
            pair[0] = pair[0] + sd * a;
            if let Some(second) = pair.get_mut(1) {
                *second = *second + sd * b;
            }
        }
    }
}

impl<R: Real> Normals<R> for NoiseSource<R::Word> {
    #[inline(always)]
    fn normal_pair(&mut self) -> (R, R) {
        NoiseSource::normal_pair(self)
    }
}

/// A lane bundle's noise whose pairs come from `pair`, a function compiled
/// apart for the caller's SIMD level, instead of being inlined where the
/// noise is added: the same numbers, in the same order, bit for bit. The
/// batched kernels draw their noise so, which keeps the Box-Muller
/// transform (a logarithm, a sine and a cosine on every lane) out of the
/// inlined flight, whose compile time grew much faster than its size.
pub struct OutOfLine<'a, const N: usize> {
    /// The lanes' generators.
    pub source: &'a mut NoiseSource<Words<N>>,
    /// `source`'s next pair, for the caller's SIMD level.
    pub pair: fn(&mut NoiseSource<Words<N>>) -> (Lanes<N>, Lanes<N>),
}

impl<const N: usize> Normals<Lanes<N>> for OutOfLine<'_, N> {
    #[inline(always)]
    fn normal_pair(&mut self) -> (Lanes<N>, Lanes<N>) {
        (self.pair)(self.source)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use statrs::distribution::{ContinuousCDF, Normal};

    #[test]
    fn words_are_those_of_the_reference_xoshiro256_plus_plus() {
        for seed in [0, 1, 0xDEAD_BEEF, u64::MAX] {
            let mut ours = NoiseSource::new(seed);
            let mut bytes = [0u8; 32];
            for (chunk, word) in bytes.chunks_mut(8).zip(expand(seed)) {
                chunk.copy_from_slice(&word.to_le_bytes());
            }
            let mut reference = rand_xoshiro::Xoshiro256PlusPlus::from_seed(bytes);
            for _ in 0..1000 {
                assert_eq!(ours.next_word(), reference.next_u64());
            }
        }
    }

    #[test]
    fn every_lane_draws_what_its_scalar_stream_draws() {
        let seeds: [u64; 8] = std::array::from_fn(|l| 1000 + l as u64 * 7919);
        let mut lanes = NoiseSource::<Words<8>>::from_seeds(&seeds);
        let mut scalars = seeds.map(NoiseSource::new);
        for _ in 0..10_000 {
            let (a, b) = lanes.normal_pair::<Lanes<8>>();
            for (l, scalar) in scalars.iter_mut().enumerate() {
                let (x, y) = scalar.normal_pair::<f64>();
                assert_eq!((a[l].to_bits(), b[l].to_bits()), (x.to_bits(), y.to_bits()));
            }
        }
    }

    #[test]
    fn numbers_are_standard_normal_and_the_pair_uncorrelated() {
        let n = 500_000;
        let mut source = NoiseSource::new(42);
        let mut xs = Vec::with_capacity(2 * n);
        let (mut products, mut positive_pairs) = (0.0, 0);
        for _ in 0..n {
            let (a, b) = source.normal_pair::<f64>();
            products += a * b;
            positive_pairs += usize::from(a > 0.0 && b > 0.0);
            xs.extend([a, b]);
        }
        let count = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / count;
        let variance = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (count - 1.0);
        // Standard errors: mean 1e-3, variance 1.4e-3, correlation 1.4e-3.
        assert!(mean.abs() < 5e-3, "mean {mean}");
        assert!((variance - 1.0).abs() < 7e-3, "variance {variance}");
        assert!(
            (products / n as f64).abs() < 7e-3,
            "correlation {}",
            products / n as f64
        );
        // Kolmogorov-Smirnov: the 0.1 % critical value is 1.95 / sqrt(count).
        xs.sort_by(f64::total_cmp);
        let normal = Normal::standard();
        let distance = xs
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                let cdf = normal.cdf(x);
                (cdf - i as f64 / count).abs().max((i as f64 + 1.0) / count - cdf)
            })
            .fold(0.0, f64::max);
        assert!(distance < 1.95 / count.sqrt(), "KS distance {distance}");
        // Both tails, beyond 3 sd: expected 2700 of a million, sd 52.
        let tails = xs.iter().filter(|x| x.abs() > 3.0).count();
        assert!((2400..3000).contains(&tails), "{tails} beyond 3 sd");
        // Each quadrant of the plane gets a quarter of the pairs (sd 6e-4).
        assert!(
            (positive_pairs as f64 / n as f64 - 0.25).abs() < 3e-3,
            "{positive_pairs}"
        );
    }

    #[test]
    fn odd_counts_use_the_first_number_of_the_last_pair() {
        let (mut odd, mut even) = (NoiseSource::new(5), NoiseSource::new(5));
        let mut three = [0.0; 3];
        let mut four = [0.0; 4];
        odd.add_scaled(&mut three, 2.0);
        even.add_scaled(&mut four, 2.0);
        assert_eq!(three, [four[0], four[1], four[2]]);
        assert_eq!(odd.next_word(), even.next_word());
    }
}
